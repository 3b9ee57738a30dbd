//! One streaming pass over a log: filtered positions, central differences, the rows of the
//! observation matrix W and the torques Y, the parallel decimation of both, and the rows folded
//! into one triangular factor per joint (fit and validation segments) — and, for IDIM-IV, the
//! rows of the instrument matrix from a simulation of the current model tracking the measured
//! motion. Memory does not depend on the length of the log.

use super::data::{LogSource, RawSample, MAX_MAGNITUDE};
use super::estimators::{IvAccumulator, TriangularFactor};
use super::model_access::{ModelAccess, TrackingModel};
use super::parameters::ParameterModel;
use super::signal::{central_differences, Butterworth, ParallelFilter, ZeroPhaseStream};
use crate::error::{Error, Result};
use std::collections::VecDeque;

/// How a log is processed (every number printed by the report).
#[derive(Clone, Debug)]
pub struct Processing {
    /// Sample time of the log (s).
    pub dt: f64,
    /// Samples in the log (the count of its first read).
    pub samples: usize,
    /// Zero-phase low-pass of the positions (None when the log gives qd and qdd).
    pub lowpass: Option<Butterworth>,
    /// Keep every `decimation`-th sample after the parallel low-pass.
    pub decimation: usize,
    /// Low-pass of the parallel decimation (None when `decimation` is 1).
    pub decimation_filter: Option<Butterworth>,
    /// Outputs of the decimation filter skipped at the start (its transient; input rate).
    pub decimation_skip: usize,
    /// Samples dropped at each end (input rate).
    pub border: usize,
    /// Time interval [from, to) whose rows are kept for validation instead of the fit.
    pub validation: Option<(f64, f64)>,
    /// Drive gains: Y = gains * current (per joint; with a transmission, motor currents and
    /// Y = R^T (gains * current)).
    pub gains: Option<Vec<f64>>,
    /// A joint's row of a decimated sample is left out when |qd_j| is below this (rad/s or m/s).
    pub min_speed: f64,
    /// Dead band of the sign of the Coulomb friction (rad/s or m/s; 0: the exact sign).
    pub coulomb_band: f64,
    /// Rows of the validation segment kept for the plot: one decimated row in this many (0:
    /// none), so that at most [`MAX_KEPT_ROWS`] are held whatever the log's length.
    pub validation_row_stride: usize,
}

/// Most decimated validation rows kept for the plot (a plot shows no more; each holds N (p + 1)
/// numbers).
pub const MAX_KEPT_ROWS: usize = 20_000;

/// Decimated validation rows (for the plot): t, Y (N per sample), W (N p per sample).
#[derive(Clone, Debug, Default)]
pub struct ValidationRows {
    /// Time of each decimated sample (s).
    pub t: Vec<f64>,
    /// Y per sample: the N measured torques (N m or N).
    pub y: Vec<Vec<f64>>,
    /// W per sample: N rows of p, row-major.
    pub w: Vec<Vec<f64>>,
}

/// What a pass produced.
#[derive(Clone, Debug)]
pub struct PassResult {
    /// One factor per joint of the fit rows and of the validation rows.
    pub fit: Vec<TriangularFactor>,
    /// The same for the validation rows.
    pub validation: Vec<TriangularFactor>,
    /// The validation rows at the log's rate, before the decimation filter: W and the raw
    /// torques as measured.
    pub validation_raw: Vec<TriangularFactor>,
    /// Instrumental-variable accumulators per joint (fit rows) when instruments were given.
    pub iv: Option<Vec<IvAccumulator>>,
    /// Samples read from the log (input rate).
    pub samples_read: usize,
    /// Samples between the borders (input rate).
    pub samples_used: usize,
    /// Decimated samples in the fit.
    pub fit_samples: usize,
    /// Decimated samples in the validation segment.
    pub validation_samples: usize,
    /// Rows left out by `min_speed`, per joint.
    pub slow_rows: Vec<usize>,
    /// Decimated validation rows, when `keep_validation_rows`.
    pub validation_rows: ValidationRows,
    /// Largest |q_sim - q_measured| of the instrument simulation (rad or m).
    pub instrument_deviation: f64,
}

/// A measured sample the simulation tracks: t, q, qd and the torque.
type Reference = (f64, Vec<f64>, Vec<f64>, Vec<f64>);

