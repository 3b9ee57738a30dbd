//! Dynamic models of robots with closed kinematic chains (§10.3.1–10.3.3): the equivalent tree's
//! Newton–Euler model projected on the actuated joints, evaluated on one assembly branch.
//!
//! - kinematic constraints: W = -Wp^-1 Wa (10.30), G = d q_tr / d q_a (10.40),
//!   qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Ψ (10.42);
//! - inverse model: Γ_cl = G^T Γ_tr (10.40), Lagrange multipliers λ = -Wp^-T Γ_p (10.37) and
//!   Γ_cl = Γ_a + Wa^T λ (10.36, upper part);
//! - direct model: A_cl (10.46), H_cl (10.47), qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.48, Cholesky).
//!
//! [`ClosedChain`] is the model (built once from a [`Robot`](crate::Robot)), [`ClosedData`] its per-evaluation
//! buffers and [`Branch`] the branch tracker: the assembly branch (sign of det Wp) and the last
//! closed point reached on it. Every evaluation at q_a first moves the tracker to q_a by
//! continuation along the straight path in q_a (predictor q_p + W dq_a, Newton corrector, steps
//! halved on failure), checking at every step that det Wp keeps its sign, that Wp stays above the
//! hard conditioning limit and that the corrector lands within the predictor's reach, within a
//! step budget (long moves are shortened where the model allows it: [`ClosedChain::step_budget`]). A
//! result therefore depends on (model, branch, inputs) only, never on a hidden history.
//!
//! Public vectors: q_a, qd_a, qdd_a, Γ_cl over the actuated joints
//! ([`ClosedChain::coordinates`]); q_p over the passive joints
//! ([`ClosedChain::passive_coordinates`]); tree states (Γ_tr, q_tr...) over the movable joints of
//! the equivalent tree (`chain.robot().coordinates()`).
//!
//! Allocation: the `_into` functions allocate nothing once the tracker is on the branch (the
//! small p x p solves use the crate's in-place LU); starting a branch
//! ([`ClosedChain::assembly_branch`], [`ClosedChain::branch_from`]) allocates.

mod continuation;
mod data;
mod derivatives;
mod direct;
mod inverse;
mod model;
mod regressor;
mod tracker;

use crate::algorithms::loop_closure::fmt_vec;
pub use data::ClosedData;
pub use derivatives::{
    closed_direct_dynamics_derivatives, closed_direct_dynamics_derivatives_into,
    closed_inverse_dynamics_derivatives, closed_inverse_dynamics_derivatives_into,
    ClosedDdmDerivatives, ClosedDerivativesData, ClosedIdmDerivatives,
};
pub(crate) use direct::closed_direct_dynamics_smoothed;
pub use direct::{
    closed_direct_dynamics, closed_direct_dynamics_into, closed_inertia_matrix_into, ClosedDdm,
};
pub use inverse::{closed_inverse_dynamics, closed_inverse_dynamics_into, ClosedIdm};
pub use model::{ClosedChain, Conditioning, ConditioningLimits, DEFAULT_STEP_BUDGET};
use nalgebra::DMatrix;
pub use regressor::closed_regressor_into;
pub use tracker::{
    closed_state, loop_closure, loop_closure_into, Branch, ClosedState, ClosureSolution,
};
pub(crate) use tracker::{last_residual, last_tree_state, refine_closure};

/// out = a b (dense, written out: no heap packing).
fn mul_into(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    for c in 0..b.ncols() {
        for r in 0..a.nrows() {
            out[(r, c)] = (0..a.ncols()).map(|k| a[(r, k)] * b[(k, c)]).sum();
        }
    }
}

/// out = a^T b (dense, written out: no heap packing).
fn tr_mul_into(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    for c in 0..b.ncols() {
        for r in 0..a.ncols() {
            out[(r, c)] = (0..a.nrows()).map(|k| a[(k, r)] * b[(k, c)]).sum();
        }
    }
}
