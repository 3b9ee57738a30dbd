//! Partial derivatives of the dynamic models of trees, for optimal control and estimation
//! (docs/models/derivatives.md, whose equations the code cites as (D1)...):
//!
//! - [`inverse_dynamics_derivatives_into`]: dGamma/dq, dGamma/dqd and A = dGamma/dqdd of the
//!   inverse model in one call, analytically: the tangents of the Newton–Euler quantities
//!   along each joint coordinate are carried over that joint's subtree (forward) and back to
//!   the base (backward), O(N d) for N joints of depth d ([`inverse`]);
//! - [`direct_dynamics_derivatives_into`]: dqdd/dq, dqdd/dqd and dqdd/dGamma = A^-1 of the
//!   direct model, -A^-1 dGamma/d(q, qd) at qdd = ddm(Gamma), from the one L'DL factorization
//!   of A the direct model computes ([`direct`]);
//! - [`regressor_derivatives_into`]: dPhi/dq_k and dPhi/dqd_k of the regressor, by the same
//!   analytical kernel on each unit standard parameter (Phi is linear in K) ([`regressor`]).
//!
//! Coulomb friction Fs sign(qd) contributes nothing (its derivative is zero away from qd = 0,
//! and it is not differentiable at 0); viscous friction Fv qd adds Fv on the diagonal of
//! dGamma/dqd; the rotor inertia Ia is on the diagonal of A. Gravity, the base motion and the
//! external wrenches (constant in the link frames) enter through the nominal pass.
//!
//! All on the checked path over the movable joints ([`crate::Robot::coordinates`]), with a
//! [`DerivativesData`] made once per thread and the outputs made once: allocation-free.

pub mod direct;
pub mod inverse;
pub mod regressor;
mod world;

pub use direct::{direct_dynamics_derivatives, direct_dynamics_derivatives_into, DdmDerivatives};
pub use inverse::{
    inverse_dynamics_derivatives, inverse_dynamics_derivatives_batch,
    inverse_dynamics_derivatives_into, IdmDerivatives,
};
pub use regressor::{
    regressor_derivatives, regressor_derivatives_into, RegressorDerivatives,
    RegressorDerivativesData,
};

use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::{DynModel, Robot};
use nalgebra::{DMatrix, Vector3};

/// The tangents of one direction (a joint position or a joint velocity) for every link: link
/// j at index j, 0 the base (always zero).
#[derive(Clone, Debug)]
pub(crate) struct Tangent {
    /// d(jw_j), d(jwd_j), d(jVd_j) (D4)–(D7).
    pub(crate) w: Vec<Vector3<f64>>,
    pub(crate) wd: Vec<Vector3<f64>>,
    pub(crate) vd: Vec<Vector3<f64>>,
    /// d(jf_j), d(jm_j): the link's own wrench (D8)–(D9), then with its successors' (D10).
    pub(crate) f: Vec<Vector3<f64>>,
    pub(crate) m: Vec<Vector3<f64>>,
}

impl Tangent {
    fn new(nl: usize) -> Self {
        let v = || vec![Vector3::zeros(); nl + 1];
        Tangent {
            w: v(),
            wd: v(),
            vd: v(),
            f: v(),
            m: v(),
        }
    }
}

/// Buffers of the derivative algorithms for one robot (make one per thread, reuse it): the
/// [`Data`] of the nominal Newton–Euler pass, the tangents along a joint position and a joint
/// velocity, and the matrices of the direct model (A and its L'DL factors). Holds no result a
/// later call depends on.
#[derive(Clone, Debug)]
pub struct DerivativesData {
    pub(crate) data: Data,
    /// Tangents along q_k ([0]) and qd_k ([1]) of the column k in progress.
    pub(crate) dir: [Tangent; 2],
    /// The world-frame terms of [`world`], the kernel of the inverse and direct derivatives.
    pub(crate) world: world::WorldTerms,
    /// dGamma/dq and dGamma/dqd of the direct model's derivatives (N x N each).
    pub(crate) dtau: [DMatrix<f64>; 2],
    /// A, then its L'DL factors (N x N).
    pub(crate) factor: DMatrix<f64>,
    /// N-vectors: the torques with qdd = 0 (H), a right-hand side.
    pub(crate) h: Vec<f64>,
    pub(crate) zeros: Vec<f64>,
    /// The tree's index lists of the direct derivatives' A^-1.
    pub(crate) tree: TreeLists,
}

