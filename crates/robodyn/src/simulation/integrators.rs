//! Fixed-step classical Runge–Kutta 4 and adaptive Dormand–Prince 5(4) for y' = f(t, y).

// The stage formulas index several parallel arrays with one index: clearer than zips.
#![allow(clippy::needless_range_loop)]

use crate::error::{Error, Result};

/// A first-order ODE y' = f(t, y).
pub trait Ode {
    /// Dimension of y.
    fn dim(&self) -> usize;
    /// Write f(t, y) into `dy`.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<()>;
    /// Called after every accepted step with the new state: an ODE written in local
    /// coordinates of a manifold may move its chart and rewrite `y` there (returning true, so
    /// that the integrator does not reuse f of the old coordinates).
    fn accepted(&mut self, _y: &mut [f64]) -> bool {
        false
    }
}

/// Integration scheme.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Classical RK4 with step `dt` (shortened so as to land on the output times).
    /// Fixed-step RK4.
    Rk4 {
        /// Step (s).
        dt: f64,
    },
    /// Dormand–Prince 5(4) with error control |err_i| <= atol + rtol max(|y_i|, |y_new_i|)
    /// (RMS norm); `h0` the first step (automatic when None), `h_max` the largest step.
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
        /// First step (s); automatic when None.
        h0: Option<f64>,
        /// Largest step (s).
        h_max: Option<f64>,
    },
}

impl Integrator {
    /// RK4 with step `dt` when one is given, else Dormand–Prince 5(4) with `rtol`, `atol` and an
    /// automatic first step (the choice of `simulate` and of the Python package).
    pub fn fixed_or_adaptive(dt: Option<f64>, rtol: f64, atol: f64) -> Integrator {
        match dt {
            Some(dt) => Integrator::Rk4 { dt },
            None => Integrator::Dopri5 {
                rtol,
                atol,
                h0: None,
                h_max: None,
            },
        }
    }

    /// Check the parameters (positive, finite).
    pub fn validate(&self) -> Result<()> {
        let bad = |name: &str, v: f64| {
            Err(Error::Input(format!(
                "{name} = {v} must be a positive finite number"
            )))
        };
        match *self {
            Integrator::Rk4 { dt } if !(dt.is_finite() && dt > 0.0) => bad("dt", dt),
            Integrator::Dopri5 { rtol, .. } if !(rtol.is_finite() && rtol > 0.0) => {
                bad("rtol", rtol)
            }
            Integrator::Dopri5 { atol, .. } if !(atol.is_finite() && atol > 0.0) => {
                bad("atol", atol)
            }
            Integrator::Dopri5 { h0: Some(h), .. } if !(h.is_finite() && h > 0.0) => bad("h0", h),
            Integrator::Dopri5 { h_max: Some(h), .. } if !(h.is_finite() && h > 0.0) => {
                bad("h_max", h)
            }
            _ => Ok(()),
        }
    }
}

/// Counters of an integration.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub accepted: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Right-hand side evaluations.
    pub evaluations: usize,
}

/// Dormand–Prince 5(4) tableau.
const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 5.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
    [
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
    ],
];
/// Fifth-order weights minus the embedded fourth-order weights.
const E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];

/// Stage buffers of the integrators, sized once.
#[derive(Clone, Debug)]
pub struct Stepper {
    /// The scheme.
    pub integrator: Integrator,
    /// Stop with an error after this many steps (accepted + rejected) in total.
    pub max_steps: Option<usize>,
    k: [Vec<f64>; 7],
    tmp: Vec<f64>,
    y1: Vec<f64>,
    err: Vec<f64>,
    /// k[0] holds f(t, y) of the current state (first same as last).
    fsal: bool,
    h: Option<f64>,
    /// Counters.
    pub stats: Stats,
}

fn finite_or_err(y: &[f64]) -> Result<()> {
    match y.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(Error::Numerical(format!(
            "the state became non-finite (state component {} = {})",
            i + 1,
            y[i]
        ))),
        None => Ok(()),
    }
}

