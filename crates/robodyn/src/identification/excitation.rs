//! Excitation trajectories (Swevers, Ganseman, Tükel, De Schutter, Van Brussel 1997): a finite
//! Fourier series per joint,
//!
//! ```text
//!  q_j(t) = q0_j + sum_{l=1..L} a_jl / (w l) sin(w l t) - b_jl / (w l) cos(w l t),
//!  w = 2 pi / T,
//! ```
//!
//! periodic by construction, at rest at t = 0 and t = T (qd = sum_l a_jl = 0 and
//! qdd = w sum_l l b_jl = 0: the last harmonic's a_jL, b_jL are fixed by the others), starting
//! at a given position. The free coefficients minimize the condition number of the
//! base-parameter observation matrix (unit columns) over the period, under position, velocity,
//! acceleration and torque limits (penalties, the trajectory scaled down until it satisfies
//! them).

use super::data::{MemoryLog, RawSample};
use super::model_access::ModelAccess;
use super::parameters::ParameterModel;
use crate::error::{Error, Result};
use argmin::core::{CostFunction, Executor, State};
use argmin::solver::neldermead::NelderMead;
use faer::Mat;
use std::cell::RefCell;
use std::f64::consts::PI;

/// A finite Fourier series per joint, at rest at t = 0 and t = period.
#[derive(Clone, Debug, PartialEq)]
pub struct FourierTrajectory {
    /// Period T_f = 2 pi / w (s).
    pub period: f64,
    /// Position at t = 0 (and t = period).
    pub start: Vec<f64>,
    /// a_jl, b_jl (N x L).
    pub a: Vec<Vec<f64>>,
    /// b_jl (N x L).
    pub b: Vec<Vec<f64>>,
}

impl FourierTrajectory {
    /// Harmonics L.
    pub fn harmonics(&self) -> usize {
        self.a.first().map_or(0, |v| v.len())
    }

    /// Number of free coefficients per joint: 2 (L - 1).
    pub fn free_per_joint(harmonics: usize) -> usize {
        2 * (harmonics - 1)
    }

    /// From the free coefficients (per joint a_j1..a_j(L-1), b_j1..b_j(L-1)): the last
    /// harmonic makes the trajectory start and end at rest.
    pub fn from_free(
        period: f64,
        start: &[f64],
        harmonics: usize,
        free: &[f64],
    ) -> FourierTrajectory {
        let n = start.len();
        let m = Self::free_per_joint(harmonics);
        assert_eq!(free.len(), n * m, "free coefficients");
        let l = harmonics;
        let mut a = vec![vec![0.0; l]; n];
        let mut b = vec![vec![0.0; l]; n];
        for j in 0..n {
            let f = &free[j * m..(j + 1) * m];
            for k in 0..l - 1 {
                a[j][k] = f[k];
                b[j][k] = f[l - 1 + k];
            }
            a[j][l - 1] = -a[j][..l - 1].iter().sum::<f64>();
            b[j][l - 1] = -(0..l - 1).map(|k| (k + 1) as f64 * b[j][k]).sum::<f64>() / l as f64;
        }
        FourierTrajectory {
            period,
            start: start.to_vec(),
            a,
            b,
        }
    }

    /// The free coefficients (inverse of [`FourierTrajectory::from_free`]).
    pub fn free(&self) -> Vec<f64> {
        let l = self.harmonics();
        let mut f = Vec::new();
        for j in 0..self.start.len() {
            f.extend_from_slice(&self.a[j][..l - 1]);
            f.extend_from_slice(&self.b[j][..l - 1]);
        }
        f
    }

