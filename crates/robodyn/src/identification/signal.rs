//! Signal processing of identification practice (Gautier 1997, Khalil & Dombre §12.4):
//!
//! - a digital Butterworth low-pass as second-order sections (the bilinear transform of the
//!   analog prototype with the cut-off prewarped, as `scipy.signal.butter(..., output="sos")`);
//! - zero-phase filtering forward and backward with odd extension at the ends and steady-state
//!   initial conditions (as `scipy.signal.sosfiltfilt`), also block by block over a stream
//!   ([`ZeroPhaseStream`]: equal to the whole-signal filter to rounding, memory independent of
//!   the length);
//! - a causal filter state ([`SosState`]) for the parallel decimation: the same low-pass applied
//!   to every column of the observation matrix and to the torques keeps Y = W X exact, whatever
//!   the phase, so it can run forward only, in one pass.
//!
//! Velocities and accelerations are central differences of the filtered positions
//! ([`central_differences`]).

use crate::error::{Error, Result};
use std::collections::VecDeque;
use std::f64::consts::PI;

/// A digital Butterworth low-pass filter as second-order sections `[b0 b1 b2 a0 a1 a2]`
/// (a0 = 1), the layout of `scipy.signal.sosfilt`.
#[derive(Clone, Debug, PartialEq)]
pub struct Butterworth {
    /// Filter order (number of poles).
    pub order: usize,
    /// Cut-off frequency (-3 dB) in Hz.
    pub cutoff: f64,
    /// Sample rate in Hz.
    pub sample_rate: f64,
    /// Second-order sections `[b0 b1 b2 1 a1 a2]`, applied in order.
    pub sos: Vec<[f64; 6]>,
}

/// Complex numbers as (re, im) pairs: the design needs a handful of products and quotients.
#[derive(Clone, Copy, Debug, PartialEq)]
struct C(f64, f64);

impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    #[cfg(test)]
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C(
            (self.0 * o.0 + self.1 * o.1) / d,
            (self.1 * o.0 - self.0 * o.1) / d,
        )
    }
    fn scale(self, s: f64) -> C {
        C(self.0 * s, self.1 * s)
    }
}

impl Butterworth {
    /// Low-pass of order `order` (1..=12) with cut-off `cutoff` Hz at `sample_rate` Hz. The
    /// cut-off must lie strictly between 0 and the Nyquist frequency (an error says so).
    ///
    /// Design (scipy's `butter`): analog poles p_k = exp(i pi (2k + N - 1) / (2N)), k = 1..N,
    /// scaled by the prewarped cut-off w = 4 tan(pi fc / fs) (sampling period 1/2 of the
    /// bilinear transform), mapped by z = (4 + p) / (4 - p); the N zeros go to z = -1 and the gain
    /// makes the DC gain 1. Complex-conjugate poles are paired into sections, the real pole of an
    /// odd order into a first-order section.
    pub fn lowpass(order: usize, cutoff: f64, sample_rate: f64) -> Result<Butterworth> {
        if !(1..=12).contains(&order) {
            return Err(Error::Input(format!(
                "Butterworth order {order}: 1 to 12 expected"
            )));
        }
        if !(sample_rate.is_finite() && sample_rate > 0.0) {
            return Err(Error::Input(format!(
                "sample rate {sample_rate} Hz is not a positive number"
            )));
        }
        let nyquist = sample_rate / 2.0;
        if !(cutoff.is_finite() && cutoff > 0.0 && cutoff < nyquist) {
            return Err(Error::Input(format!(
                "low-pass cut-off {cutoff} Hz must lie strictly between 0 and the Nyquist \
                 frequency {nyquist} Hz (sample rate {sample_rate} Hz)"
            )));
        }
        let n = order;
        let warped = 4.0 * (PI * cutoff / sample_rate).tan();
        let mut sos = Vec::new();
        // poles in the upper half plane (k = 1..n/2) with their conjugates, then the real one
        let analog = |k: usize| {
            let theta = PI * (2 * k + n - 1) as f64 / (2 * n) as f64;
            C(theta.cos(), theta.sin()).scale(warped)
        };
        let four = C(4.0, 0.0);
        for k in 1..=n / 2 {
            let p = analog(k);
            let z = four.add(p).div(four.sub(p));
            // (1 - z p)(1 - z conj(p)) = 1 - 2 Re(p) z^-1 + |p|^2 z^-2
            let (a1, a2) = (-2.0 * z.0, z.0 * z.0 + z.1 * z.1);
            // DC gain 1: b (1 + 2 + 1) = 1 + a1 + a2
            let g = (1.0 + a1 + a2) / 4.0;
            sos.push([g, 2.0 * g, g, 1.0, a1, a2]);
        }
        if n % 2 == 1 {
            let p = C(-warped, 0.0);
            let z = four.add(p).div(four.sub(p));
            let a1 = -z.0;
            let g = (1.0 + a1) / 2.0;
            sos.push([g, g, 0.0, 1.0, a1, 0.0]);
        }
        Ok(Butterworth {
            order,
            cutoff,
            sample_rate,
            sos,
        })
    }

