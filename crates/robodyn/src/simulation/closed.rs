//! Closed-chain robots in the simulator: the coordinates are the actuated joints q_a; at every
//! evaluation the passive joints q_p are re-solved by loop closure from the previous solution
//! (drift control: the loops never drift open), and qdd_a comes from A_cl, H_cl (10.46–10.48).
//! The energy is the kinetic + potential energy of the whole equivalent tree at the consistent
//! state (q_tr, qd_tr = G qd_a, 10.29); extra columns: `closure_residual` (max over the loops)
//! and the passive joints' q<j>.

use super::energy::{total_energy, EnergyWorkspace};
use super::Dynamics;
use crate::algorithms::closed_chain::{ClosedChain, ClosedDynamics};
use crate::error::{Error, Result};
use crate::model::Robot;

/// A closed-chain robot as the simulator sees it (actuated coordinates).
#[derive(Clone, Debug)]
pub struct ClosedChainDynamics {
    sys: ClosedDynamics,
    energy_ws: EnergyWorkspace,
    zeros: Vec<f64>,
    coulomb_smoothing: Option<f64>,
    /// q_tr of the last successful evaluation (for the diagnosis of a failure).
    last_q_tr: Option<Vec<f64>>,
}

impl ClosedChainDynamics {
    /// Error if the robot has no loop or its loops are malformed (see `LoopClosure::new`).
    pub fn new(robot: &Robot) -> Result<Self> {
        let sys = ClosedDynamics::new(robot)?;
        let n = sys.dof();
        Ok(ClosedChainDynamics {
            energy_ws: EnergyWorkspace::new(robot),
            sys,
            zeros: vec![0.0; n],
            coulomb_smoothing: None,
            last_q_tr: None,
        })
    }

    /// Coulomb friction of every tree joint as Fs tanh(qd / v) (v > 0), see
    /// [`ClosedChain::direct_dynamics_smoothed`].
    pub fn with_coulomb_smoothing(mut self, v: Option<f64>) -> Self {
        self.coulomb_smoothing = v.filter(|v| *v > 0.0);
        self
    }

    /// Start the first loop closure from this q_p instead of the reference assembly.
    pub fn set_guess(&mut self, q_p: &[f64]) {
        self.sys.set_guess(q_p);
    }

    pub fn model(&self) -> &ClosedChain {
        &self.sys.model
    }

    /// The actuated joints: coordinate k is joint `actuated_joints()[k]`.
    pub fn actuated_joints(&self) -> &[usize] {
        self.sys.model.actuated_joints()
    }

    /// The passive tree joints (extra columns q<j>).
    pub fn passive_joints(&self) -> &[usize] {
        self.sys.model.passive_joints()
    }

    /// A failed loop closure during a simulation is most often the approach of a singular
    /// configuration (Wp singular: the passive joints are no longer determined by the actuated
    /// ones); say so when Wp was already ill-conditioned at the last closed configuration.
    fn diagnose(&mut self, e: Error) -> Error {
        let Error::Numerical(m) = e else {
            return e;
        };
        let Some(q) = self.last_q_tr.clone() else {
            return Error::Numerical(m);
        };
        let ratio = match self.sys.model.constraints(&mut self.sys.ws, &q) {
            Ok(c) => {
                let sv = c.wp.svd(false, false).singular_values;
                sv.min() / sv.max()
            }
            Err(_) => 0.0,
        };
        if ratio < 1e-2 {
            Error::Numerical(format!(
                "{m}\n  at the last closed configuration q_tr = {q:.6?} Wp was ill-conditioned \
                 (smallest / largest singular value {ratio:.1e}): the motion reached a singular \
                 configuration of the mechanism"
            ))
        } else {
            Error::Numerical(m)
        }
    }
}

impl Dynamics for ClosedChainDynamics {
    fn dof(&self) -> usize {
        self.sys.dof()
    }
    fn labels(&self) -> Vec<String> {
        self.actuated_joints()
            .iter()
            .map(|j| j.to_string())
            .collect()
    }
    fn accel(
        &mut self,
        _t: f64,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
    ) -> Result<()> {
        if self.sys.ws.closure.last_qp.is_none() {
            self.sys.solve(q)?;
        }
        // guess None: the previous solution (drift control)
        let d = self.sys.model.direct_dynamics_smoothed(
            &mut self.sys.ws,
            q,
            qd,
            tau,
            None,
            self.coulomb_smoothing,
        );
        match d {
            Ok(d) => {
                qdd.copy_from_slice(d.qdd_a.as_slice());
                self.last_q_tr = Some(d.state.q);
                Ok(())
            }
            Err(e) => Err(self.diagnose(e)),
        }
    }
    fn energy(&mut self, q: &[f64], qd: &[f64]) -> Result<f64> {
        let sol = self.sys.solve(q)?;
        let s = self
            .sys
            .model
            .state(&mut self.sys.ws, q, qd, &self.zeros, Some(&sol.q_p))?;
        Ok(total_energy(
            self.sys.model.robot(),
            &mut self.energy_ws,
            &s.q,
            &s.qd,
        ))
    }
    fn extra_columns(&self) -> Vec<String> {
        let mut c = vec!["closure_residual".to_string()];
        c.extend(self.passive_joints().iter().map(|j| format!("q{j}")));
        c
    }
    fn extra_values(&mut self, q: &[f64], _qd: &[f64], out: &mut [f64]) -> Result<()> {
        let sol = self.sys.solve(q)?;
        out[0] = sol.residual;
        out[1..].copy_from_slice(&sol.q_p);
        Ok(())
    }
}
