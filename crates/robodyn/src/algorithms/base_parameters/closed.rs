//! Random consistent states of a closed chain for the numerical method (§10.3.4).
//!
//! [`ClosedChainSampler`] draws q_a uniformly in a box around the assembly configuration (the
//! file's `assembly`, else q = 0) and solves q_p by continuation along the straight path from the
//! assembly (as `robodyn closure` does): every sample is on the branch the assembly defines. (A
//! random walk continuing from the previous sample was tried first: on the SR400, whose assembly
//! is a flattened parallelogram, the walk crosses the bifurcation set q7 = q2 and mixes the
//! parallelogram and crossed branches, giving 50 base parameters instead of 42.) A sample is
//! rejected (another drawn) when the closure fails or Wp is ill-conditioned at the sample or
//! anywhere on the continuation path (a path through a singular configuration may switch
//! assembly branch; near one, G = [I; W] is inaccurate). Velocities and accelerations come from
//! [`ClosedChain::state`]: qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Psi (10.42);
//! G = d q_tr / d q_a (10.40).

use super::numeric::{ConsistentSample, Sampler};
use crate::algorithms::closed_chain::{ClosedChain, ClosedChainWorkspace, ClosedState};
use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use rand::{Rng, RngCore};

/// Loop-closure sampler of a closed-chain robot (see the module documentation).
#[derive(Clone, Debug)]
pub struct ClosedChainSampler {
    chain: ClosedChain,
    ws: ClosedChainWorkspace,
    /// Assembly configuration (closed): actuated and passive parts.
    qa0: Vec<f64>,
    qp0: Vec<f64>,
    /// Half-width of the random q_a box around the assembly, per actuated joint (rad for
    /// revolute, m for prismatic joints).
    pub range: Vec<f64>,
    /// Continuation steps from the assembly to each sample.
    pub continuation: usize,
    /// Smallest accepted sigma_min / sigma_max of Wp.
    pub min_wp_ratio: f64,
    /// Rejected moves allowed per sample before giving up.
    pub max_attempts: usize,
    /// qd_a uniform in [-qd_max, qd_max], qdd_a in [-qdd_max, qdd_max].
    pub qd_max: f64,
    pub qdd_max: f64,
    /// Moves rejected so far (diagnostics).
    pub rejected: usize,
}

fn ratio(s: &ClosedState) -> f64 {
    let sv = s.constraints.wp.clone().svd(false, false).singular_values;
    let (lo, hi) = (sv.min(), sv.max());
    if hi > 0.0 && lo.is_finite() {
        lo / hi
    } else {
        0.0
    }
}

impl ClosedChainSampler {
    /// Sampler of `robot` (a closed chain) starting from its assembly configuration: the file's
    /// `assembly` when given, else q = 0 (solved for q_p from that guess when not closed there).
    /// Box: +-1.5 rad for revolute actuated joints, +-0.1 m for prismatic ones.
    pub fn new(robot: &Robot) -> Result<ClosedChainSampler> {
        if robot.is_tree() {
            return Err(Error::Input(format!(
                "{} is a tree: use the tree sampler (random independent joint values)",
                robot.name()
            )));
        }
        let chain = ClosedChain::new(robot)?;
        let mut ws = chain.workspace();
        let reference = robot
            .description()
            .assembly
            .clone()
            .unwrap_or_else(|| vec![0.0; robot.nl()]);
        let pick = |js: &[usize]| -> Vec<f64> {
            js.iter()
                .map(|&j| reference.get(j - 1).copied().unwrap_or(0.0))
                .collect()
        };
        let qa0 = pick(chain.actuated_joints());
        let guess = pick(chain.passive_joints());
        let sol = chain
            .solve_positions(&mut ws, &qa0, Some(&guess))
            .map_err(|e| {
                Error::Numerical(format!(
                    "{}: the loops do not close at the assembly configuration (give `assembly` \
                     in the robot file): {e}",
                    robot.name()
                ))
            })?;
        let range = chain
            .actuated_joints()
            .iter()
            .map(|&j| match robot.frame(j).joint {
                JointType::Prismatic => 0.1,
                _ => 1.5,
            })
            .collect();
        Ok(ClosedChainSampler {
            qp0: sol.q_p,
            qa0,
            range,
            chain,
            ws,
            continuation: 24,
            min_wp_ratio: 1e-2,
            max_attempts: 200,
            qd_max: 2.0,
            qdd_max: 5.0,
            rejected: 0,
        })
    }

    /// The closed-chain model used for the samples.
    pub fn chain(&self) -> &ClosedChain {
        &self.chain
    }