    /// Steady-state section states for a unit step input (scipy's `sosfilt_zi`): each section
    /// solves `(I - A^T) z = b[1:] - a[1:] b0` (`lfilter_zi`), scaled by the DC gain of the
    /// sections before it.
    pub fn step_state(&self) -> Vec<[f64; 2]> {
        let mut scale = 1.0;
        self.sos
            .iter()
            .map(|s| {
                let [b0, b1, b2, _, a1, a2] = *s;
                let (r0, r1) = (b1 - a1 * b0, b2 - a2 * b0);
                // [[1 + a1, -1], [a2, 1]] z = r
                let det = 1.0 + a1 + a2;
                let z0 = (r0 + r1) / det;
                let z1 = r1 - a2 * z0;
                let out = [scale * z0, scale * z1];
                scale *= (b0 + b1 + b2) / (1.0 + a1 + a2);
                out
            })
            .collect()
    }

    /// Padding of the zero-phase filter at each end (scipy's `sosfiltfilt` default):
    /// 3 (2 sections + 1 - sections with b2 = 0 and a2 = 0).
    pub fn padlen(&self) -> usize {
        let zb = self.sos.iter().filter(|s| s[2] == 0.0).count();
        let za = self.sos.iter().filter(|s| s[5] == 0.0).count();
        3 * (2 * self.sos.len() + 1 - zb.min(za))
    }

    /// Samples after which the slowest pole's transient has decayed by `factor` (e.g. 1e-14):
    /// the analog pole nearest the imaginary axis has real part -w sin(pi / 2N).
    pub fn settling_samples(&self, factor: f64) -> usize {
        let sigma = 2.0 * PI * self.cutoff * (PI / (2.0 * self.order as f64)).sin();
        // a cut-off tiny against the sample rate saturates at usize::MAX (refused by the
        // callers, which compare it with the log's length)
        (((-factor.ln()) / sigma * self.sample_rate).ceil() as usize).saturating_add(1)
    }

    /// Variance inflation of a least-squares estimate whose residuals are white noise passed
    /// through this (causal) filter and then kept every `stride`-th sample (the parallel
    /// decimation): the kept noise is correlated, with autocorrelation rho(k) = r(k stride) /
    /// r(0), r(l) = sum_i h_i h_(i+l) over the impulse response h, and for regressors that vary
    /// slowly over the correlation length the covariance sigma^2 (W^T W)^-1 is too small by
    /// 1 + 2 sum_(k >= 1) rho(k) (the long-run over the short-run variance). Returns that
    /// factor (1 for a stride whose kept samples are uncorrelated).
    pub fn decimated_noise_gain(&self, stride: usize) -> f64 {
        let stride = stride.max(1);
        let len = self
            .settling_samples(1e-12)
            .clamp(16, 1 << 20)
            .saturating_add(stride);
        let mut state = SosState::new(self);
        let h: Vec<f64> = (0..len)
            .map(|i| state.step(if i == 0 { 1.0 } else { 0.0 }))
            .collect();
        let r = |lag: usize| -> f64 { h.iter().zip(&h[lag..]).map(|(a, b)| a * b).sum() };
        let r0 = r(0);
        if r0 <= 0.0 {
            return 1.0;
        }
        let tail: f64 = (1..)
            .map(|k| k * stride)
            .take_while(|&lag| lag < h.len())
            .map(r)
            .sum();
        (1.0 + 2.0 * tail / r0).max(f64::MIN_POSITIVE)
    }