    /// q, qd, qdd at time t.
    pub fn eval(&self, t: f64) -> [Vec<f64>; 3] {
        let n = self.start.len();
        let w = 2.0 * PI / self.period;
        let mut q = vec![0.0; n];
        let mut qd = vec![0.0; n];
        let mut qdd = vec![0.0; n];
        for j in 0..n {
            let mut c0 = 0.0;
            for (k, (a, b)) in self.a[j].iter().zip(&self.b[j]).enumerate() {
                let wl = w * (k + 1) as f64;
                let (s, c) = (wl * t).sin_cos();
                q[j] += a / wl * s - b / wl * c;
                c0 += b / wl;
                qd[j] += a * c + b * s;
                qdd[j] += wl * (-a * s + b * c);
            }
            q[j] += self.start[j] + c0;
        }
        [q, qd, qdd]
    }

    /// Multiply every coefficient by s (amplitude about the start position).
    pub fn scaled(&self, s: f64) -> FourierTrajectory {
        let mut t = self.clone();
        for v in t.a.iter_mut().chain(t.b.iter_mut()) {
            for x in v.iter_mut() {
                *x *= s;
            }
        }
        t
    }
}

/// The log the robot (its file's parameters) would give tracking `trajectory` from rest with a
/// PD controller whose loop has bandwidth `loop_hz` (gains from the inertia matrix's diagonal
/// at the start): t, q, qd, qdd and the joint torques every `dt` over `duration`, each row
/// satisfying the direct dynamic model exactly (synthetic logs for tests and benchmarks).
pub fn simulated_log(
    access: &ModelAccess,
    trajectory: &FourierTrajectory,
    duration: f64,
    dt: f64,
    loop_hz: f64,
) -> Result<MemoryLog> {
    let k = access.standard_parameters();
    let q0 = trajectory.eval(0.0)[0].clone();
    let a = access.tracking_model(&k, 1e-3)?.inertia_diagonal(&q0)?;
    let w = 2.0 * PI * loop_hz;
    let kp: Vec<f64> = a.iter().map(|a| a * w * w).collect();
    let kd: Vec<f64> = a.iter().map(|a| 1.4 * a * w).collect();
    let rows =
        access.simulate_tracking(&|t| trajectory.eval(t)[0].clone(), duration, dt, &kp, &kd)?;
    Ok(MemoryLog {
        name: format!("simulated {}", access.name()),
        samples: rows
            .into_iter()
            .map(|(t, [q, qd, qdd, tau])| RawSample {
                t,
                q,
                y: tau,
                qd: Some(qd),
                qdd: Some(qdd),
            })
            .collect(),
    })
}

/// Limits of one joint for the design (velocity and acceleration required).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    /// Lower position limit (rad or m), if any.
    pub q_min: Option<f64>,
    /// Upper position limit (rad or m), if any.
    pub q_max: Option<f64>,
    /// Largest |qd| (rad/s or m/s).
    pub qd: f64,
    /// Largest |qdd| (rad/s² or m/s²).
    pub qdd: f64,
    /// Largest |tau| (N m or N), if any.
    pub tau: Option<f64>,
}

/// The options of [`design`] checked against the robot: its `joints` (actuated, frame order)
/// and `p` identified parameters.
fn check_design_options(joints: &[usize], p: usize, opt: &DesignOptions) -> Result<()> {
    let n = joints.len();
    if opt.harmonics < 2 {
        return Err(Error::Input(format!(
            "{} harmonic(s): at least 2 are needed to start and end at rest",
            opt.harmonics
        )));
    }
    if !(opt.period.is_finite() && opt.period > 0.0) {
        return Err(Error::Input(format!(
            "period {} s must be positive",
            opt.period
        )));
    }
    if opt.start.len() != n || opt.limits.len() != n {
        return Err(Error::Input(format!(
            "{} start values and {} limits given, {n} actuated joints",
            opt.start.len(),
            opt.limits.len()
        )));
    }
    for (j, l) in opt.limits.iter().enumerate() {
        if !(l.qd > 0.0 && l.qdd > 0.0) {
            return Err(Error::Input(format!(
                "joint {}: velocity and acceleration limits must be positive",
                joints[j]
            )));
        }
        if l.q_min.is_some_and(|lo| lo >= opt.start[j])
            || l.q_max.is_some_and(|hi| hi <= opt.start[j])
        {
            return Err(Error::Input(format!(
                "joint {}: the start position {} is not inside the position limits",
                joints[j], opt.start[j]
            )));
        }
    }
    if opt.samples * n <= p {
        return Err(Error::Input(format!(
            "{} samples x {n} joints give fewer equations than the {p} parameters",
            opt.samples
        )));
    }
    Ok(())
}

