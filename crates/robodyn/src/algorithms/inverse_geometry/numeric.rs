//! Numeric inverse geometric model for any robot: damped least squares (Levenberg–Marquardt)
//! on the placement error, joint limits kept by projecting each step into them, restarts from
//! seeded random starts within the limits.
//!
//! Error of a placement T(q) against the target T*: e = [p* - p; R log3(R^T R*)] (position
//! difference and the SO(3) log map of the rotation difference, both in R_0's axes), whose
//! derivative at e = 0 is the frame Jacobian at the frame's origin in R_0's axes
//! ([`Reference::LocalWorldAligned`]). Step: (J^T J + lambda I) dq = J^T e, q <- clamp(q + dq);
//! lambda divided by 3 after a step that lowers |e|, multiplied by 4 (the step refused)
//! otherwise.
//!
//! Stopping rule, per start: converged when |p* - p| <= `position_tolerance` and the rotation
//! angle <= `rotation_tolerance`; a start is abandoned after `max_iterations` steps or when
//! lambda exceeds 1e10 (no step lowers the error: a local minimum or a limit); then the next
//! start. The result is the first converged start, or the start of smallest residual.

use super::transform_of;
use crate::algorithms::kinematics::{
    frame_jacobian_into, frame_placement, placements_into, FrameId, KinematicsData, Reference,
};
use crate::error::{check_vector, Error, Result};
use crate::geometry::Transform;
use crate::model::{JointType, Robot};
use nalgebra::{DMatrix, DVector, Matrix3, Matrix4, Vector3, Vector6};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The parameters of [`NumericIgm`].
#[derive(Clone, Debug, PartialEq)]
pub struct NumericOptions {
    /// Largest position error of a converged solution (m). Default 1e-10.
    pub position_tolerance: f64,
    /// Largest rotation error (angle, rad) of a converged solution. Default 1e-10.
    pub rotation_tolerance: f64,
    /// Steps per start. Default 100.
    pub max_iterations: usize,
    /// Starts in all (the given start, then random ones). Default 20.
    pub starts: usize,
    /// Seed of the random starts. Default 0.
    pub seed: u64,
    /// Initial Levenberg–Marquardt damping lambda. Default 1e-3.
    pub damping: f64,
}

impl Default for NumericOptions {
    fn default() -> Self {
        NumericOptions {
            position_tolerance: 1e-10,
            rotation_tolerance: 1e-10,
            max_iterations: 100,
            starts: 20,
            seed: 0,
            damping: 1e-3,
        }
    }
}

/// The result of the numeric inverse geometric model for one target.
#[derive(Clone, Debug, PartialEq)]
pub struct NumericSolution {
    /// Joint values (movable joints, frame order), within the limits.
    pub q: Vec<f64>,
    /// Whether both tolerances were met.
    pub converged: bool,
    /// The final position error |p* - p| (m).
    pub position_error: f64,
    /// The final rotation error (angle of R^T R*, rad).
    pub rotation_error: f64,
    /// Steps taken over all starts.
    pub iterations: usize,
    /// Starts used (1: the first start converged).
    pub starts: usize,
}

/// The numeric inverse geometric model of one frame of a robot.
#[derive(Clone, Debug)]
pub struct NumericIgm {
    frame: FrameId,
    options: NumericOptions,
    /// Bounds of the random starts and of the steps, per movable joint.
    lower: Vec<f64>,
    upper: Vec<f64>,
    /// Whether the joint has limits (else the random starts span one turn or 1 m).
    limited: Vec<(bool, bool)>,
}