    /// Zero-phase filtering of a whole signal (scipy's `sosfiltfilt` with its default odd
    /// padding). Signals shorter than the padding plus one sample are an error.
    pub fn filtfilt(&self, x: &[f64]) -> Result<Vec<f64>> {
        let pad = self.padlen();
        if x.len() <= pad {
            return Err(Error::Input(format!(
                "{} samples are too few for the zero-phase filter (more than {pad} needed)",
                x.len()
            )));
        }
        let ext = odd_extension(x, pad, true, true);
        let y = self.forward_backward(&ext);
        Ok(y[pad..pad + x.len()].to_vec())
    }

    /// Forward then backward pass, each started from the steady state of its first sample.
    fn forward_backward(&self, x: &[f64]) -> Vec<f64> {
        let zi = self.step_state();
        let mut st = SosState::with_state(self, &zi, x[0]);
        let mut y: Vec<f64> = x.iter().map(|&v| st.step(v)).collect();
        y.reverse();
        let mut st = SosState::with_state(self, &zi, y[0]);
        for v in y.iter_mut() {
            *v = st.step(*v);
        }
        y.reverse();
        y
    }
}

/// Odd extension by `pad` samples (scipy's `odd_ext`): 2 x[0] - x[pad..1] before and
/// 2 x[n-1] - x[n-2..n-1-pad] after, each side only when asked.
fn odd_extension(x: &[f64], pad: usize, left: bool, right: bool) -> Vec<f64> {
    let n = x.len();
    let mut e = Vec::with_capacity(n + 2 * pad);
    if left {
        e.extend((1..=pad).rev().map(|k| 2.0 * x[0] - x[k]));
    }
    e.extend_from_slice(x);
    if right {
        e.extend((1..=pad).map(|k| 2.0 * x[n - 1] - x[n - 1 - k]));
    }
    e
}

/// State of a causal second-order-section filter (direct form II transposed, as `sosfilt`).
#[derive(Clone, Debug)]
pub struct SosState {
    sos: Vec<[f64; 6]>,
    z: Vec<[f64; 2]>,
}

impl SosState {
    /// Zero initial state.
    pub fn new(f: &Butterworth) -> SosState {
        SosState {
            sos: f.sos.clone(),
            z: vec![[0.0; 2]; f.sos.len()],
        }
    }

    /// Initial state `zi * x0` (steady state of a constant input x0).
    pub fn with_state(f: &Butterworth, zi: &[[f64; 2]], x0: f64) -> SosState {
        SosState {
            sos: f.sos.clone(),
            z: zi.iter().map(|z| [z[0] * x0, z[1] * x0]).collect(),
        }
    }

    /// Filter one sample.
    #[inline]
    pub fn step(&mut self, x: f64) -> f64 {
        sos_step(&self.sos, &mut self.z, x)
    }
}

/// One sample through cascaded sections in direct form II transposed (`sosfilt`'s recursion):
/// y = b0 x + z0, z0 <- b1 x - a1 y + z1, z1 <- b2 x - a2 y, section after section.
#[inline]
fn sos_step(sos: &[[f64; 6]], z: &mut [[f64; 2]], mut x: f64) -> f64 {
    for (s, z) in sos.iter().zip(z.iter_mut()) {
        let y = s[0] * x + z[0];
        z[0] = s[1] * x - s[4] * y + z[1];
        z[1] = s[2] * x - s[5] * y;
        x = y;
    }
    x
}

/// Causal filtering of many parallel channels at once (the columns of the observation matrix
/// and the torques of the parallel decimation): one state per channel, zero initial state, so
/// that a linear relation between the channels holds exactly for the outputs.
#[derive(Clone, Debug)]
pub struct ParallelFilter {
    sos: Vec<[f64; 6]>,
    /// z[channel * sections + section].
    z: Vec<[f64; 2]>,
    channels: usize,
}

impl ParallelFilter {
    /// Filter `channels` channels with `f`, from a zero state.
    pub fn new(f: &Butterworth, channels: usize) -> ParallelFilter {
        ParallelFilter {
            sos: f.sos.clone(),
            z: vec![[0.0; 2]; channels * f.sos.len()],
            channels,
        }
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.channels
    }

    /// Filter one sample of every channel in place.
    pub fn step(&mut self, x: &mut [f64]) {
        let ns = self.sos.len();
        for (v, z) in x.iter_mut().zip(self.z.chunks_mut(ns)) {
            *v = sos_step(&self.sos, z, *v);
        }
    }
}

