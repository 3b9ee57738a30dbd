//! [`ClosedData`]: the per-evaluation buffers of a [`ClosedChain`].

use super::{Branch, ClosedChain};
use crate::algorithms::loop_closure::LoopWorkspace;
use crate::data::Data;
use crate::linalg::SmallLu;
use nalgebra::{DMatrix, DVector};

/// Per-evaluation buffers of a [`ClosedChain`] (its tree's [`Data`] included). One per thread.
#[derive(Clone, Debug)]
pub struct ClosedData {
    pub(super) n: usize,
    pub(super) p: usize,
    pub(super) nl: usize,
    pub(super) tree: Data,
    pub(super) lw: LoopWorkspace,
    pub(super) q_tr: Vec<f64>,
    pub(super) qd_tr: Vec<f64>,
    pub(super) qdd_tr: Vec<f64>,
    pub(super) tau_tr: Vec<f64>,
    pub(super) r: DVector<f64>,
    pub(super) jac: DMatrix<f64>,
    pub(super) lu: SmallLu,
    pub(super) w: DMatrix<f64>,
    pub(super) g: DMatrix<f64>,
    pub(super) psi: DVector<f64>,
    pub(super) qa: Vec<f64>,
    pub(super) qp: Vec<f64>,
    pub(super) pred: Vec<f64>,
    pub(super) dx: Vec<f64>,
    pub(super) start_qa: Vec<f64>,
    pub(super) start_qp: Vec<f64>,
    pub(super) start_w: DMatrix<f64>,
    pub(super) start_rcond: f64,
    pub(super) pred_step: f64,
    /// The tracker before a long move, and before a full turn (continuation).
    pub(super) saved: Branch,
    pub(super) probe: Branch,
    pub(super) target: Vec<f64>,
    pub(super) turn_end: Vec<f64>,
    pub(super) turning: Vec<(usize, f64)>,
    pub(super) a_cl: DMatrix<f64>,
    pub(super) chol: DMatrix<f64>,
    pub(super) h_cl: DVector<f64>,
    pub(super) ag: DMatrix<f64>,
    pub(super) v_nl: DVector<f64>,
    pub(super) col_n: DVector<f64>,
    pub(super) zeros_n: Vec<f64>,
    pub(super) phi: DMatrix<f64>,
}

impl ClosedData {
    /// The tree's buffers (shared with the closed-chain evaluation).
    pub(crate) fn tree_mut(&mut self) -> &mut Data {
        &mut self.tree
    }

    /// The buffers of `chain`'s evaluations.
    pub fn new(chain: &ClosedChain) -> ClosedData {
        let (n, p, nl) = (chain.dof(), chain.n_equations(), chain.robot().nl());
        ClosedData {
            n,
            p,
            nl,
            tree: Data::new(chain.robot()),
            lw: chain.closure.workspace(),
            q_tr: vec![0.0; nl],
            qd_tr: vec![0.0; nl],
            qdd_tr: vec![0.0; nl],
            tau_tr: vec![0.0; nl],
            r: DVector::zeros(p),
            jac: DMatrix::zeros(p, nl),
            lu: SmallLu::new(p),
            w: DMatrix::zeros(p, n),
            g: DMatrix::zeros(nl, n),
            psi: DVector::zeros(p),
            qa: vec![0.0; n],
            qp: vec![0.0; p],
            pred: vec![0.0; p],
            dx: vec![0.0; p],
            start_qa: vec![0.0; n],
            start_qp: vec![0.0; p],
            start_w: DMatrix::zeros(p, n),
            start_rcond: 0.0,
            pred_step: 0.0,
            saved: Branch::zeros(n, p),
            probe: Branch::zeros(n, p),
            target: vec![0.0; n],
            turn_end: vec![0.0; n],
            turning: Vec::with_capacity(n),
            a_cl: DMatrix::zeros(n, n),
            chol: DMatrix::zeros(n, n),
            h_cl: DVector::zeros(n),
            ag: DMatrix::zeros(nl, n),
            v_nl: DVector::zeros(nl),
            col_n: DVector::zeros(n),
            zeros_n: vec![0.0; n],
            phi: DMatrix::zeros(0, 0),
        }
    }
}