impl Stepper {
    /// Stage buffers of `integrator` for a state of dimension `dim`.
    pub fn new(integrator: Integrator, dim: usize) -> Self {
        Stepper {
            integrator,
            max_steps: None,
            k: std::array::from_fn(|_| vec![0.0; dim]),
            tmp: vec![0.0; dim],
            y1: vec![0.0; dim],
            err: vec![0.0; dim],
            fsal: false,
            h: None,
            stats: Stats::default(),
        }
    }

    fn eval(
        &mut self,
        ode: &mut dyn Ode,
        s: usize,
        t: f64,
        y_is_tmp: bool,
        y: &[f64],
    ) -> Result<()> {
        self.stats.evaluations += 1;
        let src = if y_is_tmp { &self.tmp[..] } else { y };
        ode.rhs(t, src, &mut self.k[s])
    }

    fn check_budget(&self) -> Result<()> {
        match self.max_steps {
            Some(m) if self.stats.accepted + self.stats.rejected >= m => {
                Err(Error::Numerical(format!(
                    "stopped by the step limit (max_steps = {m} integration steps, {} accepted \
                     and {} rejected): raise the limit, or if it is already large the motion is \
                     too stiff for the tolerances (e.g. Coulomb friction sticking: smooth it)",
                    self.stats.accepted, self.stats.rejected
                )))
            }
            _ => Ok(()),
        }
    }

    /// One classical RK4 step of size h from (t, y), result in `y` (allocation-free).
    pub fn rk4_step(&mut self, ode: &mut dyn Ode, t: f64, y: &mut [f64], h: f64) -> Result<()> {
        let n = y.len();
        self.eval(ode, 0, t, false, y)?;
        for (s, (c, w)) in [(1, (0.5, 0.5)), (2, (0.5, 0.5)), (3, (1.0, 1.0))] {
            for i in 0..n {
                self.tmp[i] = y[i] + h * w * self.k[s - 1][i];
            }
            self.eval(ode, s, t + c * h, true, y)?;
        }
        for i in 0..n {
            y[i] +=
                h / 6.0 * (self.k[0][i] + 2.0 * self.k[1][i] + 2.0 * self.k[2][i] + self.k[3][i]);
        }
        ode.accepted(y);
        self.fsal = false;
        self.stats.accepted += 1;
        Ok(())
    }

    /// One Dormand–Prince step of size h from (t, y): the fifth-order solution in `y_new()` and
    /// the error estimate (fifth minus embedded fourth order) in `error()`. Uses f(t, y) from
    /// the previous accepted step when available (FSAL).
    pub fn dopri5_step(&mut self, ode: &mut dyn Ode, t: f64, y: &[f64], h: f64) -> Result<()> {
        let n = y.len();
        if !self.fsal {
            self.eval(ode, 0, t, false, y)?;
        }
        for s in 1..7 {
            for i in 0..n {
                let mut acc = 0.0;
                for (r, a) in A[s].iter().enumerate().take(s) {
                    acc += a * self.k[r][i];
                }
                self.tmp[i] = y[i] + h * acc;
            }
            self.eval(ode, s, t + C[s] * h, true, y)?;
        }
        // stage 7 was evaluated at y1 = tmp (A[6] are the fifth-order weights)
        self.y1.copy_from_slice(&self.tmp);
        for i in 0..n {
            let mut e = 0.0;
            for (s, w) in E.iter().enumerate() {
                e += w * self.k[s][i];
            }
            self.err[i] = h * e;
        }
        Ok(())
    }

    /// The last Dormand–Prince solution.
    pub fn y_new(&self) -> &[f64] {
        &self.y1
    }

    /// The last Dormand–Prince error estimate.
    pub fn error(&self) -> &[f64] {
        &self.err
    }

