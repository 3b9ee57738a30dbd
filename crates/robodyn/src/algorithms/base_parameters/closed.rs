//! Random consistent states of a closed chain for the numerical method (§10.3.4).
//!
//! [`ClosedChainSampler`] draws q_a uniformly in a box around the assembly configuration (the
//! file's `assembly`, else q = 0) and solves q_p with the branch tracker from the start (as `robodyn closure` does): every sample is on the branch the assembly defines. (A
//! random walk continuing from the previous sample was tried first: on the SR400, whose assembly
//! is a flattened parallelogram, the walk crosses the bifurcation set q7 = q2 and mixes the
//! parallelogram and crossed branches, giving 50 base parameters instead of 42.) A sample is
//! rejected (another drawn) when the closure fails or Wp is ill-conditioned at the sample or
//! anywhere on the continuation path (a path through a singular configuration may switch
//! assembly branch; near one, G = [I; W] is inaccurate). Velocities and accelerations come from
//! [`crate::closed_state`]: qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Psi (10.42);
//! G = d q_tr / d q_a (10.40).
//!
//! The start must be a regular configuration on the intended branch ([`StartReport`]): a start
//! where Wp is singular (sigma_min/sigma_max below `min_wp_ratio`: OpenSYMORO's SR400 `.par`
//! has no assembly and q = 0 is its flattened parallelogram) or, for a parallelogram loop,
//! one off the parallelogram branch (eq 10.54 checked: the parallel links keep their relative
//! orientation) is refused when the file gave it as its `assembly`, and otherwise replaced by
//! the nearest regular start found by small deterministic moves of q_a, stated in the report.
//! Every sample then keeps the start's sign of det Wp (the branch invariant: a path that keeps
//! Wp regular keeps its sign) and, for parallelograms, the parallelogram relation.
//!
//! Every sample is reached by the library's branch tracker ([`crate::Branch`]) from the start:
//! continuation along the straight path in q_a with the sign of det Wp and the conditioning
//! checked at each step, as `idm`, `ddm` and `simulate` do.

use super::numeric::{ConsistentSample, Sampler};
use super::summary::short;
use super::symbolic::parallelograms;
use crate::algorithms::closed_chain::{
    closed_state, refine_closure, Branch, ClosedChain, ClosedState, ConditioningLimits,
};
use crate::error::{Error, Result};
use crate::geometry::frame_transforms_per_frame;
use crate::model::{JointType, Robot};
use nalgebra::Matrix3;
use rand::{Rng, RngCore};

/// Where the sampler's start comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum StartOrigin {
    /// The file's `assembly`.
    Assembly,
    /// q = 0 (no assembly in the file), regular.
    Zero,
    /// q = 0 is singular or off the parallelogram branch: moved to a regular start nearby.
    Moved {
        /// sigma_min/sigma_max of Wp at q = 0 (after closure), 0 when it did not close.
        ratio_at_zero: f64,
    },
}

/// The start of the closed-chain sampler: a regular closed configuration and its branch.
#[derive(Clone, Debug, PartialEq)]
pub struct StartReport {
    /// Where the start comes from (assembly, q = 0, or moved from q = 0).
    pub origin: StartOrigin,
    /// Tree joint values 1..NL at the start (closed).
    pub q: Vec<f64>,
    /// sigma_min/sigma_max of Wp at the start.
    pub wp_ratio: f64,
    /// Sign of det Wp at the start (kept by every sample).
    pub det_sign: f64,
    /// Cut joints of the parallelogram loops (on their parallelogram branch at the start).
    pub parallelograms: Vec<usize>,
}

