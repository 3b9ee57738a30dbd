//! Joint torque inputs of a simulation: constants, a time series (linear interpolation), or a
//! joint PD controller tracking a reference time series.

use crate::error::{Error, Result};

/// Values sampled at increasing times, linearly interpolated, held constant outside the range.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeSeries {
    times: Vec<f64>,
    /// One row per time, `width` values each.
    values: Vec<Vec<f64>>,
    width: usize,
}

impl TimeSeries {
    /// Check: at least one row, all rows the same width, finite values, strictly increasing times.
    pub fn new(times: Vec<f64>, values: Vec<Vec<f64>>) -> Result<Self> {
        if times.is_empty() || times.len() != values.len() {
            return Err(Error::Input(format!(
                "a time series needs at least one row and one row per time ({} times, {} rows)",
                times.len(),
                values.len()
            )));
        }
        let width = values[0].len();
        for (k, (t, row)) in times.iter().zip(&values).enumerate() {
            if row.len() != width {
                return Err(Error::Input(format!(
                    "time series row {} has {} values, {width} expected",
                    k + 1,
                    row.len()
                )));
            }
            if !t.is_finite() || row.iter().any(|x| !x.is_finite()) {
                return Err(Error::Input(format!(
                    "time series row {} (t = {t}) has a non-finite value",
                    k + 1
                )));
            }
            if k > 0 && *t <= times[k - 1] {
                return Err(Error::Input(format!(
                    "time series row {}: t = {t} is not after the previous time {}",
                    k + 1,
                    times[k - 1]
                )));
            }
        }
        Ok(TimeSeries {
            times,
            values,
            width,
        })
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Interval index k with times[k] <= t < times[k+1], or None outside.
    fn locate(&self, t: f64) -> Option<usize> {
        let n = self.times.len();
        if n < 2 || t < self.times[0] || t >= self.times[n - 1] {
            return None;
        }
        Some(self.times.partition_point(|&x| x <= t) - 1)
    }

    /// Linear interpolation of columns `cols` at time t into `out`.
    pub fn sample(&self, t: f64, cols: std::ops::Range<usize>, out: &mut [f64]) {
        match self.locate(t) {
            Some(k) => {
                let (t0, t1) = (self.times[k], self.times[k + 1]);
                let s = (t - t0) / (t1 - t0);
                for (o, c) in out.iter_mut().zip(cols) {
                    *o = self.values[k][c] + s * (self.values[k + 1][c] - self.values[k][c]);
                }
            }
            None => {
                let row = if t < self.times[0] {
                    &self.values[0]
                } else {
                    &self.values[self.times.len() - 1]
                };
                for (o, c) in out.iter_mut().zip(cols) {
                    *o = row[c];
                }
            }
        }
    }

    /// Slope of the interpolant (0 outside the range) of columns `cols` at t.
    pub fn slope(&self, t: f64, cols: std::ops::Range<usize>, out: &mut [f64]) {
        match self.locate(t) {
            Some(k) => {
                let dt = self.times[k + 1] - self.times[k];
                for (o, c) in out.iter_mut().zip(cols) {
                    *o = (self.values[k + 1][c] - self.values[k][c]) / dt;
                }
            }
            None => out.iter_mut().for_each(|o| *o = 0.0),
        }
    }
}

/// The torque applied to the simulated coordinates.
#[derive(Clone, Debug, PartialEq)]
pub enum TorqueInput {
    /// Constant torques.
    Constant(Vec<f64>),
    /// Torques interpolated in a time series (one column per coordinate).
    Series(TimeSeries),
    /// tau = Kp (q_ref - q) + Kd (qd_ref - qd), per coordinate (no gravity compensation).
    /// The reference holds q_ref in its first `dof` columns and, when `with_velocity`, qd_ref
    /// in the next `dof`; otherwise qd_ref is the slope of the interpolated q_ref.
    Pd {
        /// q_ref (and qd_ref) over time.
        reference: TimeSeries,
        /// Whether the reference has qd_ref columns.
        with_velocity: bool,
        /// Proportional gains (N m/rad or N/m), one per coordinate.
        kp: Vec<f64>,
        /// Derivative gains (N m s/rad or N s/m), one per coordinate.
        kd: Vec<f64>,
    },
}

impl TorqueInput {
    /// The input of a floating robot whose base is free, from joint torques: `base` zero
    /// entries (the wrench applied on the base, 6) before the joints' (constants and series;
    /// a PD input acts on joint positions and is refused by [`super::simulate`] for a floating
    /// base).
    pub fn with_free_base(self, base: usize) -> TorqueInput {
        let widen = |v: &[f64]| -> Vec<f64> {
            std::iter::repeat_n(0.0, base)
                .chain(v.iter().copied())
                .collect()
        };
        match self {
            TorqueInput::Constant(v) => TorqueInput::Constant(widen(&v)),
            TorqueInput::Series(s) => TorqueInput::Series(TimeSeries {
                width: s.width + base,
                values: s.values.iter().map(|r| widen(r)).collect(),
                times: s.times,
            }),
            pd => pd,
        }
    }

    /// Check the sizes against `dof` coordinates.
    pub fn validate(&self, dof: usize) -> Result<()> {
        let bad = |what: String| Err(Error::Input(what));
        match self {
            TorqueInput::Constant(v) if v.len() != dof => bad(format!(
                "{} constant torques given, {dof} expected",
                v.len()
            )),
            TorqueInput::Constant(v) if v.iter().any(|x| !x.is_finite()) => {
                bad("a constant torque is not finite".into())
            }
            TorqueInput::Series(s) if s.width() != dof => bad(format!(
                "the torque series has {} columns, {dof} expected",
                s.width()
            )),
            TorqueInput::Pd {
                reference,
                with_velocity,
                kp,
                kd,
            } => {
                let w = if *with_velocity { 2 * dof } else { dof };
                if reference.width() != w {
                    bad(format!(
                        "the reference has {} columns, {w} expected",
                        reference.width()
                    ))
                } else if kp.len() != dof || kd.len() != dof {
                    bad(format!(
                        "{} Kp and {} Kd gains given, {dof} expected",
                        kp.len(),
                        kd.len()
                    ))
                } else if kp.iter().chain(kd).any(|x| !x.is_finite()) {
                    bad("a PD gain is not finite".into())
                } else {
                    Ok(())
                }
            }
            _ => Ok(()),
        }
    }

    /// The torques at time t and state (q, qd) into `tau` (allocation-free).
    pub fn torque(&self, t: f64, q: &[f64], qd: &[f64], tau: &mut [f64]) {
        let n = tau.len();
        match self {
            TorqueInput::Constant(v) => tau.copy_from_slice(v),
            TorqueInput::Series(s) => s.sample(t, 0..n, tau),
            TorqueInput::Pd {
                reference,
                with_velocity,
                kp,
                kd,
            } => {
                // tau first holds q_ref, then the torque; qd_ref is accumulated term by term.
                reference.sample(t, 0..n, tau);
                for i in 0..n {
                    tau[i] = kp[i] * (tau[i] - q[i]) - kd[i] * qd[i];
                }
                let mut v = [0.0];
                for i in 0..n {
                    if *with_velocity {
                        reference.sample(t, n + i..n + i + 1, &mut v);
                    } else {
                        reference.slope(t, i..i + 1, &mut v);
                    }
                    tau[i] += kd[i] * v[0];
                }
            }
        }
    }
}