    /// Advance (t, y) to exactly `t_end` with the configured integrator.
    /// On error, `t` is the time reached (the last accepted step for Dormand–Prince).
    pub fn advance(
        &mut self,
        ode: &mut dyn Ode,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
    ) -> Result<()> {
        match self.integrator {
            Integrator::Rk4 { dt } => {
                let span = t_end - *t;
                if span <= 0.0 {
                    return Ok(());
                }
                let steps = ((span / dt) - 1e-9).ceil().max(1.0) as usize;
                let h = span / steps as f64;
                let t0 = *t;
                for s in 0..steps {
                    self.check_budget()?;
                    self.rk4_step(ode, *t, y, h)?;
                    *t = if s + 1 == steps {
                        t_end
                    } else {
                        t0 + (s + 1) as f64 * h
                    };
                    finite_or_err(y)?;
                }
                Ok(())
            }
            Integrator::Dopri5 {
                rtol,
                atol,
                h0,
                h_max,
            } => self.dopri5_advance(ode, t, y, t_end, rtol, atol, h0, h_max),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn dopri5_advance(
        &mut self,
        ode: &mut dyn Ode,
        t: &mut f64,
        y: &mut [f64],
        t_end: f64,
        rtol: f64,
        atol: f64,
        h0: Option<f64>,
        h_max: Option<f64>,
    ) -> Result<()> {
        let n = y.len();
        let h_max = h_max.unwrap_or(f64::INFINITY);
        if self.h.is_none() {
            let h = match h0 {
                Some(h) => h,
                None => {
                    // Hairer's first guess: 0.01 |y| / |f(t0, y0)| in the error norm.
                    self.eval(ode, 0, *t, false, y)?;
                    self.fsal = true;
                    let (mut d0, mut d1) = (0.0, 0.0);
                    for i in 0..n {
                        let sc = atol + rtol * y[i].abs();
                        d0 += (y[i] / sc).powi(2);
                        d1 += (self.k[0][i] / sc).powi(2);
                    }
                    let (d0, d1) = ((d0 / n as f64).sqrt(), (d1 / n as f64).sqrt());
                    if d0 < 1e-5 || d1 < 1e-5 {
                        1e-6
                    } else {
                        0.01 * d0 / d1
                    }
                }
            };
            self.h = Some(h);
        }
        let mut rejected_last = false;
        while *t < t_end {
            let remaining = t_end - *t;
            let mut h = self.h.unwrap().min(h_max);
            let last = h >= remaining * (1.0 - 1e-12);
            if last {
                h = remaining;
            }
            if h <= 1e-14 * t.abs().max(1.0) {
                return Err(Error::Numerical(format!(
                    "step size underflow (h = {h:e}): the tolerances cannot be met (stiff or \
                     diverging motion)"
                )));
            }
            self.check_budget()?;
            self.dopri5_step(ode, *t, y, h)?;
            let mut sum = 0.0;
            for i in 0..n {
                let sc = atol + rtol * y[i].abs().max(self.y1[i].abs());
                sum += (self.err[i] / sc).powi(2);
            }
            let err = (sum / n as f64).sqrt();
            let ok = err <= 1.0 && self.y1.iter().all(|x| x.is_finite());
            let fac = if err.is_finite() {
                (0.9 * err.max(1e-10).powf(-0.2)).clamp(0.2, 5.0)
            } else {
                0.2
            };
            if ok {
                y.copy_from_slice(&self.y1);
                *t = if last { t_end } else { *t + h };
                // FSAL: the last stage is f(t + h, y1), unless the ODE moved its chart
                self.k.swap(0, 6);
                self.fsal = !ode.accepted(y);
                self.stats.accepted += 1;
                let fac = if rejected_last { fac.min(1.0) } else { fac };
                // keep the controller's step when the last step was shortened to hit t_end
                if !last || fac < 1.0 {
                    self.h = Some(h * fac);
                }
                rejected_last = false;
            } else {
                self.stats.rejected += 1;
                self.h = Some(h * fac.min(1.0));
                rejected_last = true;
            }
        }
        finite_or_err(y)
    }
}