impl StartReport {
    /// One sentence for the report.
    pub fn describe(&self) -> String {
        let q: Vec<String> = self
            .q
            .iter()
            .map(|&x| short((x * 1e6).round() / 1e6))
            .collect();
        let branch = format!(
            "det Wp {} 0, sigma_min/sigma_max(Wp) = {}{}",
            if self.det_sign > 0.0 { ">" } else { "<" },
            short((self.wp_ratio * 1e4).round() / 1e4),
            if self.parallelograms.is_empty() {
                String::new()
            } else {
                format!(
                    ", parallelogram branch of the loop(s) cut at {:?}",
                    self.parallelograms
                )
            }
        );
        match &self.origin {
            StartOrigin::Assembly => format!(
                "samples on the branch of the file's assembly q = [{}] ({branch})",
                q.join(", ")
            ),
            StartOrigin::Zero => format!(
                "the file has no assembly: samples on the branch of q = 0 ({branch}); give \
                 `assembly` to choose another"
            ),
            StartOrigin::Moved { ratio_at_zero } => format!(
                "the file has no assembly and q = 0 is {} (sigma_min/sigma_max(Wp) = {}): the \
                 samples start from the regular configuration q = [{}] ({branch}); give \
                 `assembly` in the robot file to choose the branch",
                if *ratio_at_zero > 0.0 {
                    "singular or off the parallelogram branch"
                } else {
                    "not closed"
                },
                short(*ratio_at_zero),
                q.join(", ")
            ),
        }
    }
}

/// sigma_min / sigma_max of Wp at a state (0 when degenerate).
fn ratio(s: &ClosedState) -> f64 {
    let sv = s.wp.clone().svd(false, false).singular_values;
    let (lo, hi) = (sv.min(), sv.max());
    if hi > 0.0 && lo.is_finite() {
        lo / hi
    } else {
        0.0
    }
}

fn det_sign(s: &ClosedState) -> f64 {
    s.wp.clone().lu().determinant().signum()
}

/// Loop-closure sampler of a closed-chain robot (see the module documentation).
#[derive(Clone, Debug)]
pub struct ClosedChainSampler {
    chain: ClosedChain,
    /// The branch tracker at the start: every sample is reached from it.
    branch: Branch,
    /// Half-width of the random q_a box around the start, per actuated joint (rad for
    /// revolute, m for prismatic joints).
    pub range: Vec<f64>,
    /// Smallest accepted sigma_min / sigma_max of Wp at the sample and along the path.
    pub min_wp_ratio: f64,
    /// Rejected moves allowed per sample before giving up.
    pub max_attempts: usize,
    /// qd_a uniform in [-qd_max, qd_max], qdd_a in [-qdd_max, qdd_max].
    pub qd_max: f64,
    /// See `qd_max`.
    pub qdd_max: f64,
    /// Moves rejected so far (diagnostics).
    pub rejected: usize,
    start: StartReport,
    /// Parallel link pairs of the parallelogram loops: (low, high, lowA_high).
    pairs: Vec<(usize, usize, Matrix3<f64>)>,
}

/// Default smallest accepted sigma_min / sigma_max of Wp.
const MIN_WP_RATIO: f64 = 1e-2;

/// A regular start: its tracker, sigma_min/sigma_max of Wp and the tree configuration (NL).
type Start = (Branch, f64, Vec<f64>);

/// What the start search and the sample checks need.
struct Probe<'a> {
    chain: &'a ClosedChain,
    pairs: &'a [(usize, usize, Matrix3<f64>)],
    range: &'a [f64],
    min_wp_ratio: f64,
}