impl NumericIgm {
    /// The model for frame `frame` ([`Robot::frame_id`]).
    ///
    /// Errors: [`Error::Setting`] for non-positive tolerances, zero starts or iterations.
    pub fn new(robot: &Robot, frame: FrameId, options: NumericOptions) -> Result<Self> {
        super::refuse_floating(robot, "the numeric inverse geometric model")?;
        let bad = |field: &'static str, why: &str| Error::Setting {
            option: field,
            reason: why.to_string(),
        };
        if !(options.position_tolerance > 0.0 && options.rotation_tolerance > 0.0) {
            return Err(bad(
                "inverse_geometry::NumericOptions::position_tolerance",
                "the tolerances of the numeric inverse geometric model must be positive",
            ));
        }
        if options.starts == 0 || options.max_iterations == 0 {
            return Err(bad(
                "inverse_geometry::NumericOptions::starts",
                "the numeric inverse geometric model needs at least one start and one step",
            ));
        }
        if !(options.damping > 0.0 && options.damping.is_finite()) {
            return Err(bad(
                "inverse_geometry::NumericOptions::damping",
                "the initial damping must be positive and finite",
            ));
        }
        let c = robot.coordinates();
        let (mut lower, mut upper, mut limited) = (Vec::new(), Vec::new(), Vec::new());
        for &j in c.frames() {
            let l = robot.description().limits.get(&j);
            let (lo, hi) = (l.and_then(|l| l.q_min), l.and_then(|l| l.q_max));
            lower.push(lo.unwrap_or(f64::NEG_INFINITY));
            upper.push(hi.unwrap_or(f64::INFINITY));
            limited.push((lo.is_some(), hi.is_some()));
        }
        Ok(NumericIgm {
            frame,
            options,
            lower,
            upper,
            limited,
        })
    }

    /// The options.
    pub fn options(&self) -> &NumericOptions {
        &self.options
    }

    /// Joint values placing the frame at the 4x4 placement `target`, starting from `start`
    /// (movable joints; clamped into the limits), then from random starts (seeded by
    /// `options.seed`) until one converges. A target out of reach returns the start of smallest
    /// residual with `converged == false`.
    ///
    /// Errors: as [`super::ClosedFormIgm::solve`] for the target; [`Error::Dimension`],
    /// [`Error::NotFinite`] for `start`.
    pub fn solve(
        &self,
        robot: &Robot,
        target: &Matrix4<f64>,
        start: &[f64],
    ) -> Result<NumericSolution> {
        self.solve_seeded(robot, target, start, self.options.seed)
    }

    fn solve_seeded(
        &self,
        robot: &Robot,
        target: &Matrix4<f64>,
        start: &[f64],
        seed: u64,
    ) -> Result<NumericSolution> {
        let t = transform_of("target", target)?;
        let n = robot.dof();
        check_vector("start", start, n, || "movable joints".into())?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut ws = Workspace::new(robot);
        let mut best: Option<NumericSolution> = None;
        let mut iterations = 0;
        for s in 0..self.options.starts {
            let q0: Vec<f64> = if s == 0 {
                start.to_vec()
            } else {
                self.random_start(robot, start, &mut rng)
            };
            let mut sol = self.descend(robot, &mut ws, &t, q0)?;
            iterations += sol.iterations;
            sol.iterations = iterations;
            sol.starts = s + 1;
            let better = best.as_ref().is_none_or(|b| {
                sol.position_error + sol.rotation_error < b.position_error + b.rotation_error
            });
            if sol.converged {
                return Ok(sol);
            }
            if better {
                best = Some(sol);
            }
        }
        let mut b = best.expect("at least one start");
        b.iterations = iterations;
        b.starts = self.options.starts;
        Ok(b)
    }

    /// A start uniform within the limits (one turn around the given start for an unlimited
    /// revolute joint, 1 m for an unlimited prismatic one).
    fn random_start(&self, robot: &Robot, around: &[f64], rng: &mut ChaCha8Rng) -> Vec<f64> {
        let c = robot.coordinates();
        (0..around.len())
            .map(|k| {
                let span = if robot.frame(c.frame(k)).joint == JointType::Prismatic {
                    0.5
                } else {
                    PI
                };
                let lo = if self.limited[k].0 {
                    self.lower[k]
                } else {
                    around[k] - span
                };
                let hi = if self.limited[k].1 {
                    self.upper[k]
                } else {
                    around[k] + span
                };
                if hi > lo {
                    rng.random_range(lo..=hi)
                } else {
                    lo
                }
            })
            .collect()
    }

    fn clamp(&self, q: &mut [f64]) {
        for (k, x) in q.iter_mut().enumerate() {
            *x = x.clamp(self.lower[k], self.upper[k]);
        }
    }

    /// Levenberg–Marquardt from q (the module's stopping rule).
    fn descend(
        &self,
        robot: &Robot,
        ws: &mut Workspace,
        target: &Transform,
        mut q: Vec<f64>,
    ) -> Result<NumericSolution> {
        let o = &self.options;
        self.clamp(&mut q);
        let mut e = ws.error(robot, &self.frame, target, &q)?;
        let mut lambda = o.damping;
        let mut it = 0;
        let converged = |e: &Vector6<f64>| {
            e.fixed_rows::<3>(0).norm() <= o.position_tolerance
                && e.fixed_rows::<3>(3).norm() <= o.rotation_tolerance
        };
        while !converged(&e) && it < o.max_iterations && lambda < 1e10 {
            it += 1;
            frame_jacobian_into(
                robot,
                &ws.data,
                &self.frame,
                Reference::LocalWorldAligned,
                &mut ws.j,
            )?;
            let jt_e = ws.j.tr_mul(&DVector::from_column_slice(e.as_slice()));
            let jtj = ws.j.tr_mul(&ws.j);
            loop {
                let mut a = jtj.clone();
                for k in 0..a.nrows() {
                    a[(k, k)] += lambda;
                }
                let dq = a.cholesky().map(|c| c.solve(&jt_e));
                let Some(dq) = dq else {
                    lambda *= 4.0;
                    continue;
                };
                let mut trial: Vec<f64> = q.iter().zip(dq.iter()).map(|(a, b)| a + b).collect();
                self.clamp(&mut trial);
                let e_trial = ws.error(robot, &self.frame, target, &trial)?;
                if e_trial.norm() < e.norm() {
                    (q, e) = (trial, e_trial);
                    lambda = (lambda / 3.0).max(1e-12);
                    break;
                }
                lambda *= 4.0;
                if lambda >= 1e10 {
                    // restore the data of q for the next Jacobian
                    ws.error(robot, &self.frame, target, &q)?;
                    break;
                }
            }
        }
        Ok(NumericSolution {
            converged: converged(&e),
            position_error: e.fixed_rows::<3>(0).norm(),
            rotation_error: e.fixed_rows::<3>(3).norm(),
            q,
            iterations: it,
            starts: 1,
        })
    }
}

