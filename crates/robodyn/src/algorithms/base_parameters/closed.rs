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
//! A general branch tracker (closed-chain continuation with branch checks, planned in the
//! library for `idm`, `ddm`, `simulate`) should replace [`ClosedChainSampler::new`]'s start
//! search and the continuation of `try_move`: the sampler would hold the tracker's branch
//! state and ask it for q_p at each target q_a.

use super::numeric::{ConsistentSample, Sampler};
use super::summary::short;
use super::symbolic::parallelograms;
use crate::algorithms::closed_chain::{ClosedChain, ClosedChainWorkspace, ClosedState};
use crate::error::{Error, Result};
use crate::geometry::frame_transforms;
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

fn det_sign(s: &ClosedState) -> f64 {
    s.constraints.wp.clone().lu().determinant().signum()
}

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
    start: StartReport,
    /// Parallel link pairs of the parallelogram loops: (low, high, lowA_high).
    pairs: Vec<(usize, usize, Matrix3<f64>)>,
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
    /// `assembly` when given, else q = 0 (solved for q_p from that guess when not closed there),
    /// moved to a regular start when q = 0 is singular (see the module documentation).
    /// Box: +-1.5 rad for revolute actuated joints, +-0.1 m for prismatic ones.
    pub fn new(robot: &Robot) -> Result<ClosedChainSampler> {
        if robot.is_tree() {
            return Err(Error::Input(format!(
                "{} is a tree: use the tree sampler (random independent joint values)",
                robot.name()
            )));
        }
        let chain = ClosedChain::new(robot)?;
        let ws = chain.workspace();
        let given = robot.description().assembly.clone();
        let reference = given.clone().unwrap_or_else(|| vec![0.0; robot.nl()]);
        let pick = |js: &[usize], q: &[f64]| -> Vec<f64> {
            js.iter()
                .map(|&j| q.get(j - 1).copied().unwrap_or(0.0))
                .collect()
        };
        let pairs = parallel_pairs(robot)?;
        let range = chain
            .actuated_joints()
            .iter()
            .map(|&j| match robot.frame(j).joint {
                JointType::Prismatic => 0.1,
                _ => 1.5,
            })
            .collect();
        let mut sampler = ClosedChainSampler {
            qa0: pick(chain.actuated_joints(), &reference),
            qp0: pick(chain.passive_joints(), &reference),
            range,
            chain,
            ws,
            continuation: 24,
            min_wp_ratio: 1e-2,
            max_attempts: 200,
            qd_max: 2.0,
            qdd_max: 5.0,
            rejected: 0,
            start: StartReport {
                origin: StartOrigin::Zero,
                q: reference.clone(),
                wp_ratio: 0.0,
                det_sign: 1.0,
                parallelograms: Vec::new(),
            },
            pairs,
        };
        let (qa0, guess) = (sampler.qa0.clone(), sampler.qp0.clone());
        let first = sampler.regular_start(&qa0, &guess);
        let origin = match (&first, &given) {
            (Ok(_), Some(_)) => StartOrigin::Assembly,
            (Ok(_), None) => StartOrigin::Zero,
            (Err((_, e)), Some(_)) => {
                return Err(Error::Numerical(format!(
                    "{}: the assembly configuration cannot start the samples: {e}; give a \
                     regular `assembly` in the robot file",
                    robot.name()
                )))
            }
            (Err((ratio, _)), None) => StartOrigin::Moved {
                ratio_at_zero: *ratio,
            },
        };
        let (qa, qp, ratio, sign) = match first {
            Ok(v) => v,
            Err(_) => sampler.search_start(&qa0, &guess).ok_or_else(|| {
                Error::Numerical(format!(
                    "{}: the file has no assembly, q = 0 is singular (or does not close) and no \
                     regular closed configuration was found near it; give `assembly` in the \
                     robot file",
                    robot.name()
                ))
            })?,
        };
        let mut q = vec![0.0; robot.nl()];
        sampler.chain.closure().assemble(&qa, &qp, &mut q);
        sampler.start = StartReport {
            origin,
            q,
            wp_ratio: ratio,
            det_sign: sign,
            parallelograms: parallelograms(robot.description())?
                .iter()
                .map(|p| p.cut)
                .collect(),
        };
        sampler.qa0 = qa;
        sampler.qp0 = qp;
        Ok(sampler)
    }

    /// How the start was chosen, and its branch.
    pub fn start(&self) -> &StartReport {
        &self.start
    }

    /// Close the loops at `qa` from `guess`; Ok((qa, qp, ratio, det sign)) when the result is
    /// regular and on the parallelogram branch, Err((ratio, reason)) otherwise.
    #[allow(clippy::type_complexity)]
    fn regular_start(
        &mut self,
        qa: &[f64],
        guess: &[f64],
    ) -> std::result::Result<(Vec<f64>, Vec<f64>, f64, f64), (f64, String)> {
        let sol = self
            .chain
            .solve_positions(&mut self.ws, qa, Some(guess))
            .map_err(|e| (0.0, format!("the loops do not close there: {e}")))?;
        let qp = self.polish(qa, sol.q_p);
        let zeros = vec![0.0; qa.len()];
        let st = self
            .chain
            .state(&mut self.ws, qa, &zeros, &zeros, Some(&qp))
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
        if !self.on_parallelograms(&st.q) {
            return Err((r, "it is not on the parallelogram branch (eq 10.54)".into()));
        }
        Ok((qa.to_vec(), qp, r, det_sign(&st)))
    }

    /// Small deterministic moves of q_a around a singular start (0.05 to 0.8 rad, or a tenth
    /// of that in m), each closed from the singular start's q_p: the first regular result on the
    /// parallelogram branch.
    #[allow(clippy::type_complexity)]
    fn search_start(
        &mut self,
        qa0: &[f64],
        guess: &[f64],
    ) -> Option<(Vec<f64>, Vec<f64>, f64, f64)> {
        let mut rng = crate::testing::rng(0x57a7);
        for attempt in 0..60 {
            let size = 0.05 * (1.0 + attempt as f64 / 4.0).min(16.0);
            let qa: Vec<f64> = qa0
                .iter()
                .zip(&self.range)
                .map(|(&x, &r)| x + size * (r / 1.5) * rng.random_range(-1.0..1.0))
                .collect();
            if let Ok(v) = self.regular_start(&qa, guess) {
                return Some(v);
            }
        }
        None
    }

    /// Whether every parallel pair of the parallelogram loops keeps its relative orientation
    /// lowA_high (eq 10.54) at tree configuration `q`.
    fn on_parallelograms(&self, q: &[f64]) -> bool {
        if self.pairs.is_empty() {
            return true;
        }
        let t = frame_transforms(self.chain.robot(), q);
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
            if ratio(&on_path) < self.min_wp_ratio || det_sign(&on_path) != self.start.det_sign {
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
        if ratio(&state) < self.min_wp_ratio
            || det_sign(&state) != self.start.det_sign
            || !self.on_parallelograms(&state.q)
        {
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
