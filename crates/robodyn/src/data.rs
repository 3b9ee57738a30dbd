//! Per-evaluation data of a tree robot (Pinocchio's `Data`): every buffer the tree algorithms
//! use, sized once from the model and reused across calls, so that the `_into` functions
//! allocate nothing. A `Data` holds no result a later call depends on: every call overwrites
//! what it reads.

use crate::error::{Error, Result};
use crate::model::{DynModel, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, Matrix3, Matrix6, Vector3, Vector6};
use std::cell::RefCell;

/// Buffers of the tree algorithms (Newton–Euler, composite links, inertia matrix, H,
/// articulated bodies, regressor) for one model. Index j of a per-link buffer holds link/frame
/// j; index 0 is the base. Make one per thread with [`Data::new`].
#[derive(Clone, Debug)]
pub struct Data<T: DynScalar = f64> {
    nl: usize,
    nf: usize,
    /// iA_j, orientation of frame j in its antecedent frame (frames 0..NF).
    pub(crate) rot: Vec<Matrix3<T>>,
    /// iP_j, origin of frame j in its antecedent frame.
    pub(crate) pos: Vec<Vector3<T>>,
    /// jw_j, angular velocity of link j in R_j.
    pub(crate) w: Vec<Vector3<T>>,
    /// jwd_j.
    pub(crate) wd: Vec<Vector3<T>>,
    /// jVd_j, linear acceleration of O_j (gravity included as a base acceleration).
    pub(crate) vd: Vec<Vector3<T>>,
    /// jU_j = skew(jwd_j) + skew(jw_j)^2 (eq 10.6–10.7).
    pub(crate) u: Vec<Matrix3<T>>,
    /// jf_j, force exerted on link j by link a(j).
    pub(crate) f: Vec<Vector3<T>>,
    /// jm_j, moment about O_j exerted on link j by link a(j).
    pub(crate) m: Vec<Vector3<T>>,
    /// jJ_j^c, jMS_j^c, M_j^c of the composite link j (link j and its successors).
    pub(crate) jc: Vec<Matrix3<T>>,
    pub(crate) msc: Vec<Vector3<T>>,
    pub(crate) mc: Vec<T>,
    /// Column wrenches of the inertia matrix by component (fx, fy, fz, mx, my, mz), each
    /// indexed by preorder position ([`crate::model::TreeIndex::preorder`]): a subtree's
    /// columns are contiguous in each, so their transport is a vectorizable loop (trees with
    /// long subtrees, [`crate::model::TreeIndex::short`]).
    pub(crate) col: [Vec<T>; 6],
    /// A(q) (NL x NL), then its L'DL factors.
    pub(crate) a: DMatrix<T>,
    /// A(q) and its L'DL factors for the model of the dynamic recursions (N x N over the
    /// movable joints, [`Robot::dynamic`]).
    pub(crate) a_dyn: DMatrix<T>,
    /// Articulated bodies: gamma_j, J*_j, beta*_j, u_j = J*_j a_j, H_j, Gamma_j minus friction,
    /// classical accelerations [Vd_j; wd_j].
    pub(crate) gamma: Vec<Vector6<T>>,
    pub(crate) art_inertia: Vec<Matrix6<T>>,
    pub(crate) art_bias: Vec<Vector6<T>>,
    pub(crate) art_u: Vec<Vector6<T>>,
    pub(crate) art_d: Vec<T>,
    pub(crate) art_tau: Vec<T>,
    pub(crate) acc: Vec<Vector6<T>>,
    /// The regressor of the tree (NL x 13 NL), sized at the first regressor call.
    pub(crate) phi: DMatrix<T>,
    /// Tree arrays (NL entries, joint j at j-1) the public joint vectors scatter into.
    pub(crate) q: Vec<T>,
    pub(crate) qd: Vec<T>,
    pub(crate) qdd: Vec<T>,
    pub(crate) h: Vec<T>,
    pub(crate) zeros: Vec<T>,
    /// Floating base: the 6 base rows B of A over the joints (row c at c N), then
    /// X = A_jj^-1 B' (column d at 6 N + d N), and H and zeros over nv = 6 + N entries.
    pub(crate) base_rows: Vec<T>,
    pub(crate) h_v: Vec<T>,
    pub(crate) zeros_v: Vec<T>,
    /// The column wrenches of the inertia matrix as records [fx, fy, fz, mx, my, mz] by
    /// preorder position, each carried in registers without a slice per component: the layout
    /// of a floating robot whose carried subtrees are short
    /// ([`crate::model::TreeIndex::short`], a leg of three joints); empty for other robots.
    pub(crate) rec: Vec<[T; 6]>,
}

impl Data<f64> {
    /// The buffers of `robot`'s algorithms.
    pub fn new(robot: &Robot) -> Data<f64> {
        let mut d = Data::from_model(robot.numeric());
        let n = robot.dynamic().nl;
        d.a_dyn = DMatrix::zeros(n, n);
        if robot.is_floating() && robot.dynamic().index.short {
            d.rec = vec![[0.0; 6]; n + 1];
        }
        d
    }

    /// Error unless this data was made for a model of `robot`'s size ([`Error::Dimension`]).
    pub fn check(&self, robot: &Robot) -> Result<()> {
        if self.nl != robot.nl() || self.nf != robot.nf() {
            return Err(Error::dimension(
                "data",
                robot.nl(),
                self.nl,
                format!(
                    "links: the Data was made for another robot than `{}` (NL = {}, NF = {})",
                    robot.name(),
                    robot.nl(),
                    robot.nf()
                ),
            ));
        }
        Ok(())
    }
}

