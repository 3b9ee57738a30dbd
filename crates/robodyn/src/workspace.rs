//! Per-evaluation buffers (Pinocchio's `Data`): sized once from the model and reused across calls,
//! so that the hot paths allocate nothing.

use crate::model::DynModel;
use crate::scalar::DynScalar;
use nalgebra::{Matrix3, Vector3};

/// Buffers of the recursive Newton–Euler algorithm and of the kinematic recursions.
/// Index j holds link/frame j; index 0 is the base.
#[derive(Clone, Debug)]
pub struct Workspace<T: DynScalar = f64> {
    /// iA_j, orientation of frame j in its antecedent frame (frames 0..NF).
    pub rot: Vec<Matrix3<T>>,
    /// iP_j, origin of frame j in its antecedent frame.
    pub pos: Vec<Vector3<T>>,
    /// jw_j, angular velocity of link j in R_j.
    pub w: Vec<Vector3<T>>,
    /// jwd_j.
    pub wd: Vec<Vector3<T>>,
    /// jVd_j, linear acceleration of O_j (gravity included as a base acceleration).
    pub vd: Vec<Vector3<T>>,
    /// jU_j = skew(jwd_j) + skew(jw_j)^2 (eq 10.6–10.7).
    pub u: Vec<Matrix3<T>>,
    /// jf_j, force exerted on link j by link a(j).
    pub f: Vec<Vector3<T>>,
    /// jm_j, moment about O_j exerted on link j by link a(j).
    pub m: Vec<Vector3<T>>,
}

impl<T: DynScalar> Workspace<T> {
    /// Buffers for a model.
    pub fn new(model: &DynModel<T>) -> Self {
        let nf = model.frames.len();
        let nl = model.nl;
        let v = || vec![Vector3::zeros(); nl + 1];
        Workspace {
            rot: vec![Matrix3::identity(); nf + 1],
            pos: vec![Vector3::zeros(); nf + 1],
            w: v(),
            wd: v(),
            vd: v(),
            u: vec![Matrix3::zeros(); nl + 1],
            f: v(),
            m: v(),
        }
    }
}
