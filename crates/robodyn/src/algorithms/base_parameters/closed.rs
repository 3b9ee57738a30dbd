//! Random consistent states of a closed chain for the numerical method (§10.3.4).
//!
//! [`ClosedChainSampler`] draws q_a uniformly in a box around the assembly configuration (the
//! file's `assembly`, else q = 0) and solves q_p with the branch tracker ([`crate::Branch`])
//! started at the assembly: every sample is on the branch the assembly defines. (A
//! random walk continuing from the previous sample was tried first: on the SR400, whose assembly
//! is a flattened parallelogram, the walk crosses the bifurcation set q7 = q2 and mixes the
//! parallelogram and crossed branches, giving 50 base parameters instead of 42.) A sample is
//! rejected (another drawn) when the closure fails or Wp is ill-conditioned at the sample or
//! anywhere on the continuation path (a path through a singular configuration may switch
//! assembly branch; near one, G = [I; W] is inaccurate). Velocities and accelerations come from
//! [`closed_state`]: qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Psi (10.42);
//! G = d q_tr / d q_a (10.40).

use super::numeric::{ConsistentSample, Sampler};
use crate::algorithms::closed_chain::{
    closed_state, refine_closure, Branch, ClosedChain, ClosedState, ConditioningLimits,
};
use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
use rand::{Rng, RngCore};

/// Loop-closure sampler of a closed-chain robot (see the module documentation).
#[derive(Clone, Debug)]
pub struct ClosedChainSampler {
    chain: ClosedChain,
    /// The branch tracker at the assembly configuration: every sample is reached from it.
    start: Branch,
    /// Half-width of the random q_a box around the assembly, per actuated joint (rad for
    /// revolute, m for prismatic joints).
    pub range: Vec<f64>,
    /// Smallest accepted reciprocal condition number of Wp at the sample and along the path
    /// (the tracker's hard limit while sampling).
    pub min_wp_ratio: f64,
    /// Rejected moves allowed per sample before giving up.
    pub max_attempts: usize,
    /// qd_a uniform in [-qd_max, qd_max], qdd_a in [-qdd_max, qdd_max].
    pub qd_max: f64,
    /// See `qd_max`.
    pub qdd_max: f64,
    /// Moves rejected so far (diagnostics).
    pub rejected: usize,
}

impl ClosedChainSampler {
    /// Sampler of `robot` (a closed chain) starting from the branch tracker at its assembly
    /// configuration ([`ClosedChain::assembly_branch`]: the file's `assembly`, else q = 0, which
    /// must be closed and regular). Box: +-1.5 rad for revolute actuated joints, +-0.1 m for
    /// prismatic ones.
    pub fn new(robot: &Robot) -> Result<ClosedChainSampler> {
        if robot.is_tree() {
            return Err(Error::Input(format!(
                "{} is a tree: use the tree sampler (random independent joint values)",
                robot.name()
            )));
        }
        let chain = ClosedChain::new(robot)?;
        let start = chain.assembly_branch().map_err(|e| match e {
            Error::LoopNotClosed { .. } => Error::Numerical(format!(
                "{}: the loops do not close at the assembly configuration (give `assembly` in \
                 the robot file): {e}",
                robot.name()
            )),
            e => e,
        })?;
        let range = chain
            .coordinates()
            .frames()
            .iter()
            .map(|&j| match robot.frame(j).joint {
                JointType::Prismatic => 0.1,
                _ => 1.5,
            })
            .collect();
        Ok(ClosedChainSampler {
            chain,
            start,
            range,
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
        let qa0 = self.start.q_a().to_vec();
        let n = qa0.len();
        let target: Vec<f64> = (0..n)
            .map(|k| qa0[k] + rng.random_range(-self.range[k]..self.range[k]))
            .collect();
        // The tracker continues from the assembly along the straight path, refusing a path
        // through a singular configuration (where it may switch assembly branch: the SR400's
        // parallelogram flattens at q7 = q2 and q7 = q2 + pi) and any point whose Wp is below
        // `min_wp_ratio` (near one, G = [I; W] is inaccurate).
        // (the tracker's limit is on the 1-norm reciprocal condition number, which can be p
        // times smaller than sigma_min / sigma_max: the sample itself is checked on the latter)
        let p = self.chain.n_equations().max(1) as f64;
        let limits = ConditioningLimits {
            wp_hard: self.min_wp_ratio / p,
            ..*self.chain.limits()
        };
        let chain = self.chain.clone().with_limits(limits);
        let mut branch = self.start.clone();
        let zeros = vec![0.0; n];
        let s = closed_state(&chain, &mut branch, &target, &zeros, &zeros).ok()?;
        // Newton steps beyond the closure tolerance: the error on q_p (amplified by Wp^-1) would
        // show in the rank decision of the numerical method.
        let qp = refine_closure(&chain, &target, s.q_p.as_slice());
        let mut branch = chain.branch_from(&target, &qp).ok()?;
        let mut v = |s: f64| -> Vec<f64> { (0..n).map(|_| rng.random_range(-s..s)).collect() };
        let (qd, qdd) = (v(self.qd_max), v(self.qdd_max));
        let state = closed_state(&chain, &mut branch, &target, &qd, &qdd).ok()?;
        let sv = state.wp.clone().svd(false, false).singular_values;
        (sv.min() >= self.min_wp_ratio * sv.max()).then_some(state)
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
             (reciprocal condition number < {:e}) around it",
            self.chain.robot().name(),
            self.max_attempts,
            self.start.q_a(),
            self.chain.coordinates().frames(),
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
        // tree arrays (NL entries) from the vectors over the tree's movable joints
        let c = robot.coordinates();
        let tree = |v: &nalgebra::DVector<f64>| {
            let mut t = vec![0.0; robot.nl()];
            c.scatter(v.as_slice(), &mut t);
            t
        };
        let mut g = nalgebra::DMatrix::zeros(robot.nl(), s.g.ncols());
        for (r, &j) in c.frames().iter().enumerate() {
            g.row_mut(j - 1).copy_from(&s.g.row(r));
        }
        Ok(ConsistentSample {
            q: tree(&s.q),
            qd: tree(&s.qd),
            qdd: tree(&s.qdd),
            g: Some(g),
        })
    }
}