/// Options of [`design`].
#[derive(Clone, Debug)]
pub struct DesignOptions {
    /// Period of the trajectory (s).
    pub period: f64,
    /// Harmonics L per joint (at least 2: the last one brings the motion to rest).
    pub harmonics: usize,
    /// Start (and end) position of the actuated joints.
    pub start: Vec<f64>,
    /// Limits per actuated joint.
    pub limits: Vec<Limits>,
    /// Samples per period at which W is evaluated.
    pub samples: usize,
    /// Nelder–Mead iterations and random starting points tried first.
    pub iterations: u64,
    /// Random starting points tried before Nelder–Mead starts from the best.
    pub restarts: usize,
    /// Seed of the random starting points.
    pub seed: u64,
}

/// Which limit makes the scale of the trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Binding {
    /// Index of the joint among the actuated joints (0 when `what` is `torque` or `none`).
    pub joint: usize,
    /// `velocity`, `acceleration`, `position`, `torque` or `none`.
    pub what: &'static str,
}

/// A designed trajectory.
#[derive(Clone, Debug)]
pub struct Design {
    /// The trajectory found, scaled to its limits.
    pub trajectory: FourierTrajectory,
    /// Condition number (unit columns) of the base-parameter observation matrix over the period.
    pub condition: f64,
    /// The same for the best random starting point.
    pub initial_condition: f64,
    /// The limit reached by the trajectory.
    pub binding: Binding,
    /// Cost evaluations made.
    pub evaluations: usize,
    /// Largest |q - start|, |qd|, |qdd|, |tau| per joint over the period.
    pub peaks: Vec<[f64; 4]>,
}

/// The evaluation of one candidate: scaled to its limits, the condition number.
struct Problem<'a> {
    inner: RefCell<Inner<'a>>,
    opt: &'a DesignOptions,
}

struct Inner<'a> {
    access: &'a mut ModelAccess,
    params: &'a mut ParameterModel,
    evaluations: usize,
}

/// Penalty cost of a candidate that cannot be evaluated (loop closure fails, singular W).
const FAILED: f64 = 1e3;