/// Zero-phase filtering of a multi-channel stream, block by block: samples go in with
/// [`ZeroPhaseStream::push`], filtered samples come out in order (with a delay of one block and
/// the overlap). Each block is filtered forward and backward together with `overlap` samples
/// on both sides, which are then dropped: the transient of the truncation decays below 1e-14
/// over the overlap, so the output equals [`Butterworth::filtfilt`] of the whole signal to
/// rounding, with the same odd padding at the two ends. Memory: (block + 2 overlap) samples.
#[derive(Clone, Debug)]
pub struct ZeroPhaseStream {
    filter: Butterworth,
    channels: usize,
    overlap: usize,
    block: usize,
    /// Raw samples not yet dropped, from index `base` of the stream.
    buf: VecDeque<Vec<f64>>,
    base: usize,
    /// Index of the next sample to emit.
    next: usize,
    /// Samples received.
    received: usize,
}

impl ZeroPhaseStream {
    /// A stream of samples of `channels` channels filtered forward and backward by `filter`.
    pub fn new(filter: Butterworth, channels: usize) -> ZeroPhaseStream {
        let overlap = filter.settling_samples(1e-15).max(filter.padlen() + 1);
        let block = overlap.saturating_mul(4).max(1024);
        ZeroPhaseStream {
            filter,
            channels,
            overlap,
            block,
            buf: VecDeque::new(),
            base: 0,
            next: 0,
            received: 0,
        }
    }

    /// Samples on each side of a block filtered with it and dropped.
    pub fn overlap(&self) -> usize {
        self.overlap
    }

    /// Add one sample (one value per channel); filtered samples now complete are passed to
    /// `out` in order.
    pub fn push(&mut self, x: &[f64], out: &mut dyn FnMut(&[f64])) {
        debug_assert_eq!(x.len(), self.channels);
        self.buf.push_back(x.to_vec());
        self.received += 1;
        if self.received
            >= self
                .next
                .saturating_add(self.block)
                .saturating_add(self.overlap)
        {
            self.emit(self.next + self.block, false, out);
        }
    }

    /// End of the stream: the remaining samples (error if the whole stream is shorter than the
    /// padding).
    pub fn finish(&mut self, out: &mut dyn FnMut(&[f64])) -> Result<()> {
        let pad = self.filter.padlen();
        if self.received <= pad {
            return Err(Error::Input(format!(
                "{} samples are too few for the zero-phase filter (more than {pad} needed)",
                self.received
            )));
        }
        if self.next < self.received {
            self.emit(self.received, true, out);
        }
        Ok(())
    }

    /// Filter the window [next - overlap, end + overlap) and emit samples next..end.
    fn emit(&mut self, end: usize, last: bool, out: &mut dyn FnMut(&[f64])) {
        let lo = self.next.saturating_sub(self.overlap).max(self.base);
        let hi = if last {
            self.received
        } else {
            end.saturating_add(self.overlap).min(self.received)
        };
        let first = lo == 0;
        let pad = self.filter.padlen();
        let len = hi - lo;
        let mut result = vec![vec![0.0; self.channels]; end - self.next];
        let mut x = Vec::with_capacity(len);
        for c in 0..self.channels {
            x.clear();
            x.extend((lo..hi).map(|i| self.buf[i - self.base][c]));
            let ext = odd_extension(&x, pad, first, last);
            let y = self.filter.forward_backward(&ext);
            let shift = if first { pad } else { 0 };
            for (k, r) in result.iter_mut().enumerate() {
                r[c] = y[shift + self.next + k - lo];
            }
        }
        for r in &result {
            out(r);
        }
        self.next = end;
        // keep `overlap` samples before the next block
        let keep_from = self.next.saturating_sub(self.overlap);
        while self.base < keep_from {
            self.buf.pop_front();
            self.base += 1;
        }
    }
}

