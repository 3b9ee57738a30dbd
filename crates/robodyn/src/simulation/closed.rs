//! Closed-chain robots in the simulator: the coordinates are the actuated joints q_a; at every
//! evaluation the branch tracker moves to the stage's q_a (drift control: the loops never drift
//! open, and the motion stays on the branch it started on), and qdd_a comes from A_cl, H_cl
//! (10.46–10.48). The energy is the kinetic + potential energy of the whole equivalent tree at
//! the consistent state (q_tr, qd_tr = G qd_a, 10.29); extra columns: `closure_residual` (max
//! over the loops) and the passive joints' `q<j>`.

use super::energy::mechanical_energy;
use super::Dynamics;
use crate::algorithms::closed_chain::{
    closed_direct_dynamics_smoothed, last_residual, last_tree_state, loop_closure_into, Branch,
    ClosedChain, ClosedData,
};
use crate::error::{Error, Result};
use crate::model::Environment;

/// A closed-chain robot as the simulator sees it (actuated coordinates), on a branch.
#[derive(Clone, Debug)]
pub struct ClosedChainDynamics {
    chain: ClosedChain,
    data: ClosedData,
    branch: Branch,
    env: Environment,
    qdd: Vec<f64>,
    q_p: Vec<f64>,
    coulomb_smoothing: Option<f64>,
}

impl ClosedChainDynamics {
    /// The simulated system of `chain` under its robot's environment, starting on `branch`
    /// (e.g. [`ClosedChain::assembly_branch`]).
    pub fn new(chain: ClosedChain, branch: Branch) -> Self {
        let n = chain.dof();
        ClosedChainDynamics {
            data: ClosedData::new(&chain),
            env: chain.robot().environment().clone(),
            q_p: vec![0.0; chain.n_equations()],
            chain,
            branch,
            qdd: vec![0.0; n],
            coulomb_smoothing: None,
        }
    }

    /// Coulomb friction of every tree joint as Fs tanh(qd / v) (v > 0, rad/s or m/s) instead of
    /// Fs sign(qd): the exact sign makes the right-hand side discontinuous.
    pub fn with_coulomb_smoothing(mut self, v: Option<f64>) -> Self {
        self.coulomb_smoothing = v.filter(|v| *v > 0.0);
        self
    }

    /// The closed-chain model.
    pub fn chain(&self) -> &ClosedChain {
        &self.chain
    }

    /// The branch tracker (at the last evaluated q_a).
    pub fn branch(&self) -> &Branch {
        &self.branch
    }

    fn hint(&self, e: Error) -> Error {
        match e {
            Error::BranchLost { .. } | Error::Singular { .. } => Error::Numerical(format!(
                "{e}\n  the motion reached a singular configuration of the mechanism (Wp \
                 singular: the passive joints are no longer determined by the actuated ones)"
            )),
            e => e,
        }
    }
}

impl Dynamics for ClosedChainDynamics {
    fn dof(&self) -> usize {
        self.chain.dof()
    }
    fn labels(&self) -> Vec<String> {
        let c = self.chain.coordinates();
        c.frames().iter().map(|j| j.to_string()).collect()
    }
    fn accel(
        &mut self,
        _t: f64,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
    ) -> Result<()> {
        closed_direct_dynamics_smoothed(
            &self.chain,
            &mut self.data,
            &mut self.branch,
            &self.env,
            [q, qd, tau],
            self.coulomb_smoothing,
            &mut self.qdd,
        )
        .map_err(|e| self.hint(e))?;
        qdd.copy_from_slice(&self.qdd);
        Ok(())
    }
    fn energy(&mut self, q: &[f64], qd: &[f64]) -> Result<f64> {
        let z = vec![0.0; q.len()];
        closed_direct_dynamics_smoothed(
            &self.chain,
            &mut self.data,
            &mut self.branch,
            &self.env,
            [q, qd, &z],
            None,
            &mut self.qdd,
        )
        .map_err(|e| self.hint(e))?;
        // the tree state the evaluation reached (tree arrays) on the movable joints
        let (q_tr, qd_tr) = last_tree_state(&self.data);
        let movable = self.chain.robot().coordinates().frames();
        let q_m: Vec<f64> = movable.iter().map(|&j| q_tr[j - 1]).collect();
        let qd_m: Vec<f64> = movable.iter().map(|&j| qd_tr[j - 1]).collect();
        mechanical_energy(self.chain.robot(), self.data.tree_mut(), &q_m, &qd_m)
    }
    fn extra_columns(&self) -> Vec<String> {
        let mut c = vec!["closure_residual".to_string()];
        let p = self.chain.passive_coordinates();
        c.extend(p.frames().iter().map(|j| format!("q{j}")));
        c
    }
    fn extra_values(&mut self, q: &[f64], _qd: &[f64], out: &mut [f64]) -> Result<()> {
        loop_closure_into(
            &self.chain,
            &mut self.data,
            &mut self.branch,
            q,
            &mut self.q_p,
        )
        .map_err(|e| self.hint(e))?;
        out[0] = last_residual(&self.chain, &self.data);
        out[1..].copy_from_slice(&self.q_p);
        Ok(())
    }
}