/// Per-solve buffers.
struct Workspace {
    data: KinematicsData,
    j: DMatrix<f64>,
}

impl Workspace {
    fn new(robot: &Robot) -> Self {
        Workspace {
            data: KinematicsData::new(robot),
            j: DMatrix::zeros(6, robot.dof()),
        }
    }

    /// e = [p* - p; R log3(R^T R*)] at q (the placements of q left in `data`).
    fn error(
        &mut self,
        robot: &Robot,
        frame: &FrameId,
        target: &Transform,
        q: &[f64],
    ) -> Result<Vector6<f64>> {
        placements_into(robot, &mut self.data, q)?;
        let t = frame_placement(robot, &self.data, frame)?;
        let w = t.rot * log3(&t.rot.tr_mul(&target.rot));
        let p = target.pos - t.pos;
        Ok(Vector6::new(p.x, p.y, p.z, w.x, w.y, w.z))
    }
}

/// The SO(3) log map: the rotation vector (axis times angle in [0, pi]) of R. From the
/// antisymmetric part v = vee(R - R^T) / 2 = sin(angle) axis and cos(angle) = (tr R - 1) / 2 by
/// atan2 (exact for small angles, where acos of the trace loses half the digits); near pi the
/// axis comes from the symmetric part (R + I) / 2 = axis axis^T.
pub(crate) fn log3(r: &Matrix3<f64>) -> Vector3<f64> {
    let v = Vector3::new(
        r[(2, 1)] - r[(1, 2)],
        r[(0, 2)] - r[(2, 0)],
        r[(1, 0)] - r[(0, 1)],
    ) / 2.0;
    let s = v.norm();
    let c = ((r.trace() - 1.0) / 2.0).clamp(-1.0, 1.0);
    let angle = s.atan2(c);
    if c > -0.9 {
        return if s < 1e-300 {
            Vector3::zeros()
        } else {
            v * (angle / s)
        };
    }
    let b = (r + Matrix3::identity()) / 2.0;
    let k = (0..3)
        .max_by(|&a, &b2| b[(a, a)].total_cmp(&b[(b2, b2)]))
        .unwrap_or(0);
    let mut axis: Vector3<f64> = b.column(k).into();
    axis /= axis.norm();
    if axis.dot(&v) < 0.0 {
        axis = -axis;
    }
    axis * angle
}

/// [`NumericIgm::solve`] on N targets over the cores (rayon): target i starts from row i of
/// `starts` (N x n row-major, n = `robot.dof()`) with the seed `options.seed + i`; one result
/// per target, an error naming its row (1-based).
///
/// Errors: [`Error::Dimension`] when `starts` does not hold N x n entries.
pub fn numeric_igm_batch(
    robot: &Robot,
    igm: &NumericIgm,
    targets: &[Matrix4<f64>],
    starts: &[f64],
) -> Result<Vec<NumericSolution>> {
    let n = robot.dof();
    if starts.len() != targets.len() * n {
        return Err(Error::dimension(
            "starts",
            targets.len() * n,
            starts.len(),
            format!("{} targets x {n} movable joints", targets.len()),
        ));
    }
    targets
        .par_iter()
        .enumerate()
        .map(|(i, t)| {
            igm.solve_seeded(
                robot,
                t,
                &starts[i * n..(i + 1) * n],
                igm.options.seed + i as u64,
            )
            .map_err(|e| e.in_row(i + 1))
        })
        .collect()
}