impl Probe<'_> {
    /// Close the loops at `qa` from `guess` and check the result: Ok when regular and on the
    /// parallelogram branch, Err((sigma_min/sigma_max of Wp, reason)) otherwise.
    fn regular_start(
        &self,
        qa: &[f64],
        guess: &[f64],
    ) -> std::result::Result<Start, (f64, String)> {
        let b = self
            .chain
            .branch_from(qa, guess)
            .map_err(|e| (0.0, format!("the loops do not close regularly there: {e}")))?;
        let qp = refine_closure(self.chain, qa, b.q_p());
        let mut b = self
            .chain
            .branch_from(qa, &qp)
            .map_err(|e| (0.0, e.to_string()))?;
        let zeros = vec![0.0; qa.len()];
        let st = closed_state(self.chain, &mut b, qa, &zeros, &zeros)
            .map_err(|e| (0.0, e.to_string()))?;
        let r = ratio(&st);
        if r < self.min_wp_ratio {
            return Err((
                r,
                format!(
                    "Wp is singular there (sigma_min/sigma_max = {r:e} < {:e})",
                    self.min_wp_ratio
                ),
            ));
        }
        let q = self.tree_q(&st);
        if !self.on_parallelograms(&q) {
            return Err((r, "it is not on the parallelogram branch (eq 10.54)".into()));
        }
        Ok((b, r, q))
    }

    /// Small deterministic moves of q_a around a singular start (0.05 to 0.8 rad, or a tenth
    /// of that in m), each closed from the singular start's q_p: the first regular result on the
    /// parallelogram branch.
    fn search_start(&self, qa0: &[f64], guess: &[f64]) -> Option<Start> {
        let mut rng = crate::sampling::rng(0x57a7);
        for attempt in 0..60 {
            let size = 0.05 * (1.0 + attempt as f64 / 4.0).min(16.0);
            let qa: Vec<f64> = qa0
                .iter()
                .zip(self.range)
                .map(|(&x, &r)| x + size * (r / 1.5) * rng.random_range(-1.0..1.0))
                .collect();
            if let Ok(v) = self.regular_start(&qa, guess) {
                return Some(v);
            }
        }
        None
    }

    /// Tree joint values 1..NL of a closed state (fixed frames 0).
    fn tree_q(&self, s: &ClosedState) -> Vec<f64> {
        let robot = self.chain.robot();
        let mut q = vec![0.0; robot.nl()];
        robot.coordinates().scatter(s.q.as_slice(), &mut q);
        q
    }

    /// Whether every parallel pair of the parallelogram loops keeps its relative orientation
    /// lowA_high (eq 10.54) at tree configuration `q`.
    fn on_parallelograms(&self, q: &[f64]) -> bool {
        if self.pairs.is_empty() {
            return true;
        }
        let t = frame_transforms_per_frame(self.chain.robot(), q);
        let rot = |j: usize| {
            if j == 0 {
                Matrix3::identity()
            } else {
                t[j - 1].rot
            }
        };
        self.pairs
            .iter()
            .all(|(lo, hi, a)| (rot(*lo).transpose() * rot(*hi) - a).amax() < 1e-6)
    }
}

impl ClosedChainSampler {
    /// Sampler of `robot` (a closed chain) starting from its assembly configuration: the file's
    /// `assembly` when given, else q = 0, moved to a regular start nearby when q = 0 is singular
    /// or off the parallelogram branch (see the module documentation). Box: +-1.5 rad for
    /// revolute actuated joints, +-0.1 m for prismatic ones.
    pub fn new(robot: &Robot) -> Result<ClosedChainSampler> {
        if robot.is_tree() {
            return Err(Error::Input(format!(
                "{} is a tree: use the tree sampler (random independent joint values)",
                robot.name()
            )));
        }
        let chain = ClosedChain::new(robot)?;
        let given = robot.description().assembly.is_some();
        let reference = robot
            .description()
            .assembly
            .clone()
            .unwrap_or_else(|| vec![0.0; robot.nl()]);
        let pick = |c: &crate::Coordinates| -> Vec<f64> {
            c.frames().iter().map(|&j| reference[j - 1]).collect()
        };
        let (qa0, qp0) = (pick(chain.coordinates()), pick(chain.passive_coordinates()));
        let range: Vec<f64> = chain
            .coordinates()
            .frames()
            .iter()
            .map(|&j| match robot.frame(j).joint {
                JointType::Prismatic => 0.1,
                _ => 1.5,
            })
            .collect();
        let pairs = parallel_pairs(robot)?;
        let probe = Probe {
            chain: &chain,
            pairs: &pairs,
            range: &range,
            min_wp_ratio: MIN_WP_RATIO,
        };
        let first = probe.regular_start(&qa0, &qp0);
        let origin = match (&first, given) {
            (Ok(_), true) => StartOrigin::Assembly,
            (Ok(_), false) => StartOrigin::Zero,
            (Err((_, e)), true) => {
                return Err(Error::Numerical(format!(
                    "{}: the assembly configuration cannot start the samples: {e}; give a \
                     regular `assembly` in the robot file",
                    robot.name()
                )))
            }
            (Err((ratio, _)), false) => StartOrigin::Moved {
                ratio_at_zero: *ratio,
            },
        };
        let (branch, ratio, q) = match first {
            Ok(v) => v,
            Err(_) => probe.search_start(&qa0, &qp0).ok_or_else(|| {
                Error::Numerical(format!(
                    "{}: the file has no assembly, q = 0 is singular (or does not close) and no \
                     regular closed configuration was found near it; give `assembly` in the \
                     robot file",
                    robot.name()
                ))
            })?,
        };
        let start = StartReport {
            origin,
            q,
            wp_ratio: ratio,
            det_sign: branch.det_sign(),
            parallelograms: parallelograms(robot.description())?
                .iter()
                .map(|p| p.cut)
                .collect(),
        };
        Ok(ClosedChainSampler {
            chain,
            branch,
            range,
            min_wp_ratio: MIN_WP_RATIO,
            max_attempts: 200,
            qd_max: 2.0,
            qdd_max: 5.0,
            rejected: 0,
            start,
            pairs,
        })
    }