impl Problem<'_> {
    /// Scale the candidate to its binding limit; the scaled trajectory and which limit binds.
    fn feasible(&self, free: &[f64]) -> Option<(FourierTrajectory, Binding)> {
        let o = self.opt;
        let tr = FourierTrajectory::from_free(o.period, &o.start, o.harmonics, free);
        let n = o.start.len();
        // dense check of the kinematic limits
        let m = 4 * o.samples;
        let mut peak_qd = vec![0.0f64; n];
        let mut peak_qdd = vec![0.0f64; n];
        let mut up = vec![0.0f64; n];
        let mut down = vec![0.0f64; n];
        for k in 0..m {
            let [q, qd, qdd] = tr.eval(o.period * k as f64 / m as f64);
            for j in 0..n {
                peak_qd[j] = peak_qd[j].max(qd[j].abs());
                peak_qdd[j] = peak_qdd[j].max(qdd[j].abs());
                up[j] = up[j].max(q[j] - o.start[j]);
                down[j] = down[j].max(o.start[j] - q[j]);
            }
        }
        let mut s = f64::INFINITY;
        let mut binding = Binding {
            joint: 0,
            what: "none",
        };
        let mut bind = |v: f64, j: usize, what: &'static str, s: &mut f64| {
            if v < *s {
                *s = v;
                binding = Binding { joint: j, what };
            }
        };
        for (j, l) in o.limits.iter().enumerate() {
            if peak_qd[j] > 0.0 {
                bind(l.qd / peak_qd[j], j, "velocity", &mut s);
            }
            if peak_qdd[j] > 0.0 {
                bind(l.qdd / peak_qdd[j], j, "acceleration", &mut s);
            }
            if let (Some(hi), true) = (l.q_max, up[j] > 0.0) {
                bind((hi - o.start[j]) / up[j], j, "position", &mut s);
            }
            if let (Some(lo), true) = (l.q_min, down[j] > 0.0) {
                bind((o.start[j] - lo) / down[j], j, "position", &mut s);
            }
        }
        if !(s.is_finite() && s > 0.0) {
            return None;
        }
        let mut tr = tr.scaled(s);
        if o.limits.iter().any(|l| l.tau.is_some()) {
            // the torque is not linear in the scale: bisect down to the largest feasible one
            let inner = &mut *self.inner.borrow_mut();
            let ok = |t: &FourierTrajectory, inner: &mut Inner| -> Option<bool> {
                inner.access.restart();
                for k in 0..o.samples {
                    let [q, qd, qdd] = t.eval(o.period * k as f64 / o.samples as f64);
                    let tau = inner.access.inverse_dynamics(&q, &qd, &qdd).ok()?;
                    for (j, l) in o.limits.iter().enumerate() {
                        if l.tau.is_some_and(|m| tau[j].abs() > m) {
                            return Some(false);
                        }
                    }
                }
                Some(true)
            };
            if !ok(&tr, inner)? {
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..12 {
                    let mid = 0.5 * (lo + hi);
                    if ok(&tr.scaled(mid), inner)? {
                        lo = mid;
                    } else {
                        hi = mid;
                    }
                }
                if lo == 0.0 {
                    return None;
                }
                tr = tr.scaled(lo);
                binding = Binding {
                    joint: 0,
                    what: "torque",
                };
            }
        }
        Some((tr, binding))
    }

    /// Condition number of the unit-column W over the samples of a period.
    fn condition(&self, tr: &FourierTrajectory) -> Option<f64> {
        let o = self.opt;
        let inner = &mut *self.inner.borrow_mut();
        inner.evaluations += 1;
        let n = o.start.len();
        let p = inner.params.count();
        let mut w = Mat::<f64>::zeros(o.samples * n, p);
        let mut rows = vec![0.0; n * p];
        let mut tau_e = vec![0.0; n];
        inner.access.restart();
        for k in 0..o.samples {
            let [q, qd, qdd] = tr.eval(o.period * k as f64 / o.samples as f64);
            inner
                .params
                .rows(inner.access, &q, &qd, &qdd, &mut rows, &mut tau_e)
                .ok()?;
            for i in 0..n {
                for c in 0..p {
                    w[(k * n + i, c)] = rows[i * p + c];
                }
            }
        }
        for c in 0..p {
            let norm = (0..w.nrows())
                .map(|i| w[(i, c)] * w[(i, c)])
                .sum::<f64>()
                .sqrt();
            if norm.is_nan() || norm <= 0.0 {
                return None;
            }
            for i in 0..w.nrows() {
                w[(i, c)] /= norm;
            }
        }
        let sv = w.singular_values().ok()?;
        let c = sv[0] / sv[sv.len() - 1];
        c.is_finite().then_some(c)
    }

    fn cost_of(&self, free: &[f64]) -> f64 {
        match self.feasible(free).and_then(|(tr, _)| self.condition(&tr)) {
            Some(c) => c.ln(),
            None => FAILED,
        }
    }
}

impl CostFunction for Problem<'_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, p: &Self::Param) -> std::result::Result<Self::Output, argmin::core::Error> {
        Ok(self.cost_of(p))
    }
}