/// The simulation behind the instruments of IDIM-IV: the current model driven by the measured
/// torque (offsets removed) plus a PD correction toward the measured (filtered) motion, so that
/// it follows the motion without the measurement noise; the instrument rows are W at the
/// simulated states.
pub struct Instruments {
    /// The robot with the current estimate as its parameters.
    pub model: TrackingModel,
    /// Proportional gains of the tracking loop per joint (N m / rad or N / m).
    pub kp: Vec<f64>,
    /// Derivative gains per joint (N m s / rad or N s / m).
    pub kd: Vec<f64>,
    /// Torque offsets of the estimate, removed from the measured torque (N m or N).
    pub offsets: Vec<f64>,
    /// RK4 steps per sample.
    pub substeps: usize,
    state: Option<(Vec<f64>, Vec<f64>)>,
    previous: Option<Reference>,
    deviation: f64,
}

impl Instruments {
    /// A simulation that starts at the first measured sample.
    pub fn new(
        model: TrackingModel,
        kp: Vec<f64>,
        kd: Vec<f64>,
        offsets: Vec<f64>,
        substeps: usize,
    ) -> Self {
        Instruments {
            model,
            kp,
            kd,
            offsets,
            substeps: substeps.max(1),
            state: None,
            previous: None,
            deviation: 0.0,
        }
    }

    fn accel(
        &mut self,
        q: &[f64],
        qd: &[f64],
        reference: &Reference,
        out: &mut [f64],
    ) -> Result<()> {
        let (_, qr, qdr, y) = reference;
        let tau: Vec<f64> = (0..q.len())
            .map(|k| {
                y[k] - self.offsets[k] + self.kp[k] * (qr[k] - q[k]) + self.kd[k] * (qdr[k] - qd[k])
            })
            .collect();
        self.model.accel(q, qd, &tau, out)
    }

    /// Advance by `dt` to the sample (t, q, qd, y) and return the simulated state there.
    fn step(
        &mut self,
        (t, dt): (f64, f64),
        q: &[f64],
        qd: &[f64],
        y: &[f64],
    ) -> Result<[Vec<f64>; 3]> {
        let n = q.len();
        let current = (t, q.to_vec(), qd.to_vec(), y.to_vec());
        let (mut qs, mut qds) = match (self.state.take(), self.previous.take()) {
            (Some(s), Some(prev)) => {
                // RK4 with the previous sample's reference and torque held (zero-order hold)
                // the step from the log's sample time, not from differences of time stamps
                // (Unix times lose digits)
                let h = dt / self.substeps as f64;
                let (mut qs, mut qds) = s;
                let mut k = [
                    vec![0.0; 2 * n],
                    vec![0.0; 2 * n],
                    vec![0.0; 2 * n],
                    vec![0.0; 2 * n],
                ];
                let mut a = vec![0.0; n];
                for _ in 0..self.substeps {
                    let mut yq = qs.clone();
                    let mut yv = qds.clone();
                    for st in 0..4 {
                        if st > 0 {
                            let c = if st == 3 { 1.0 } else { 0.5 };
                            for i in 0..n {
                                yq[i] = qs[i] + c * h * k[st - 1][i];
                                yv[i] = qds[i] + c * h * k[st - 1][n + i];
                            }
                        }
                        self.accel(&yq, &yv, &prev, &mut a)?;
                        k[st][..n].copy_from_slice(&yv);
                        k[st][n..].copy_from_slice(&a);
                    }
                    for i in 0..n {
                        qs[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
                        qds[i] += h / 6.0
                            * (k[0][n + i] + 2.0 * k[1][n + i] + 2.0 * k[2][n + i] + k[3][n + i]);
                    }
                }
                if qs.iter().chain(&qds).any(|v| !v.is_finite()) {
                    return Err(Error::Numerical(format!(
                        "the instrument simulation of the current model diverged at t = {t} s"
                    )));
                }
                (qs, qds)
            }
            _ => (q.to_vec(), qd.to_vec()),
        };
        let mut qdd = vec![0.0; n];
        self.accel(&qs, &qds, &current, &mut qdd)?;
        for i in 0..n {
            self.deviation = self.deviation.max((qs[i] - q[i]).abs());
        }
        self.previous = Some(current);
        self.state = Some((qs.clone(), qds.clone()));
        Ok([std::mem::take(&mut qs), std::mem::take(&mut qds), qdd])
    }
}

/// A sample after filtering and differentiation.
struct Processed {
    t: f64,
    q: Vec<f64>,
    qd: Vec<f64>,
    qdd: Vec<f64>,
    y: Vec<f64>,
}

/// Where the model's torques of every kept sample go in a prediction pass: the parameters x
/// and a sink called with (t, tau) per sample, tau the N joint torques W x + tau_e.
pub struct PredictionSink<'a> {
    /// The identified parameters (in the order of the parameter model).
    pub x: &'a [f64],
    /// Called once per sample between the borders, in order.
    pub sink: &'a mut dyn FnMut(f64, &[f64]) -> Result<()>,
}