impl DerivativesData {
    /// The buffers for `robot` (sized from its model of the dynamic recursions).
    pub fn new(robot: &Robot) -> Self {
        let n = robot.dof();
        let nl = robot.dynamic().nl;
        DerivativesData {
            data: Data::new(robot),
            dir: [Tangent::new(nl), Tangent::new(nl)],
            world: world::WorldTerms::new(nl),
            dtau: [DMatrix::zeros(n, n), DMatrix::zeros(n, n)],
            factor: DMatrix::zeros(n, n),
            h: vec![0.0; n],
            zeros: vec![0.0; n],
            tree: TreeLists::new(robot.dynamic()),
        }
    }

    /// The [`Data`] of the last nominal pass (link velocities, accelerations, wrenches of the
    /// model of the dynamic recursions, as after [`crate::inverse_dynamics_into`]).
    pub fn data(&self) -> &Data {
        &self.data
    }

    /// Error unless this data was made for `robot`.
    pub fn check(&self, robot: &Robot) -> Result<()> {
        self.data.check(robot)?;
        // the derivatives read IA, FS, FV per joint: not a transmission's motors yet
        robot.require_no_motor_drives("the derivatives of the dynamic models")?;
        if self.factor.nrows() != robot.dof() || self.dir[0].w.len() != robot.dynamic().nl + 1 {
            return Err(Error::dimension(
                "derivatives data",
                robot.dof(),
                self.factor.nrows(),
                format!("joints: made for another robot than `{}`", robot.name()),
            ));
        }
        Ok(())
    }
}

/// Index lists of the tree of A over the links 1..NL, 0-based (link k + 1 at k), made once.
#[derive(Clone, Debug)]
pub(crate) struct TreeLists {
    /// The movable proper ancestors of each link, from the nearest.
    pub(crate) ancestors: Vec<Vec<usize>>,
    /// The first and one-past-last link of the subtree of each link's topmost movable
    /// ancestor: the rows where its column of A^-1 can be nonzero (A, hence A^-1, is block
    /// diagonal over the subtrees of a fixed base).
    pub(crate) span: Vec<(usize, usize)>,
}

impl TreeLists {
    fn new(model: &DynModel<f64>) -> Self {
        let lambda = &model.index.movable_parent;
        let chain = |mut j: usize| {
            let mut up = Vec::new();
            while lambda[j] != 0 {
                j = lambda[j];
                up.push(j - 1);
            }
            up
        };
        let ancestors: Vec<Vec<usize>> = (1..=model.nl).map(chain).collect();
        let top = |k: usize| ancestors[k].last().copied().unwrap_or(k);
        let span = (0..model.nl)
            .map(|k| {
                let members = (0..model.nl).filter(|&i| top(i) == top(k));
                members.fold((usize::MAX, 0), |(lo, hi), i| (lo.min(i), hi.max(i + 1)))
            })
            .collect();
        TreeLists { ancestors, span }
    }
}

/// Error unless every matrix of `outputs` (name, matrix) is N x N over the movable joints.
pub(crate) fn check_square(robot: &Robot, outputs: &[(&str, &DMatrix<f64>)]) -> Result<()> {
    let n = robot.dof();
    for (name, m) in outputs {
        if m.shape() != (n, n) {
            return Err(Error::dimension(
                *name,
                n * n,
                m.len(),
                format!(
                    "{n} x {n} over {}",
                    robot.coordinates().describe("movable joints")
                ),
            ));
        }
    }
    Ok(())
}