thread_local! {
    /// The [`Data`] of the allocating convenience functions on this thread (see [`with_data`]).
    static SCRATCH: RefCell<Option<Data>> = const { RefCell::new(None) };
}

/// Run `f` with a [`Data`] that fits `robot`: the allocating convenience functions
/// (`inverse_dynamics`, `inertia_matrix`, `direct_dynamics`, ...) use it instead of building a
/// whole `Data` per call. One `Data` is kept per thread and rebuilt only when a robot of another
/// size comes ([`Data::check`]; the sizes are all a `Data` depends on: it holds no result a later
/// call reads, and the topology is in the model), so several robots on one thread stay correct
/// and a thread alternating between robots of different sizes only pays the allocation it paid
/// before. A re-entrant call (from inside `f`) gets a fresh `Data`. The kept `Data` lives until
/// the thread ends (its size is that of the last robot: O(NL^2) for A).
pub(crate) fn with_data<R>(robot: &Robot, f: impl FnOnce(&mut Data) -> R) -> R {
    // `f` runs outside the borrow of the cell, so a re-entrant call finds it empty
    let taken = SCRATCH
        .try_with(|c| c.try_borrow_mut().ok().and_then(|mut c| c.take()))
        .ok()
        .flatten();
    let mut data = match taken {
        Some(d) if d.check(robot).is_ok() && d.a_dyn.nrows() == robot.dof() => d,
        _ => Data::new(robot),
    };
    let r = f(&mut data);
    // (after the thread's locals are destroyed, the data is simply dropped)
    let _ = SCRATCH.try_with(|c| {
        if let Ok(mut c) = c.try_borrow_mut() {
            *c = Some(data);
        }
    });
    r
}

impl<T: DynScalar> Data<T> {
    /// The buffers of the generic layer for a model in scalar `T` (e.g. `Expr` for the
    /// customized symbolic models).
    pub fn from_model(model: &DynModel<T>) -> Self {
        let nf = model.frames.len();
        let nl = model.nl;
        let v = || vec![Vector3::zeros(); nl + 1];
        let z = || vec![T::zero(); nl];
        let v6 = || vec![Vector6::zeros(); nl + 1];
        Data {
            nl,
            nf,
            rot: vec![Matrix3::identity(); nf + 1],
            pos: vec![Vector3::zeros(); nf + 1],
            w: v(),
            wd: v(),
            vd: v(),
            u: vec![Matrix3::zeros(); nl + 1],
            f: v(),
            m: v(),
            jc: vec![Matrix3::zeros(); nl + 1],
            msc: v(),
            mc: vec![T::zero(); nl + 1],
            col: std::array::from_fn(|_| vec![T::zero(); nl + 1]),
            a: DMatrix::from_element(nl, nl, T::zero()),
            a_dyn: DMatrix::from_element(0, 0, T::zero()),
            gamma: v6(),
            art_inertia: vec![Matrix6::zeros(); nl + 1],
            art_bias: v6(),
            art_u: v6(),
            art_d: vec![T::zero(); nl + 1],
            art_tau: vec![T::zero(); nl + 1],
            acc: v6(),
            phi: DMatrix::from_element(0, 0, T::zero()),
            q: z(),
            qd: z(),
            qdd: z(),
            h: z(),
            zeros: z(),
            base_rows: vec![T::zero(); 12 * nl],
            h_v: vec![T::zero(); nl + 6],
            zeros_v: vec![T::zero(); nl + 6],
            rec: Vec::new(),
        }
    }

    /// NL of the model this data was made for.
    pub fn nl(&self) -> usize {
        self.nl
    }

    // Read-only views of what the last Newton–Euler pass computed. After
    // `inverse_dynamics_into` (and the other checked tree functions) the recursions ran on the
    // model of the dynamic recursions (`Robot::dynamic`, fixed frames folded): index k = 1..=N
    // is the link of joint-vector entry k-1 (frame `robot.coordinates().frame(k - 1)`), index 0
    // the base; entries above N are left over. Vectors are in the link's own frame R_j.

    /// jw_j, the angular velocity of each link (rad/s), index 0 the base.
    pub fn angular_velocities(&self) -> &[Vector3<T>] {
        &self.w
    }

    /// jwd_j, the angular acceleration of each link (rad/s²).
    pub fn angular_accelerations(&self) -> &[Vector3<T>] {
        &self.wd
    }

    /// jVd_j, the linear acceleration of each link's origin O_j (m/s²), gravity included as an
    /// upward acceleration of the base (eq 10.6).
    pub fn linear_accelerations(&self) -> &[Vector3<T>] {
        &self.vd
    }

    /// jf_j, the force exerted on each link by its antecedent (N), eq 10.10.
    pub fn forces(&self) -> &[Vector3<T>] {
        &self.f
    }

    /// jm_j, the moment about O_j exerted on each link by its antecedent (N m), eq 10.11.
    pub fn moments(&self) -> &[Vector3<T>] {
        &self.m
    }

    /// iA_j and iP_j, the orientation and origin of each frame in its antecedent's frame
    /// (placements relative to the antecedent, index 0 unused).
    pub fn local_placements(&self) -> (&[Matrix3<T>], &[Vector3<T>]) {
        (&self.rot, &self.pos)
    }
}