/// Central differences of a uniformly sampled signal at the interior sample k:
/// `(x[k+1] - x[k-1]) / (2 dt)` and `(x[k+1] - 2 x[k] + x[k-1]) / dt^2`.
#[inline]
pub fn central_differences(prev: f64, cur: f64, next: f64, dt: f64) -> (f64, f64) {
    (
        (next - prev) / (2.0 * dt),
        (next - 2.0 * cur + prev) / (dt * dt),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cutoff_at_or_above_nyquist_is_refused() {
        let e = Butterworth::lowpass(4, 2500.0, 5000.0).unwrap_err();
        assert!(e.to_string().contains("Nyquist"), "{e}");
        assert!(Butterworth::lowpass(4, 0.0, 5000.0).is_err());
        assert!(Butterworth::lowpass(0, 10.0, 5000.0).is_err());
    }

    #[test]
    fn dc_gain_is_one_and_cutoff_is_minus_3_db() {
        for order in 1..=8 {
            let f = Butterworth::lowpass(order, 30.0, 1000.0).unwrap();
            // |H(e^{iw})| at the cut-off: 1/sqrt(2)
            let w = 2.0 * PI * 30.0 / 1000.0;
            let z1 = C(w.cos(), -w.sin()); // z^-1
            let z2 = z1.mul(z1);
            let mut h = C(1.0, 0.0);
            let mut dc = 1.0;
            for s in &f.sos {
                let num = C(s[0], 0.0).add(z1.scale(s[1])).add(z2.scale(s[2]));
                let den = C(1.0, 0.0).add(z1.scale(s[4])).add(z2.scale(s[5]));
                h = h.mul(num.div(den));
                dc *= (s[0] + s[1] + s[2]) / (1.0 + s[4] + s[5]);
            }
            let mag = (h.0 * h.0 + h.1 * h.1).sqrt();
            assert!((dc - 1.0).abs() < 1e-12, "order {order}: dc {dc}");
            assert!(
                (mag - 0.5f64.sqrt()).abs() < 1e-12,
                "order {order}: |H(fc)| = {mag}"
            );
        }
    }

    #[test]
    fn stream_equals_whole_signal_filter() {
        let f = Butterworth::lowpass(4, 20.0, 1000.0).unwrap();
        let n = 9000;
        let x: Vec<[f64; 2]> = (0..n)
            .map(|k| {
                let t = k as f64 / 1000.0;
                [
                    (3.0 * t).sin() + 0.1 * (400.0 * t).sin(),
                    t * t - (50.0 * t).cos(),
                ]
            })
            .collect();
        let whole: Vec<Vec<f64>> = (0..2)
            .map(|c| {
                f.filtfilt(&x.iter().map(|v| v[c]).collect::<Vec<_>>())
                    .unwrap()
            })
            .collect();
        let mut s = ZeroPhaseStream::new(f, 2);
        let mut got: Vec<Vec<f64>> = Vec::new();
        for v in &x {
            s.push(v, &mut |y| got.push(y.to_vec()));
        }
        s.finish(&mut |y| got.push(y.to_vec())).unwrap();
        assert_eq!(got.len(), n);
        for k in 0..n {
            for c in 0..2 {
                assert!(
                    (got[k][c] - whole[c][k]).abs() < 1e-12,
                    "sample {k} channel {c}: {} vs {}",
                    got[k][c],
                    whole[c][k]
                );
            }
        }
    }

    /// Reference values computed with SciPy 1.17.1 (Python, `import scipy.signal as sg`):
    /// `sos = sg.butter(N, fc, fs=fs, output="sos")`, and for
    /// x = sin(2 pi 3 t) + 0.5 cos(2 pi 0.2 fs t) + t, t = k / fs, k = 0..399,
    /// `sg.sosfiltfilt(sos, x)` printed with `repr` at a few samples (ends included, where the odd padding
    /// and the steady-state initial conditions matter). The sections themselves may be paired
    /// differently (scipy attaches two zeros to the real pole of an odd order); the filter and
    /// its zero-phase output are the same.
    #[test]
    fn decimated_noise_gain_against_simulated_noise() {
        // 8th-order low-pass at 0.8 x the Nyquist frequency of a decimation by 10, as the
        // identification's parallel decimation at 500 Hz
        let f = Butterworth::lowpass(8, 20.0, 500.0).unwrap();
        // stride 1: the long-run variance of filtered white noise is the DC gain squared (1)
        // over the variance sum h^2, i.e. the closed form 1 / sum h^2
        let mut st = SosState::new(&f);
        let h2: f64 = (0..20_000)
            .map(|i| st.step(if i == 0 { 1.0 } else { 0.0 }).powi(2))
            .sum();
        let g1 = f.decimated_noise_gain(1);
        assert!((g1 - 1.0 / h2).abs() < 1e-9 * g1, "{g1} vs {}", 1.0 / h2);
        // a stride far beyond the impulse response: uncorrelated kept samples
        assert!((f.decimated_noise_gain(100_000) - 1.0).abs() < 1e-12);
        // stride 10: against the variance of the means of batches of filtered, decimated
        // pseudo-random noise (an independent estimate of the long-run variance)
        let g10 = f.decimated_noise_gain(10);
        let mut st = SosState::new(&f);
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let kept: Vec<f64> = (0..4_000_000)
            .map(|_| st.step(uniform()))
            .skip(1000)
            .step_by(10)
            .collect();
        let var = kept.iter().map(|x| x * x).sum::<f64>() / kept.len() as f64;
        let batch = 200;
        let means: Vec<f64> = kept
            .chunks_exact(batch)
            .map(|c| c.iter().sum::<f64>() / batch as f64)
            .collect();
        let long_run = batch as f64 * means.iter().map(|m| m * m).sum::<f64>() / means.len() as f64;
        let estimate = long_run / var;
        // 2000 batches: the estimate's relative standard error is sqrt(2 / 2000) ~ 3 %
        assert!(
            (estimate - g10).abs() < 0.1 * g10 && g10 > 1.1,
            "noise gain {g10} vs simulated {estimate}"
        );
    }

    #[test]
    fn matches_scipy_butter_and_sosfiltfilt() {
        type Case<'a> = (usize, f64, f64, &'a [(usize, f64)]);
        let cases: [Case; 3] = [
            (
                4,
                30.0,
                1000.0,
                &[
                    (0, 0.526715744137132),
                    (1, 0.4872762861019126),
                    (7, 0.27328069678634304),
                    (50, 0.853429031960689),
                    (199, -0.37343231903231616),
                    (398, 1.4411028042547516),
                    (399, 1.4545932514126985),
                ],
            ),
            (
                3,
                100.0,
                5000.0,
                &[
                    (0, 0.5238045557442583),
                    (1, 0.47684844930564035),
                    (7, 0.2329493005626147),
                    (50, 0.20984982942995112),
                    (199, 0.721592745449282),
                    (398, 1.1405097088906515),
                    (399, 1.1432923791110934),
                ],
            ),
            (
                5,
                12.5,
                200.0,
                &[
                    (0, 0.511565749906016),
                    (1, 0.4770877734031309),
                    (7, 0.5622444224425598),
                    (50, -0.7494079116607815),
                    (199, 0.9008921050548965),
                    (398, 1.9162553871557448),
                    (399, 2.0576392411586424),
                ],
            ),
        ];
        for (order, fc, fs, expected) in cases {
            let f = Butterworth::lowpass(order, fc, fs).unwrap();
            let x: Vec<f64> = (0..400)
                .map(|k| {
                    let t = k as f64 / fs;
                    (2.0 * PI * 3.0 * t).sin() + 0.5 * (2.0 * PI * 0.2 * fs * t).cos() + t
                })
                .collect();
            let y = f.filtfilt(&x).unwrap();
            for &(k, v) in expected {
                assert!(
                    (y[k] - v).abs() < 1e-12,
                    "order {order}, fc {fc}, fs {fs}, sample {k}: {} vs scipy {v}",
                    y[k]
                );
            }
        }
        // the poles of scipy's order-4 design, 30 Hz at 1 kHz (a1, a2 of its two sections)
        let f = Butterworth::lowpass(4, 30.0, 1000.0).unwrap();
        let mut a: Vec<(f64, f64)> = f.sos.iter().map(|s| (s[4], s[5])).collect();
        a.sort_by(|x, y| x.0.partial_cmp(&y.0).unwrap());
        let scipy = [
            (-1.8331252600998054, 0.8661804464426682),
            (-1.6746609472909773, 0.7048586816622795),
        ];
        for (g, e) in a.iter().zip(scipy) {
            assert!((g.0 - e.0).abs() < 1e-14 && (g.1 - e.1).abs() < 1e-14);
        }
        let gain: f64 = f.sos.iter().map(|s| s[0]).product();
        assert!((gain - 6.23869835484794e-05).abs() < 1e-18);
    }
}