/// Design an exciting trajectory: random starting points, then Nelder–Mead on the free
/// coefficients; every candidate is scaled to its binding limit before its condition number is
/// computed, so the result satisfies the limits.
pub fn design(
    access: &mut ModelAccess,
    params: &mut ParameterModel,
    opt: &DesignOptions,
) -> Result<Design> {
    use rand::Rng;
    let n = access.actuated_joints().len();
    check_design_options(access.actuated_joints(), params.count(), opt)?;
    let dim = n * FourierTrajectory::free_per_joint(opt.harmonics);
    let problem = Problem {
        inner: RefCell::new(Inner {
            access,
            params,
            evaluations: 0,
        }),
        opt,
    };
    let mut rng = crate::sampling::rng(opt.seed);
    let mut best: Option<(f64, Vec<f64>)> = None;
    for _ in 0..opt.restarts.max(1) {
        let x: Vec<f64> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
        let c = problem.cost_of(&x);
        if best.as_ref().is_none_or(|b| c < b.0) {
            best = Some((c, x));
        }
    }
    let (c0, x0) = best.expect("one start");
    if c0 >= FAILED {
        return Err(Error::Numerical(
            "no random starting trajectory could be evaluated (loop closure failed or a parameter \
             is not excited at all): check the start position and the limits"
                .into(),
        ));
    }
    let mut simplex = vec![x0.clone()];
    for k in 0..dim {
        let mut v = x0.clone();
        v[k] += if v[k] >= 0.0 { -0.5 } else { 0.5 };
        simplex.push(v);
    }
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(1e-8)
        .map_err(|e| Error::Numerical(format!("Nelder-Mead: {e}")))?;
    let res = Executor::new(problem, solver)
        .configure(|s| s.max_iters(opt.iterations))
        .run()
        .map_err(|e| Error::Numerical(format!("the excitation optimization failed: {e}")))?;
    let xbest = res.state.get_best_param().cloned().unwrap_or(x0);
    let problem = res.problem.problem.expect("problem returned");
    let (tr, binding) = problem.feasible(&xbest).ok_or_else(|| {
        Error::Numerical("the optimized trajectory cannot be scaled to the limits".into())
    })?;
    let condition = problem
        .condition(&tr)
        .ok_or_else(|| Error::Numerical("the optimized trajectory's W is singular".into()))?;
    let mut peaks = vec![[0.0f64; 4]; n];
    let inner = &mut *problem.inner.borrow_mut();
    inner.access.restart();
    for k in 0..4 * opt.samples {
        let [q, qd, qdd] = tr.eval(opt.period * k as f64 / (4 * opt.samples) as f64);
        let tau = inner.access.inverse_dynamics(&q, &qd, &qdd)?;
        for j in 0..n {
            let v = [
                (q[j] - opt.start[j]).abs(),
                qd[j].abs(),
                qdd[j].abs(),
                tau[j].abs(),
            ];
            for (a, b) in peaks[j].iter_mut().zip(v) {
                *a = a.max(b);
            }
        }
    }
    Ok(Design {
        trajectory: tr,
        condition,
        initial_condition: c0.exp(),
        binding,
        evaluations: inner.evaluations,
        peaks,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn starts_and_ends_at_rest_and_derivatives_agree() {
        let free: Vec<f64> = (0..2 * 2 * 3)
            .map(|k| ((k * 7 % 5) as f64 - 2.0) * 0.3)
            .collect();
        let tr = FourierTrajectory::from_free(4.0, &[0.2, -0.5], 4, &free);
        assert_eq!(tr.free(), free);
        for t in [0.0, 4.0] {
            let [q, qd, qdd] = tr.eval(t);
            assert!((q[0] - 0.2).abs() < 1e-12 && (q[1] + 0.5).abs() < 1e-12);
            assert!(qd.iter().chain(&qdd).all(|v| v.abs() < 1e-12));
        }
        // finite differences
        let h = 1e-5;
        for t in [0.3, 1.7, 3.1] {
            let [q1, qd1, _] = tr.eval(t - h);
            let [_, qd, qdd] = tr.eval(t);
            let [q2, qd2, _] = tr.eval(t + h);
            for j in 0..2 {
                assert!(((q2[j] - q1[j]) / (2.0 * h) - qd[j]).abs() < 1e-7);
                assert!(((qd2[j] - qd1[j]) / (2.0 * h) - qdd[j]).abs() < 1e-6);
            }
        }
    }
}