struct Pass<'a> {
    params: &'a mut ParameterModel,
    access: &'a mut ModelAccess,
    proc: &'a Processing,
    instruments: Option<&'a mut Instruments>,
    predict: Option<PredictionSink<'a>>,
    n: usize,
    p: usize,
    stream: Option<ZeroPhaseStream>,
    pending: VecDeque<(f64, Vec<f64>)>,
    window: VecDeque<(f64, Vec<f64>, Vec<f64>)>,
    processed: usize,
    processed_total: usize,
    decimator: Option<ParallelFilter>,
    dec_count: usize,
    dec_skip: usize,
    channels: Vec<f64>,
    w: Vec<f64>,
    z: Vec<f64>,
    tau_e: Vec<f64>,
    out: PassResult,
}

impl Pass<'_> {
    fn raw(&mut self, s: RawSample) -> Result<()> {
        self.out.samples_read += 1;
        let y = match &self.proc.gains {
            Some(g) => {
                let scaled: Vec<f64> = s.y.iter().zip(g).map(|(i, g)| i * g).collect();
                match &self.params.transmission {
                    // tau = R^T tau_m
                    Some(r) => (0..self.n)
                        .map(|c| (0..self.n).map(|m| r[m][c] * scaled[m]).sum())
                        .collect(),
                    None => scaled,
                }
            }
            None => s.y,
        };
        // the processing decides (the log's qd, qdd or filtered differences), not the sample
        match (self.stream.as_mut(), s.qd, s.qdd) {
            (None, Some(qd), Some(qdd)) => self.processed_sample(Processed {
                t: s.t,
                q: s.q,
                qd,
                qdd,
                y,
            }),
            (None, _, _) => Err(Error::Input(
                "the log has no qd/qdd and no position filter was set".into(),
            )),
            (Some(stream), _, _) => {
                self.pending.push_back((s.t, y));
                let mut outs = Vec::new();
                stream.push(&s.q, &mut |v| outs.push(v.to_vec()));
                for q in outs {
                    self.filtered(q)?;
                }
                Ok(())
            }
        }
    }

    /// A filtered position sample, in order: central differences need its neighbours.
    fn filtered(&mut self, q: Vec<f64>) -> Result<()> {
        let (t, y) = self
            .pending
            .pop_front()
            .expect("one pending sample per filtered one");
        self.window.push_back((t, q, y));
        if self.window.len() == 3 {
            let (a, b, c) = (&self.window[0], &self.window[1], &self.window[2]);
            let dt = self.proc.dt;
            let (mut qd, mut qdd) = (vec![0.0; self.n], vec![0.0; self.n]);
            for k in 0..self.n {
                (qd[k], qdd[k]) = central_differences(a.1[k], b.1[k], c.1[k], dt);
            }
            let s = Processed {
                t: b.0,
                q: b.1.clone(),
                qd,
                qdd,
                y: b.2.clone(),
            };
            self.window.pop_front();
            self.processed_sample(s)?;
        }
        Ok(())
    }

    /// Border removal: the first and the last `border` processed samples are dropped (their
    /// count is known from the log's first read: nothing is held back).
    fn processed_sample(&mut self, s: Processed) -> Result<()> {
        self.processed += 1;
        let border = self.proc.border;
        if self.processed <= border || self.processed + border > self.processed_total {
            return Ok(());
        }
        self.kept(s)
    }

    /// Every entry of the rows of W and of Y at `t` finite and of magnitude at most
    /// [`MAX_MAGNITUDE`] (else the sums of squares of the least squares overflow): an error
    /// naming the parameter, the joint and the time.
    fn check_rows(&self, t: f64, y: &[f64]) -> Result<()> {
        let (n, p) = (self.n, self.p);
        let bad = |v: f64| !(v.is_finite() && v.abs() <= MAX_MAGNITUDE);
        if let Some(i) = self.w.iter().position(|&v| bad(v)) {
            return Err(Error::Numerical(format!(
                "at t = {t} s the observation matrix has {:e} in the column of {} and the row of \
                 joint {} (not a finite number of magnitude at most {MAX_MAGNITUDE:e}: are the \
                 positions, velocities or accelerations of the log in range?)",
                self.w[i],
                self.params.params[i % p].name,
                self.params.joints[i / p]
            )));
        }
        if let Some(k) = (0..n).position(|k| bad(y[k] - self.tau_e[k])) {
            return Err(Error::Numerical(format!(
                "at t = {t} s the torque of joint {} less that of the external wrenches is {:e} \
                 (not a finite number of magnitude at most {MAX_MAGNITUDE:e})",
                self.params.joints[k],
                y[k] - self.tau_e[k]
            )));
        }
        Ok(())
    }

    fn kept(&mut self, s: Processed) -> Result<()> {
        self.out.samples_used += 1;
        let (n, p) = (self.n, self.p);
        self.params.rows(
            self.access,
            &s.q,
            &s.qd,
            &s.qdd,
            &mut self.w,
            &mut self.tau_e,
        )?;
        self.check_rows(s.t, &s.y)?;
        if let Some(pr) = self.predict.as_mut() {
            return predicted(pr, (s.t, &self.w, &self.tau_e), self.params);
        }
        let iv = self.instruments.is_some();
        let validation = self
            .proc
            .validation
            .is_some_and(|(a, b)| s.t >= a && s.t < b);
        if validation {
            for k in 0..n {
                self.out.validation_raw[k]
                    .push(&self.w[k * p..(k + 1) * p], s.y[k] - self.tau_e[k]);
            }
        }
        if let Some(ins) = self.instruments.as_deref_mut() {
            let [qs, qds, qdds] = ins.step((s.t, self.proc.dt), &s.q, &s.qd, &s.y)?;
            let mut te = vec![0.0; n];
            self.params
                .rows(self.access, &qs, &qds, &qdds, &mut self.z, &mut te)?;
        }
        // channels: W (n p), Y (n), Z (n p)
        self.channels[..n * p].copy_from_slice(&self.w);
        for k in 0..n {
            self.channels[n * p + k] = s.y[k] - self.tau_e[k];
        }
        if iv {
            self.channels[n * p + n..].copy_from_slice(&self.z);
        }
        self.dec_count += 1;
        if let Some(d) = &mut self.decimator {
            d.step(&mut self.channels);
            if self.dec_count <= self.dec_skip
                || !(self.dec_count - self.dec_skip).is_multiple_of(self.proc.decimation)
            {
                return Ok(());
            }
        }
        let ch = &self.channels;
        if validation {
            self.out.validation_samples += 1;
            for k in 0..n {
                self.out.validation[k].push(&ch[k * p..(k + 1) * p], ch[n * p + k]);
            }
            let stride = self.proc.validation_row_stride;
            if stride > 0 && (self.out.validation_samples - 1).is_multiple_of(stride) {
                self.out.validation_rows.t.push(s.t);
                self.out
                    .validation_rows
                    .y
                    .push(ch[n * p..n * p + n].to_vec());
                self.out.validation_rows.w.push(ch[..n * p].to_vec());
            }
        } else {
            self.out.fit_samples += 1;
            for k in 0..n {
                if s.qd[k].abs() < self.proc.min_speed {
                    self.out.slow_rows[k] += 1;
                    continue;
                }
                let w = &ch[k * p..(k + 1) * p];
                let y = ch[n * p + k];
                self.out.fit[k].push(w, y);
                if let Some(acc) = &mut self.out.iv {
                    let z = &ch[n * p + n + k * p..n * p + n + (k + 1) * p];
                    acc[k].push(z, w, y);
                }
            }
        }
        Ok(())
    }
}