    /// Try one random configuration; `None` when rejected.
    fn try_move(&mut self, rng: &mut dyn RngCore) -> Option<ClosedState> {
        let n = self.qa0.len();
        let target: Vec<f64> = (0..n)
            .map(|k| self.qa0[k] + rng.random_range(-self.range[k]..self.range[k]))
            .collect();
        // Continuation from the assembly, staying in its regular region: a path through a
        // singular configuration (Wp rank-deficient) may switch assembly branch (the SR400's
        // parallelogram flattens at q7 = q2 and q7 = q2 + pi), so such a path is rejected.
        // Predictor-corrector: the guess of each step is q_p + W dq_a (eq 10.29); a corrected
        // q_p far from the prediction means Newton jumped to another branch: rejected.
        let steps = self.continuation.max(1);
        let zeros = vec![0.0; n];
        let mut q_p = self.qp0.clone();
        let mut w: Option<nalgebra::DMatrix<f64>> = None;
        let dqa: Vec<f64> = (0..n)
            .map(|k| (target[k] - self.qa0[k]) / steps as f64)
            .collect();
        for s in 1..=steps {
            let t = s as f64 / steps as f64;
            let qa: Vec<f64> = (0..n)
                .map(|k| self.qa0[k] + t * (target[k] - self.qa0[k]))
                .collect();
            let predicted: Vec<f64> = match &w {
                Some(w) => {
                    let d = w * nalgebra::DVector::from_column_slice(&dqa);
                    q_p.iter().zip(d.iter()).map(|(a, b)| a + b).collect()
                }
                None => q_p.clone(),
            };
            let step_norm = predicted
                .iter()
                .zip(&q_p)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            q_p = self
                .chain
                .closure()
                .solve(&mut self.ws.closure, &qa, Some(&predicted))
                .ok()?
                .q_p;
            let jump = q_p
                .iter()
                .zip(&predicted)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if w.is_some() && jump > 0.05 + 0.5 * step_norm {
                return None;
            }
            let on_path = self
                .chain
                .state(&mut self.ws, &qa, &zeros, &zeros, Some(&q_p))
                .ok()?;
            if ratio(&on_path) < self.min_wp_ratio {
                return None;
            }
            w = Some(on_path.constraints.w.clone());
        }
        let sol_q_p = q_p;
        let qp = self.polish(&target, sol_q_p);
        let mut v = |s: f64| -> Vec<f64> { (0..n).map(|_| rng.random_range(-s..s)).collect() };
        let (qd, qdd) = (v(self.qd_max), v(self.qdd_max));
        let state = self
            .chain
            .state(&mut self.ws, &target, &qd, &qdd, Some(&qp))
            .ok()?;
        if ratio(&state) < self.min_wp_ratio {
            return None;
        }
        Some(state)
    }

    /// Newton steps on the kept closure equations (q_p -= Wp^-1 phi) until the residual stops
    /// decreasing: the solver stops at 1e-12, and its error on q_p (amplified by Wp^-1) would
    /// show in the rank decision of the numerical method.
    fn polish(&mut self, q_a: &[f64], mut q_p: Vec<f64>) -> Vec<f64> {
        let lc = self.chain.closure();
        let (p, nl) = (lc.n_equations(), self.chain.robot().nl());
        let mut q = vec![0.0; nl];
        let mut r = nalgebra::DVector::zeros(p);
        let mut jac = nalgebra::DMatrix::zeros(p, nl);
        let pcols = lc.passive_columns();
        lc.assemble(q_a, &q_p, &mut q);
        lc.kinematics(&mut self.ws.closure, &q, None, None);
        lc.residual(&self.ws.closure, &mut r);
        let mut norm = r.amax();
        for _ in 0..6 {
            if norm == 0.0 {
                break;
            }
            lc.constraint_jacobian(&self.ws.closure, &mut jac);
            let wp = jac.select_columns(pcols.iter());
            let Some(step) = wp.lu().solve(&r) else { break };
            let trial: Vec<f64> = q_p.iter().zip(step.iter()).map(|(a, b)| a - b).collect();
            lc.assemble(q_a, &trial, &mut q);
            lc.kinematics(&mut self.ws.closure, &q, None, None);
            lc.residual(&self.ws.closure, &mut r);
            let nt = r.amax();
            if nt >= norm {
                break;
            }
            q_p = trial;
            norm = nt;
        }
        q_p
    }

    /// The next consistent state (also returned by [`Sampler::sample`]).
    pub fn next_state(&mut self, rng: &mut dyn RngCore) -> Result<ClosedState> {
        for _ in 0..self.max_attempts {
            if let Some(s) = self.try_move(rng) {
                return Ok(s);
            }
            self.rejected += 1;
        }
        Err(Error::Numerical(format!(
            "{}: no acceptable closed configuration in {} random configurations around the assembly q_a = {:?} \
             (actuated joints {:?}) within {:?}: the loops fail to close or Wp is ill-conditioned \
             (sigma_min/sigma_max < {:e}) around it",
            self.chain.robot().name(),
            self.max_attempts,
            self.qa0,
            self.chain.actuated_joints(),
            self.range,
            self.min_wp_ratio
        )))
    }
}

impl Sampler for ClosedChainSampler {
    fn sample(&mut self, robot: &Robot, rng: &mut dyn RngCore) -> Result<ConsistentSample> {
        if robot.nl() != self.chain.robot().nl() || robot.name() != self.chain.robot().name() {
            return Err(Error::Input(format!(
                "the sampler was built for {}, not for {}",
                self.chain.robot().name(),
                robot.name()
            )));
        }
        let s = self.next_state(rng)?;
        Ok(ConsistentSample {
            q: s.q,
            qd: s.qd,
            qdd: s.qdd,
            g: Some(s.constraints.g),
        })
    }
}