    /// How the start was chosen, and its branch.
    pub fn start(&self) -> &StartReport {
        &self.start
    }

    /// The closed-chain model used for the samples.
    pub fn chain(&self) -> &ClosedChain {
        &self.chain
    }

    /// Try one random configuration; `None` when rejected.
    fn try_move(&mut self, rng: &mut dyn RngCore) -> Option<ClosedState> {
        let qa0 = self.branch.q_a().to_vec();
        let n = qa0.len();
        let target: Vec<f64> = (0..n)
            .map(|k| qa0[k] + rng.random_range(-self.range[k]..self.range[k]))
            .collect();
        // The tracker continues from the start along the straight path, refusing a path
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
        let mut branch = self.branch.clone();
        let zeros = vec![0.0; n];
        let s = closed_state(&chain, &mut branch, &target, &zeros, &zeros).ok()?;
        // Newton steps beyond the closure tolerance: the error on q_p (amplified by Wp^-1) would
        // show in the rank decision of the numerical method.
        let qp = refine_closure(&chain, &target, s.q_p.as_slice());
        let mut branch = chain.branch_from(&target, &qp).ok()?;
        let mut v = |s: f64| -> Vec<f64> { (0..n).map(|_| rng.random_range(-s..s)).collect() };
        let (qd, qdd) = (v(self.qd_max), v(self.qdd_max));
        let state = closed_state(&chain, &mut branch, &target, &qd, &qdd).ok()?;
        let probe = Probe {
            chain: &self.chain,
            pairs: &self.pairs,
            range: &self.range,
            min_wp_ratio: self.min_wp_ratio,
        };
        (ratio(&state) >= self.min_wp_ratio
            && det_sign(&state) == self.start.det_sign
            && probe.on_parallelograms(&probe.tree_q(&state)))
        .then_some(state)
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
            self.branch.q_a(),
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

/// The parallel link pairs of the parallelogram loops of `robot`, lowA_high evaluated.
fn parallel_pairs(robot: &Robot) -> Result<Vec<(usize, usize, Matrix3<f64>)>> {
    let desc = robot.description();
    let env = |s: &str| desc.symbols.get(s).copied();
    let mut out = Vec::new();
    for p in parallelograms(desc)? {
        for (lo, hi, a) in p.pairs {
            let mut m = Matrix3::zeros();
            for r in 0..3 {
                for c in 0..3 {
                    m[(r, c)] = a[(r, c)].eval(&env).map_err(|e| {
                        Error::Input(format!("parallelogram of loop {}: {e}", p.cut))
                    })?;
                }
            }
            out.push((lo, hi, m));
        }
    }
    Ok(out)
}