/// The model's torques W x + tau_e of one sample sent to the sink: an error naming the joint
/// and the time where one is not finite (never a NaN in the predictions).
fn predicted(
    pr: &mut PredictionSink<'_>,
    (t, w, tau_e): (f64, &[f64], &[f64]),
    params: &ParameterModel,
) -> Result<()> {
    let p = pr.x.len();
    let tau: Vec<f64> = tau_e
        .iter()
        .enumerate()
        .map(|(k, e)| e + (0..p).map(|c| w[k * p + c] * pr.x[c]).sum::<f64>())
        .collect();
    if let Some(k) = tau.iter().position(|v| !v.is_finite()) {
        return Err(Error::Numerical(format!(
            "at t = {t} s the predicted torque of joint {} is {} (are the parameters finite?)",
            params.joints[k], tau[k]
        )));
    }
    (pr.sink)(t, &tau)
}

/// Run one pass over `log`.
pub fn run_pass(
    log: &dyn LogSource,
    params: &mut ParameterModel,
    access: &mut ModelAccess,
    proc: &Processing,
    instruments: Option<&mut Instruments>,
) -> Result<PassResult> {
    pass(log, (params, access), proc, instruments, None)
}

/// A pass over `log` that sends the model's torques W x + tau_e of every sample between the
/// borders (from the filtered positions and their differences, or the log's derivatives) to
/// `predict`, instead of building the least-squares factors.
pub fn run_prediction_pass<'a>(
    log: &dyn LogSource,
    params: &'a mut ParameterModel,
    access: &'a mut ModelAccess,
    proc: &'a Processing,
    predict: PredictionSink<'a>,
) -> Result<usize> {
    if predict.x.len() != params.count() {
        return Err(Error::Input(format!(
            "{} parameter values for a model of {} parameters",
            predict.x.len(),
            params.count()
        )));
    }
    Ok(pass(log, (params, access), proc, None, Some(predict))?.samples_used)
}

fn pass<'a>(
    log: &dyn LogSource,
    (params, access): (&'a mut ParameterModel, &'a mut ModelAccess),
    proc: &'a Processing,
    instruments: Option<&'a mut Instruments>,
    predict: Option<PredictionSink<'a>>,
) -> Result<PassResult> {
    access.restart();
    let n = params.joints_count();
    let p = params.count();
    let iv = instruments.is_some();
    let channels = n * p + n + if iv { n * p } else { 0 };
    let decimator = proc
        .decimation_filter
        .as_ref()
        .filter(|_| proc.decimation > 1)
        .map(|f| ParallelFilter::new(f, channels));
    let mut pass = Pass {
        stream: proc.lowpass.clone().map(|f| ZeroPhaseStream::new(f, n)),
        params,
        access,
        proc,
        instruments,
        predict,
        n,
        p,
        pending: VecDeque::new(),
        window: VecDeque::new(),
        processed: 0,
        // central differences give no sample at either end
        processed_total: if proc.lowpass.is_some() {
            proc.samples.saturating_sub(2)
        } else {
            proc.samples
        },
        decimator,
        dec_count: 0,
        dec_skip: proc.decimation_skip,
        channels: vec![0.0; channels],
        w: vec![0.0; n * p],
        z: vec![0.0; n * p],
        tau_e: vec![0.0; n],
        out: PassResult {
            fit: (0..n).map(|_| TriangularFactor::new(p)).collect(),
            validation: (0..n).map(|_| TriangularFactor::new(p)).collect(),
            validation_raw: (0..n).map(|_| TriangularFactor::new(p)).collect(),
            iv: iv.then(|| (0..n).map(|_| IvAccumulator::new(p)).collect()),
            samples_read: 0,
            samples_used: 0,
            fit_samples: 0,
            validation_samples: 0,
            slow_rows: vec![0; n],
            validation_rows: ValidationRows::default(),
            instrument_deviation: 0.0,
        },
    };
    log.read(&mut |s| pass.raw(s))?;
    if let Some(mut stream) = pass.stream.take() {
        let mut outs = Vec::new();
        stream.finish(&mut |v| outs.push(v.to_vec()))?;
        for q in outs {
            pass.filtered(q)?;
        }
    }
    if let Some(ins) = pass.instruments.as_deref() {
        pass.out.instrument_deviation = ins.deviation;
    }
    Ok(pass.out)
}
