//! Identification of the base parameters from measured motion and torques (the inverse dynamic
//! identification model, IDIM: Gautier 1990; Khalil & Dombre ch. 12), for trees and closed
//! chains (Gamma_cl = G^T Phi K, eq 10.40, in the actuated coordinates).
//!
//! - [`data`]: logs (CSV, streamed);
//! - [`signal`]: Butterworth design, zero-phase filtering, parallel decimation filter;
//! - [`parameters`]: the identified vector (base parameters, motor drive parameters of a
//!   transmission, offsets) and its rows;
//! - [`observation`]: one streaming pass building the triangular factors of [W Y];
//! - [`estimators`]: OLS, Gautier's WLS, relative standard deviations, condition number,
//!   IDIM-IV;
//! - [`consistency`]: physically consistent standard parameters (SDP, pseudo-inertia PSD),
//!   solved by [`conic`], a small interior-point method for 4x4 PSD blocks and bounds;
//! - [`excitation`]: finite Fourier series minimizing the condition number;
//! - [`gains`]: drive gains identified jointly with the parameters (currents and a reference);
//! - [`payload`]: a payload's standard parameters on a link, with its identifiability;
//! - [`stacked`]: least squares over blocks of rows sharing unknowns, rank-revealing (the
//!   joint problems of [`gains`] and [`payload`]);
//! - [`signs`]: the signs physics fixes (friction, rotor inertias, sums of masses and moments
//!   of inertia), checked on the estimate;
//! - [`statistics`]: the sufficient statistics of one log, merged over a set of logs
//!   (map-reduce; serialized as JSON);
//! - [`predictions`]: the identified model's torques at every sample of a log;
//! - [`report`]: table (text, JSON, CSV) and SVG plots;
//! - [`model_access`]: the only calls into the rest of the library;
//! - [`fuzz_checks`]: the properties the fuzz targets check (`fuzz/`).

pub mod conic;
pub mod consistency;
pub mod data;
pub mod estimators;
pub mod excitation;
pub mod fuzz_checks;
pub mod gains;
pub mod model_access;
pub mod observation;
pub mod parameters;
pub mod payload;
pub mod predictions;
pub mod report;
pub mod signal;
pub mod signs;
pub mod stacked;
pub mod statistics;

use crate::error::{Error, Result};
use data::{record, summarize, Effort, LogSource, LogSummary};
use estimators::{
    combine, iv_solve, joint_sigma, least_squares, output_sq, residual_sq, restrict, LsSolution,
};
use faer::Mat;
use model_access::ModelAccess;
use observation::{run_pass, Instruments, PassResult, Processing, ValidationRows};
use parameters::{Kind, Parameter, ParameterModel, ParameterOptions};
use signal::Butterworth;
pub use statistics::Statistics;

pub use model_access::Rotors;

/// The estimator of the final values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// Ordinary least squares.
    Ols,
    /// Weighted least squares, each joint's rows divided by the standard deviation of its error
    /// (Gautier 1997).
    Wls,
    /// Instrumental variables (IDIM-IV), weighted as WLS.
    Iv,
}

impl Estimator {
    /// Every estimator.
    pub const ALL: [Estimator; 3] = [Estimator::Ols, Estimator::Wls, Estimator::Iv];

    /// Its key in options and files: `ols`, `wls`, `iv` ([`Estimator::from_key`] reads it back;
    /// [`Estimator::name`] is the report's spelling).
    pub fn key(self) -> &'static str {
        match self {
            Estimator::Ols => "ols",
            Estimator::Wls => "wls",
            Estimator::Iv => "iv",
        }
    }

    /// The estimator of a key of [`Estimator::key`].
    pub fn from_key(key: &str) -> Option<Estimator> {
        Estimator::ALL.into_iter().find(|e| e.key() == key)
    }

    /// What the estimator is, in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            Estimator::Ols => "ordinary least squares",
            Estimator::Wls => {
                "weighted least squares, each joint's rows weighted by 1/sigma_j (Gautier)"
            }
            Estimator::Iv => "instrumental variables (IDIM-IV), weighted like WLS",
        }
    }

    /// Its name in the report: `OLS`, `WLS`, `IDIM-IV`.
    pub fn name(self) -> &'static str {
        match self {
            Estimator::Ols => "OLS",
            Estimator::Wls => "WLS",
            Estimator::Iv => "IDIM-IV",
        }
    }
}

/// Essential parameters: drop the least identifiable parameter (largest relative standard
/// deviation) while that is above `max_relative_std` and the relative error grows by less than
/// `tolerance` (relative).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EssentialOptions {
    /// Relative standard deviation (%) above which a parameter may be dropped (default 10).
    pub max_relative_std: f64,
    /// Largest relative growth of the relative error accepted per drop (default 0.02).
    pub tolerance: f64,
}

impl Default for EssentialOptions {
    fn default() -> Self {
        EssentialOptions {
            max_relative_std: 10.0,
            tolerance: 0.02,
        }
    }
}

/// Options of [`identify`].
#[derive(Clone, Debug)]
pub struct Options {
    /// What is identified: rotor inertias, friction, offsets.
    pub parameters: ParameterOptions,
    /// Estimator of the final values (default WLS).
    pub estimator: Estimator,
    /// Identify under the physical-consistency constraints (SDP).
    pub consistent: bool,
    /// Compute standard parameters consistent with the estimate (needed by `--write-robot`).
    pub standard: bool,
    /// The solver of the consistency SDP (default robodyn's interior-point method; Clarabel
    /// with the `sdp` feature, as a cross-check).
    pub consistency_solver: consistency::Solver,
    /// Reduce to the essential parameters (None: keep every base parameter).
    pub essential: Option<EssentialOptions>,
    /// Joint-space bandwidth of the robot's dynamics (Hz, default [`DEFAULT_BANDWIDTH`]); the
    /// filter and decimation defaults follow from it.
    pub bandwidth: f64,
    /// Low-pass of the positions: cut-off (Hz, default 10 x bandwidth, at most 0.4 fs), order.
    pub cutoff: Option<f64>,
    /// Order of the position low-pass (Butterworth, applied forward and backward; default 4).
    pub filter_order: usize,
    /// Decimation factor (default: the decimation low-pass at twice the position cut-off, or
    /// at 10 x bandwidth where the log gives qd, qdd; see [`default_decimation`]).
    pub decimation: Option<usize>,
    /// Samples dropped at each end (default: the settling of the position filter).
    pub border: Option<usize>,
    /// Validation segment as fractions [from, to) of the log's duration; None: all rows fit.
    pub validation: Option<(f64, f64)>,
    /// Use qd, qdd of the log when given (else differentiate the filtered positions).
    pub use_log_derivatives: bool,
    /// Drive gains (currents to torques), per motor.
    pub gains: Option<Vec<f64>>,
    /// A joint's row is left out where |qd_j| is below this (rad/s or m/s): None for the
    /// default, [`DEFAULT_MIN_SPEED`] when the velocities are differentiated from the positions
    /// (near rest their sign, hence the Coulomb friction's, is uncertain) and 0 (every row)
    /// when the log gives them.
    pub min_speed: Option<f64>,
    /// IDIM-IV: iterations and the bandwidth of the tracking loop of the simulation (Hz).
    pub iv_iterations: usize,
    /// Bandwidth of the IDIM-IV tracking loop (Hz; default bandwidth / 4).
    pub iv_bandwidth: Option<f64>,
    /// Keep the decimated rows of the validation segment in the result (for the plot; at most
    /// [`observation::MAX_KEPT_ROWS`], evenly spaced, whatever the log's length).
    pub keep_validation_rows: bool,
    /// Dead band of the sign of the Coulomb friction in W (rad/s or m/s; see
    /// [`model_access::coulomb_sign`]): None for the default, [`DEFAULT_COULOMB_BAND`] when
    /// the velocities are differentiated from the positions and 0 (the exact sign) when the
    /// log gives them.
    pub coulomb_band: Option<f64>,
}

/// Default dead band of the Coulomb sign where the velocities are estimated (rad/s or m/s):
/// below it an estimated velocity is taken as rest, sign 0, instead of a sign drawn by the
/// noise of the differentiated positions (chosen by cross-validation on the TX40 log:
/// docs/models/identification.md).
pub const DEFAULT_COULOMB_BAND: f64 = 3e-3;

/// Default minimum speed where the velocities are estimated (rad/s or m/s): a joint's rows
/// where |qd_j| is below it are left out of the fit, where the sign of its estimated velocity,
/// hence of its Coulomb friction, is least certain (chosen by cross-validation on the TX40
/// log: docs/models/identification.md). Where the log gives qd, every row is kept.
pub const DEFAULT_MIN_SPEED: f64 = 5e-3;

/// Default joint-space bandwidth of the robot's dynamics (Hz): the position cut-off (10 x) and
/// the decimation ([`default_decimation`]) follow from it (chosen by cross-validation on the
/// TX40 log: docs/models/identification.md).
pub const DEFAULT_BANDWIDTH: f64 = 5.0;

/// The band the rows keep, as a multiple of the bandwidth: the default cut-off of the position
/// low-pass (at most 0.4 fs), and of the decimation low-pass where the log gives qd, qdd.
const ROW_BAND_PER_BANDWIDTH: f64 = 10.0;

/// The default decimation factor at sample rate `fs` (Hz), the largest whose decimation
/// low-pass (0.8 x the new Nyquist frequency) is at or above
///
/// - twice the position low-pass's cut-off `position_cutoff`, where the velocities are
///   differentiated from the filtered positions: that filter band-limits the regressor, and the
///   decimation low-pass, acting on W and the torques alike, keeps that band whole and removes
///   the torque noise and ripple above it;
/// - 10 x `bandwidth` where the log gives qd, qdd (`position_cutoff` None): no other filter
///   band-limits the rows, so the decimation low-pass sets their band, and removes the noise of
///   measured columns of W above it (motor currents of [`gains`]: noise in W biases least
///   squares).
///
/// At least 1 (no decimation when the log's rate is too low for it).
pub fn default_decimation(fs: f64, bandwidth: f64, position_cutoff: Option<f64>) -> usize {
    let fd = position_cutoff.map_or(ROW_BAND_PER_BANDWIDTH * bandwidth, |fc| 2.0 * fc);
    ((0.8 * fs / (2.0 * fd)).floor() as usize).max(1)
}

impl Options {
    /// Check every number of the options (positive bandwidths and cut-off, a filter order of 1
    /// to 12, fractions of the validation segment, finite non-zero gains, ...): an input error
    /// naming the option and its value, before any reading.
    pub fn validate(&self) -> Result<()> {
        let bad = |what: &str, v: f64, expected: &str| {
            Err(Error::Input(format!("{what} {v}: {expected} expected")))
        };
        let positive = |what: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                bad(what, v, "a positive number")
            }
        };
        let non_negative = |what: &str, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                bad(what, v, "a finite number >= 0")
            }
        };
        positive("the bandwidth (Hz)", self.bandwidth)?;
        if let Some(fc) = self.cutoff {
            positive("the cut-off of the position low-pass (Hz)", fc)?;
        }
        if !(1..=12).contains(&self.filter_order) {
            return Err(Error::Input(format!(
                "the order of the position low-pass {}: 1 to 12 expected",
                self.filter_order
            )));
        }
        if self.decimation == Some(0) {
            return Err(Error::Input(
                "the decimation factor 0: 1 or more expected".into(),
            ));
        }
        if let Some((a, b)) = self.validation {
            if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) || a >= b {
                return Err(Error::Input(format!(
                    "validation segment {a}:{b}: fractions 0 <= from < to <= 1 of the log expected"
                )));
            }
        }
        if let Some(g) = &self.gains {
            if let Some((k, v)) = g
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v != 0.0))
            {
                return bad(
                    &format!("drive gain {} of {}", k + 1, g.len()),
                    *v,
                    "a finite non-zero number",
                );
            }
        }
        if let Some(v) = self.min_speed {
            non_negative("the minimum speed (rad/s or m/s)", v)?;
        }
        if self.iv_iterations == 0 {
            return Err(Error::Input(
                "0 IDIM-IV iterations: 1 or more expected".into(),
            ));
        }
        if let Some(f) = self.iv_bandwidth {
            positive("the bandwidth of the IDIM-IV tracking loop (Hz)", f)?;
        }
        if let Some(e) = &self.essential {
            positive(
                "the relative standard deviation above which essential parameters are dropped (%)",
                e.max_relative_std,
            )?;
            non_negative(
                "the tolerance on the growth of the relative error of the essential parameters",
                e.tolerance,
            )?;
        }
        if let Some(b) = self.coulomb_band {
            non_negative("the dead band of the Coulomb sign (rad/s or m/s)", b)?;
        }
        Ok(())
    }
}

impl Default for Options {
    fn default() -> Self {
        Options {
            parameters: ParameterOptions::default(),
            estimator: Estimator::Wls,
            consistent: false,
            standard: false,
            consistency_solver: consistency::Solver::default(),
            essential: None,
            bandwidth: DEFAULT_BANDWIDTH,
            cutoff: None,
            filter_order: 4,
            decimation: None,
            border: None,
            validation: Some((0.8, 1.0)),
            use_log_derivatives: true,
            gains: None,
            min_speed: None,
            iv_iterations: 8,
            iv_bandwidth: None,
            keep_validation_rows: false,
            coulomb_band: None,
        }
    }
}

/// Fit of one joint's equations.
#[derive(Clone, Debug, PartialEq)]
pub struct JointFit {
    /// Frame number of the joint.
    pub joint: usize,
    /// Joint name.
    pub name: String,
    /// Rows used.
    pub rows: usize,
    /// RMS of the residual (N m or N).
    pub rms: f64,
    /// ||Y_j - W_j X|| / ||Y_j||.
    pub relative_error: f64,
    /// Gautier's standard deviation of the joint's error (the WLS weight is 1 / sigma).
    pub sigma: Option<f64>,
}

/// The processing applied, with every value used (printed by the report).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ProcessingReport {
    /// The log (file name).
    pub source: String,
    /// Samples in the log: those read (once) and used by every pass.
    pub samples: usize,
    /// Sample rate fs of the log (Hz).
    pub sample_rate: f64,
    /// Duration of the log (s).
    pub duration: f64,
    /// Joint-space bandwidth used (Hz).
    pub bandwidth: f64,
    /// qd, qdd were read from the log (else differentiated from the filtered positions).
    pub derivatives_from_log: bool,
    /// (order, cut-off Hz) of the zero-phase position low-pass.
    pub lowpass: Option<(usize, f64)>,
    /// Decimation factor (every n-th filtered sample is a row).
    pub decimation: usize,
    /// (order, cut-off Hz) of the parallel decimation low-pass.
    pub decimation_filter: Option<(usize, f64)>,
    /// Samples dropped at each end of the log (settling of the position filter).
    pub border: usize,
    /// Samples dropped at the start by the settling of the decimation filter.
    pub decimation_skip: usize,
    /// Factor applied to the covariance of the estimate (1 without decimation): the decimation
    /// low-pass leaves the decimated residuals correlated, and for white torque noise at the
    /// log's rate the usual sigma^2 (W^T W)^-1 is too small by this factor
    /// ([`signal::Butterworth::decimated_noise_gain`]).
    pub std_inflation: f64,
    /// The `min_speed` applied (rad/s or m/s).
    pub min_speed: f64,
    /// The dead band of the Coulomb sign applied (rad/s or m/s; 0: the exact sign).
    pub coulomb_band: f64,
    /// Decimated samples in the fit.
    pub fit_samples: usize,
    /// Decimated samples in the validation segment.
    pub validation_samples: usize,
    /// Validation segment [from, to) in s of the log's time, if any.
    pub validation: Option<(f64, f64)>,
    /// Rows left out by `min_speed`, per joint.
    pub slow_rows: Vec<usize>,
}

/// Validation on the segment left out of the fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    /// Start of the segment (s, log time).
    pub from: f64,
    /// End of the segment (s, log time).
    pub to: f64,
    /// ||Y - W X|| / ||Y|| over the segment, with the X of the fit.
    pub relative_error: f64,
    /// The same per joint.
    pub per_joint: Vec<JointFit>,
    /// ||Y - W X|| / ||Y|| on the raw torques: every sample of the segment at the log's rate,
    /// before the decimation filter (torque ripple and noise included), as measured.
    pub raw_relative_error: f64,
    /// The same per joint.
    pub raw_per_joint: Vec<JointFit>,
}

/// The essential parameters found.
#[derive(Clone, Debug, PartialEq)]
pub struct Essential {
    /// Indices (into the parameters) kept.
    pub kept: Vec<usize>,
    /// Estimate of the kept parameters (same order).
    pub x: Vec<f64>,
    /// Their relative standard deviations (%).
    pub relative_std: Vec<f64>,
    /// ||Y - W X|| / ||Y|| with the kept parameters only.
    pub relative_error: f64,
    /// The same with every parameter (the reference of the tolerance).
    pub full_relative_error: f64,
}

/// IDIM-IV iterations.
#[derive(Clone, Debug, PartialEq)]
pub struct IvReport {
    /// Iterations run.
    pub iterations: usize,
    /// No parameter moved by more than 0.02 standard deviations in the last iteration.
    pub converged: bool,
    /// Largest change of the last iteration, in standard deviations.
    pub last_change: f64,
    /// Largest distance between the simulated and the measured positions.
    pub deviation: f64,
    /// The weighted least-squares estimate the iterations started from.
    pub wls: Vec<f64>,
}

/// Physically consistent standard parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Consistent {
    /// Standard parameters K (13 per link) satisfying the constraints.
    pub standard: Vec<f64>,
    /// Their base parameters (the identified vector without offsets).
    pub x: Vec<f64>,
    /// (x_consistent - x_estimate) / std per parameter, and the largest.
    pub deviation: Vec<f64>,
    /// The largest |deviation|.
    pub max_deviation: f64,
    /// Squared Mahalanobis distance of the consistent set from the unconstrained estimate
    /// (x_c - x)^T Cov^-1 (x_c - x): chi-square with p degrees of freedom when the true
    /// parameters are consistent.
    pub distance2: f64,
    /// Smallest eigenvalue of a link's pseudo-inertia matrix (kg m^2 scale) and of A(q).
    pub min_pseudo_inertia_eigenvalue: f64,
    /// Smallest eigenvalue of A(q) over 30 random configurations (kg m^2 scale).
    pub min_inertia_eigenvalue: f64,
    /// The solver used and its status, as printed in the report.
    pub solver: String,
}

/// What a warning is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WarningKind {
    /// The observation matrix is ill-conditioned.
    IllConditioned,
    /// Parameters with relative standard deviations above 50 %.
    PoorlyIdentified,
    /// The model explains the torques poorly.
    PoorFit,
    /// The validation segment is predicted much worse than the fit.
    Validation,
    /// IDIM-IV did not converge.
    IvNotConverged,
    /// The unconstrained estimate is not physically consistent (squared Mahalanobis distance).
    Inconsistent,
    /// A parameter whose sign physics fixes has the other sign, significantly
    /// ([`signs`]).
    PhysicallyImpossible,
}

impl WarningKind {
    /// Its name in the JSON report (`ill_conditioned`, `physically_impossible`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            WarningKind::IllConditioned => "ill_conditioned",
            WarningKind::PoorlyIdentified => "poorly_identified",
            WarningKind::PoorFit => "poor_fit",
            WarningKind::Validation => "validation",
            WarningKind::IvNotConverged => "iv_not_converged",
            WarningKind::Inconsistent => "inconsistent",
            WarningKind::PhysicallyImpossible => "physically_impossible",
        }
    }
}

/// A warning of the identification: where the result may be unreliable, with the parameters
/// concerned. Its `Display` is the message.
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// What it is about.
    pub kind: WarningKind,
    /// The parameters concerned (names, as in [`Identification::parameters`]); may be empty.
    pub parameters: Vec<String>,
    /// The message, in words.
    pub message: String,
}

impl Warning {
    fn new(kind: WarningKind, parameters: Vec<String>, message: String) -> Warning {
        Warning {
            kind,
            parameters,
            message,
        }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

/// Result of [`identify`].
#[derive(Clone, Debug)]
pub struct Identification {
    /// Robot name.
    pub robot: String,
    /// Frame numbers of the joints whose torques are modelled (actuated joints).
    pub joints: Vec<usize>,
    /// Their names.
    pub joint_names: Vec<String>,
    /// Whether the joint of frame j is prismatic (entry j - 1, j = 1..=NL): forces in N and
    /// positions in m rather than N m and rad (the units of the report and the plot).
    pub prismatic: Vec<bool>,
    /// The identified parameters (names, kinds), in the order of `x`.
    pub parameters: Vec<Parameter>,
    /// The estimator used (`OLS`, `WLS` or `IDIM-IV`, with "under physical-consistency
    /// constraints (SDP)" when constrained).
    pub estimator: String,
    /// The estimate X (SI units of each parameter).
    pub x: Vec<f64>,
    /// Standard deviations of X (same units).
    pub std: Vec<f64>,
    /// Relative standard deviations 100 std / |x| (%).
    pub relative_std: Vec<f64>,
    /// Condition number of W with unit-norm columns.
    pub condition_number: f64,
    /// Condition number of W as built (depends on the units).
    pub condition_number_unscaled: f64,
    /// ||Y - W X|| / ||Y|| over the fit rows.
    pub relative_error: f64,
    /// Fit per joint.
    pub per_joint: Vec<JointFit>,
    /// Prediction of the validation segment, if one was kept out.
    pub validation: Option<Validation>,
    /// The processing applied, with every value used (of the first log, with the counts
    /// summed, when there are several).
    pub processing: ProcessingReport,
    /// The processing of each log, in order.
    pub logs: Vec<ProcessingReport>,
    /// The essential parameters, when asked for.
    pub essential: Option<Essential>,
    /// IDIM-IV iterations, for that estimator.
    pub iv: Option<IvReport>,
    /// Physically consistent standard parameters, when asked for.
    pub consistent: Option<Consistent>,
    /// Where the result may be unreliable (ill-conditioning, poor fit, physically impossible
    /// values, ...).
    pub warnings: Vec<Warning>,
    /// What the user should know about the processing.
    pub notes: Vec<String>,
    /// Decimated rows of the validation segment (empty unless `keep_validation_rows`).
    pub validation_rows: ValidationRows,
    /// The parameter model (rows, maps) for predictions and robot files.
    pub model: ParameterModel,
}

impl Identification {
    /// Standard parameters of a robot file reproducing the estimate: the consistent ones when
    /// computed, else the base robot (every other standard parameter zero).
    pub fn standard_parameters(&self) -> Vec<f64> {
        match &self.consistent {
            Some(c) => c.standard.clone(),
            None => self.model.base_robot_parameters(&self.x),
        }
    }

    /// Predicted torques of the validation rows (N per row).
    pub fn predicted_validation(&self) -> Vec<Vec<f64>> {
        let p = self.x.len();
        let n = self.joints.len();
        self.validation_rows
            .w
            .iter()
            .map(|w| {
                (0..n)
                    .map(|k| (0..p).map(|c| w[k * p + c] * self.x[c]).sum())
                    .collect()
            })
            .collect()
    }
}

/// Processing settings from the log's sample rate and the options (checked by
/// [`Options::validate`]; the filters' settling and the borders against the log's length).
pub fn processing(summary: &LogSummary, opt: &Options) -> Result<(Processing, ProcessingReport)> {
    opt.validate()?;
    let fs = summary.sample_rate();
    let bw = opt.bandwidth;
    let derivatives = summary.has_derivatives && opt.use_log_derivatives;
    let lowpass = if derivatives {
        None
    } else {
        let fc = opt
            .cutoff
            .unwrap_or((ROW_BAND_PER_BANDWIDTH * bw).min(0.4 * fs));
        Some(Butterworth::lowpass(opt.filter_order, fc, fs)?)
    };
    let nd = opt
        .decimation
        .unwrap_or_else(|| default_decimation(fs, bw, lowpass.as_ref().map(|f| f.cutoff)));
    let decimation_filter = if nd > 1 {
        Some(Butterworth::lowpass(8, 0.8 * fs / (2.0 * nd as f64), fs)?)
    } else {
        None
    };
    let samples = summary.samples;
    if let Some(f) = &lowpass {
        // the zero-phase stream holds the filter's settling time: no longer than the log
        let settling = f.settling_samples(1e-3);
        if settling >= samples {
            return Err(Error::Input(format!(
                "{}: the position low-pass (cut-off {} Hz at {fs} Hz) settles in {settling} \
                 samples, more than the log's {samples}: the log is too short for this cut-off",
                summary.source, f.cutoff
            )));
        }
    }
    let border = opt
        .border
        .unwrap_or_else(|| lowpass.as_ref().map_or(0, |f| f.settling_samples(1e-3)));
    if border >= samples / 2 {
        return Err(Error::Input(format!(
            "{}: dropping {border} samples at each end (the border) leaves nothing of the \
             log's {samples} samples",
            summary.source
        )));
    }
    let decimation_skip = decimation_filter
        .as_ref()
        .map_or(0, |f| f.settling_samples(1e-3));
    let std_inflation = decimation_filter
        .as_ref()
        .map_or(1.0, |f| f.decimated_noise_gain(nd));
    let duration = summary.duration();
    let validation = opt.validation.map(|(a, b)| {
        let end = if b >= 1.0 {
            f64::INFINITY
        } else {
            summary.t0 + b * duration
        };
        (summary.t0 + a * duration, end)
    });
    check_efforts(summary, opt)?;
    let coulomb_band = opt.coulomb_band.unwrap_or(if derivatives {
        0.0
    } else {
        DEFAULT_COULOMB_BAND
    });
    let min_speed = opt
        .min_speed
        .unwrap_or(if derivatives { 0.0 } else { DEFAULT_MIN_SPEED });
    let proc = Processing {
        dt: summary.dt,
        samples,
        lowpass: lowpass.clone(),
        decimation: nd,
        decimation_filter: decimation_filter.clone(),
        decimation_skip,
        border,
        validation,
        gains: opt.gains.clone(),
        min_speed,
        coulomb_band,
        validation_row_stride: if opt.keep_validation_rows {
            // the decimated rows of the segment, estimated from its fraction of the log
            let fraction = opt.validation.map_or(0.0, |(a, b)| b - a);
            let expected = (fraction * samples as f64 / nd as f64).ceil() as usize;
            expected.div_ceil(observation::MAX_KEPT_ROWS).max(1)
        } else {
            0
        },
    };
    let report = ProcessingReport {
        source: summary.source.clone(),
        samples,
        sample_rate: fs,
        duration,
        bandwidth: bw,
        derivatives_from_log: derivatives,
        lowpass: lowpass.map(|f| (f.order, f.cutoff)),
        decimation: nd,
        decimation_filter: decimation_filter.map(|f| (f.order, f.cutoff)),
        border,
        decimation_skip,
        std_inflation,
        min_speed,
        coulomb_band,
        fit_samples: 0,
        validation_samples: 0,
        validation: validation.map(|(a, b)| (a, b.min(summary.t0 + duration))),
        slow_rows: Vec::new(),
    };
    Ok((proc, report))
}

/// Currents need gains and gains need currents (torques taken as currents would be scaled
/// silently).
fn check_efforts(summary: &LogSummary, opt: &Options) -> Result<()> {
    match (summary.effort, &opt.gains) {
        (Effort::Current, None) => Err(Error::Input(format!(
            "{}: the log has motor currents (i<j>): give the drive gains to convert them to \
             torques",
            summary.source
        ))),
        (Effort::Torque, Some(_)) => Err(Error::Input(format!(
            "{}: drive gains were given but the log has joint torques (tau<j> columns), not \
             motor currents (i<j>): the gains would scale the torques",
            summary.source
        ))),
        _ => Ok(()),
    }
}

/// One gain per motor (actuated joint).
fn check_gain_count(opt: &Options, motors: usize) -> Result<()> {
    match &opt.gains {
        Some(g) if g.len() != motors => Err(Error::Input(format!(
            "{} drive gains for {motors} motors: one gain per motor expected",
            g.len()
        ))),
        _ => Ok(()),
    }
}

fn joint_fits(
    access: &ModelAccess,
    factors: &mut [estimators::TriangularFactor],
    x: &[f64],
    sigma: Option<&[f64]>,
) -> (Vec<JointFit>, f64) {
    let names = access.joint_names();
    let (mut res, mut out) = (0.0, 0.0);
    let fits = factors
        .iter_mut()
        .enumerate()
        .map(|(k, f)| {
            let rows = f.rows();
            let t = f.factor();
            let r = residual_sq(t, x);
            let y = output_sq(t);
            res += r;
            out += y;
            JointFit {
                joint: access.actuated_joints()[k],
                name: names[k].clone(),
                rows,
                rms: if rows > 0 {
                    (r / rows as f64).sqrt()
                } else {
                    0.0
                },
                relative_error: if y > 0.0 { (r / y).sqrt() } else { 0.0 },
                sigma: sigma.map(|s| s[k]),
            }
        })
        .collect();
    (fits, if out > 0.0 { (res / out).sqrt() } else { 0.0 })
}

/// Identify the parameters of `access`'s robot from `log`.
///
/// # Example
///
/// A noise-free log of the SCARA tracking a Fourier trajectory (simulated with the file's
/// parameters): ordinary least squares give back the true base parameters.
///
/// ```
/// use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
/// use robodyn::identification::model_access::ModelAccess;
/// use robodyn::io::load_description;
/// use robodyn::identification::{identify, Estimator, Options};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/scara.toml");
/// let mut access = ModelAccess::new(load_description(path)?)?;
/// let start = access.reference_actuated()?;
/// let harmonics = 5;
/// let free: Vec<f64> = (0..start.len() * FourierTrajectory::free_per_joint(harmonics))
///     .map(|k| 0.4 * ((k as f64) * 1.7).sin())
///     .collect();
/// let trajectory = FourierTrajectory::from_free(4.0, &start, harmonics, &free);
/// let log = simulated_log(&access, &trajectory, 8.0, 0.004, 5.0)?; // t, q, qd, qdd, torques
/// let opt = Options { estimator: Estimator::Ols, validation: None, ..Options::default() };
/// let id = identify(&mut access, &log, &opt)?;
/// let truth = id.model.values(&access.standard_parameters());
/// for (k, p) in id.parameters.iter().enumerate() {
///     println!("{:>8} = {:10.5} (true {:10.5})", p.name, id.x[k], truth[k]);
/// }
/// assert!(id.relative_error < 1e-8);
/// # Ok(())
/// # }
/// ```
pub fn identify(
    access: &mut ModelAccess,
    log: &dyn LogSource,
    opt: &Options,
) -> Result<Identification> {
    identify_logs(access, &[log], opt)
}

/// Identify the parameters of `access`'s robot from several logs of it (a fleet of identical
/// robots, campaigns): one least-squares problem over the rows of every log, each log
/// processed (filtered, decimated, its borders and validation segment taken) on its own. The
/// same as [`identify_from_statistics`] of the logs' [`statistics::statistics`], with IDIM-IV
/// as well (it simulates each log again).
pub fn identify_logs(
    access: &mut ModelAccess,
    logs: &[&dyn LogSource],
    opt: &Options,
) -> Result<Identification> {
    opt.validate()?;
    if logs.is_empty() {
        return Err(Error::Input(
            "no log to identify from: give at least one".into(),
        ));
    }
    let mut model = ParameterModel::build(access, &opt.parameters)?;
    check_gain_count(opt, model.joints_count())?;
    // each log is read once (recorded unless it is repeatable): every pass sees the same
    // samples, whatever happens to the source (a file still being written, a pipe)
    let read = logs
        .iter()
        .map(|log| read_once(*log, model.joints_count()))
        .collect::<Result<Vec<_>>>()?;
    let mut parts = Vec::with_capacity(logs.len());
    let mut passes = Vec::with_capacity(logs.len());
    for (log, (summary, recording)) in logs.iter().zip(&read) {
        let source: &dyn LogSource = match recording {
            Some(r) => r,
            None => *log,
        };
        let (stats, proc) = pass_statistics(access, &mut model, (source, summary), opt)?;
        parts.push(stats);
        passes.push((source, proc));
    }
    let stats = if parts.len() == 1 {
        parts.pop().expect("one part")
    } else {
        Statistics::merged(&parts)?
    };
    finish(access, model, stats, opt, Some(&passes))
}

/// Identify the parameters of `access`'s robot from the statistics of logs
/// ([`statistics::statistics`], possibly computed elsewhere and read back with
/// [`Statistics::from_json`]), merged: the same numbers as [`identify_logs`] of the logs. The
/// statistics must be of this robot, with these parameters and the row options of `opt`
/// (checked); IDIM-IV, which simulates the logs again, needs the logs themselves.
pub fn identify_from_statistics(
    access: &mut ModelAccess,
    parts: &[Statistics],
    opt: &Options,
) -> Result<Identification> {
    opt.validate()?;
    if opt.estimator == Estimator::Iv {
        return Err(Error::Input(
            "IDIM-IV simulates every log again at each iteration: it needs the logs, not their \
             statistics (use WLS or OLS, or identify from the logs)"
                .into(),
        ));
    }
    let model = ParameterModel::build(access, &opt.parameters)?;
    check_gain_count(opt, model.joints_count())?;
    let stats = Statistics::merged(parts)?;
    stats.check_against(access, &model, opt)?;
    finish(access, model, stats, opt, None)
}

/// Read a log once: its summary, and its recording unless it is repeatable.
pub(crate) fn read_once(
    log: &dyn LogSource,
    n: usize,
) -> Result<(LogSummary, Option<data::RecordedLog>)> {
    if log.repeatable() {
        Ok((summarize(log, n)?, None))
    } else {
        let (summary, r) = record(log, n)?;
        Ok((summary, Some(r)))
    }
}

/// The statistics of one log read once (`source` repeatable, `summary` its first read): the
/// pass of the fit, with the processing it used.
fn pass_statistics(
    access: &mut ModelAccess,
    model: &mut ParameterModel,
    (source, summary): (&dyn LogSource, &LogSummary),
    opt: &Options,
) -> Result<(Statistics, Processing)> {
    let (proc, mut preport) = processing(summary, opt)?;
    model.coulomb_band = proc.coulomb_band;
    let mut pass = run_pass(source, model, access, &proc, None)?;
    if pass.samples_read != summary.samples {
        return Err(Error::Input(format!(
            "{}: the log changed while it was read ({} samples, then {})",
            summary.source, summary.samples, pass.samples_read
        )));
    }
    preport.fit_samples = pass.fit_samples;
    preport.validation_samples = pass.validation_samples;
    preport.slow_rows = pass.slow_rows.clone();
    let digest = pass
        .fit
        .iter_mut()
        .flat_map(|f| {
            let t = f.factor();
            (0..t.ncols()).map(|i| t[(i, i)]).collect::<Vec<_>>()
        })
        .collect();
    let stats = Statistics {
        format: statistics::FORMAT.into(),
        version: statistics::VERSION,
        fingerprint: statistics::Fingerprint::of(access, model),
        options: statistics::RowOptions::of(opt),
        logs: vec![preport],
        digests: vec![digest],
        fit: std::mem::take(&mut pass.fit),
        validation: std::mem::take(&mut pass.validation),
        validation_raw: std::mem::take(&mut pass.validation_raw),
        validation_rows: std::mem::take(&mut pass.validation_rows),
    };
    Ok((stats, proc))
}

/// The statistics of one log (see [`statistics::statistics`]).
fn log_statistics(
    access: &mut ModelAccess,
    model: &mut ParameterModel,
    log: &dyn LogSource,
    opt: &Options,
) -> Result<(Statistics, Processing)> {
    check_gain_count(opt, model.joints_count())?;
    let (summary, recording) = read_once(log, model.joints_count())?;
    let source: &dyn LogSource = match &recording {
        Some(r) => r,
        None => log,
    };
    pass_statistics(access, model, (source, &summary), opt)
}

/// The identification from merged statistics; `logs` (each log with its processing) for
/// IDIM-IV.
fn finish(
    access: &mut ModelAccess,
    mut model: ParameterModel,
    mut stats: Statistics,
    opt: &Options,
    logs: Option<&[(&dyn LogSource, Processing)]>,
) -> Result<Identification> {
    let p = model.count();
    let names = model.names();
    let rows = check_rows(&mut stats, p)?;
    let preport = merged_report(&stats.logs);
    let mut warnings = Vec::new();
    let mut notes = Vec::new();
    let ts: Vec<Mat<f64>> = stats.fit.iter_mut().map(|f| f.factor().clone()).collect();
    let (mut sol, sigma) =
        first_estimate(opt.estimator, &mut stats.fit, &ts, rows, (&names, access))?;
    let mut estimator = opt.estimator.name().to_string();
    let mut iv_report = None;
    if opt.estimator == Estimator::Iv {
        let sig = sigma.as_deref().expect("weights");
        let logs = logs.expect("IDIM-IV is refused without the logs");
        let (report, warning) =
            idim_iv(logs, (&mut model, access), opt, (&ts, sig, rows), &mut sol)?;
        warnings.extend(warning);
        iv_report = Some(report);
    }
    // the decimated residuals are correlated: the covariance accounts for it
    sol.inflate(preport.std_inflation);
    let tw = weighted(&ts, sigma.as_deref());
    // physically consistent parameters: the constrained least squares, which is also the
    // consistent set nearest to the unconstrained estimate in the metric of its covariance
    let mut consistent = None;
    if opt.consistent || opt.standard {
        let c =
            consistency::consistent_parameters(access, &model, &tw, &sol, opt.consistency_solver)?;
        warnings.extend(inconsistency_warning(&c, &sol, &names));
        if opt.consistent {
            sol.x = c.x_full.clone();
            estimator.push_str(" under physical-consistency constraints (SDP)");
            notes.push(
                "the standard deviations are those of the unconstrained estimate; parameters whose \
                 constraint is active are at the boundary of the consistent set"
                    .into(),
            );
        }
        consistent = Some(c.result);
    }
    // essential parameters
    let essential = match opt.essential {
        Some(e) => Some(essential_parameters(
            &tw,
            &ts,
            (rows, preport.std_inflation),
            &names,
            &e,
        )?),
        None => None,
    };
    let relative_std = sol.relative_std();
    let (per_joint, relative_error) = joint_fits(access, &mut stats.fit, &sol.x, sigma.as_deref());
    let validation = validation(access, &mut stats, &sol.x, &preport);
    let quality = quality_warnings(&sol, &names, &relative_std, relative_error, &validation);
    warnings.extend(quality);
    warnings.extend(signs::warnings(
        &model,
        &sol.x,
        &sol.std,
        &relative_std,
        &ts,
    ));
    notes.extend(processing_notes(
        &preport,
        opt,
        model.transmission.is_some(),
    ));
    notes.extend(logs_note(&stats.logs));
    Ok(Identification {
        robot: access.name().to_string(),
        joints: access.actuated_joints().to_vec(),
        joint_names: access.joint_names(),
        prismatic: (1..=access.nl()).map(|j| access.is_prismatic(j)).collect(),
        parameters: model.params.clone(),
        estimator,
        x: sol.x.clone(),
        std: sol.std.clone(),
        relative_std,
        condition_number: sol.condition,
        condition_number_unscaled: sol.condition_unscaled,
        relative_error,
        per_joint,
        validation: validation.ok(),
        processing: preport,
        logs: std::mem::take(&mut stats.logs),
        essential,
        iv: iv_report,
        consistent,
        warnings,
        notes,
        validation_rows: std::mem::take(&mut stats.validation_rows),
        model,
    })
}

/// The processing of a set of logs: that of the first, with the counts (samples, duration,
/// decimated samples, slow rows) summed over the logs and the source naming them all.
fn merged_report(logs: &[ProcessingReport]) -> ProcessingReport {
    let mut r = logs[0].clone();
    if logs.len() == 1 {
        return r;
    }
    r.source = statistics::sources(logs);
    // the covariance's inflation for correlated residuals: each log's weighted by its rows
    // (the logs' decimation filters differ only with their sample rates)
    let rows: usize = logs.iter().map(|l| l.fit_samples).sum();
    if rows > 0 {
        r.std_inflation = logs
            .iter()
            .map(|l| l.std_inflation * l.fit_samples as f64)
            .sum::<f64>()
            / rows as f64;
    }
    for l in &logs[1..] {
        r.samples += l.samples;
        r.duration += l.duration;
        r.fit_samples += l.fit_samples;
        r.validation_samples += l.validation_samples;
        for (a, b) in r.slow_rows.iter_mut().zip(&l.slow_rows) {
            *a += b;
        }
    }
    r
}

/// The note of an identification from several logs: how the processing is reported.
fn logs_note(logs: &[ProcessingReport]) -> Option<String> {
    (logs.len() > 1).then(|| {
        let rates: Vec<f64> = logs.iter().map(|l| l.sample_rate).collect();
        let same = rates.iter().all(|&r| r == rates[0]);
        format!(
            "identified from {} logs, each processed on its own (the processing printed is the \
             first's{}; samples, duration and decimated samples are the sums; the validation \
             segment is the same fraction of each log, its times those of the first)",
            logs.len(),
            if same {
                String::new()
            } else {
                ", sample rates differ".into()
            }
        )
    })
}

/// The warning when the unconstrained estimate `sol` is not physically consistent: the nearest
/// consistent set `c` lies beyond the 99.8 % quantile of chi-square with p degrees of freedom
/// (p + 3 sqrt(2p)) in the metric of the estimate's covariance, and differs from it by more than
/// rounding (a noise-free fit whose true values lie on the boundary, e.g. zero friction, is not
/// reported).
fn inconsistency_warning(
    c: &consistency::ConsistentSolution,
    sol: &LsSolution,
    names: &[String],
) -> Option<Warning> {
    let p = sol.x.len();
    let bound = p as f64 + 3.0 * (2.0 * p as f64).sqrt();
    let scale = sol.x.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let significant = c
        .x_full
        .iter()
        .zip(&sol.x)
        .any(|(a, b)| (a - b).abs() > 1e-6 * b.abs().max(1e-3 * scale));
    if c.result.distance2 <= bound || !significant {
        return None;
    }
    let worst = c
        .result
        .deviation
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
        .map_or(0, |(i, _)| i);
    Some(Warning::new(
        WarningKind::Inconsistent,
        vec![names[worst].clone()],
        format!(
            "the unconstrained estimate is not physically consistent: the nearest consistent \
             set is at a squared Mahalanobis distance {:.1} (above {bound:.1}, the 99.8 % \
             quantile of chi-square with {p} degrees of freedom); largest change {:.1} standard \
             deviations ({})",
            c.result.distance2, c.result.max_deviation, names[worst]
        ),
    ))
}

/// The triangular factor of the union of the joints' rows, joint k's weighted by 1 / sigma_k
/// (unweighted without sigma).
fn weighted(ts: &[Mat<f64>], sigma: Option<&[f64]>) -> Mat<f64> {
    let parts: Vec<(&Mat<f64>, f64)> = match sigma {
        Some(sig) => ts.iter().zip(sig).map(|(t, s)| (t, 1.0 / s)).collect(),
        None => ts.iter().map(|t| (t, 1.0)).collect(),
    };
    combine(&parts)
}

/// OLS, or Gautier's WLS with each joint's sigma (the weights, returned); IDIM-IV starts from
/// the WLS estimate.
fn first_estimate(
    estimator: Estimator,
    fit: &mut [estimators::TriangularFactor],
    ts: &[Mat<f64>],
    rows: usize,
    (names, access): (&[String], &ModelAccess),
) -> Result<(LsSolution, Option<Vec<f64>>)> {
    // OLS first for every estimator: its rank check names the parameters without effect (a
    // log that excites nothing) before the weights are formed
    let ols = least_squares(&weighted(ts, None), rows, names)?;
    if estimator == Estimator::Ols {
        return Ok((ols, None));
    }
    let sig = fit
        .iter_mut()
        .map(|f| {
            let r = f.rows();
            joint_sigma(f.factor(), r)
        })
        .collect::<Result<Vec<f64>>>()?;
    if let Some(k) = sig.iter().position(|s| s.is_nan() || *s <= 0.0) {
        return Err(Error::Setting {
            option: "identification::Options::estimator",
            reason: format!(
                "joint {}: its equations are fitted exactly (sigma = 0), so Gautier's weight \
                 1/sigma is infinite; use the OLS estimator (noise-free data)",
                access.actuated_joints()[k]
            ),
        });
    }
    let sol = least_squares(&weighted(ts, Some(&sig)), rows, names)?;
    Ok((sol, Some(sig)))
}

/// What the user should know about the processing: the decimation filtering the dynamics, the
/// rows left out as slow, the motor units of a transmission.
fn processing_notes(preport: &ProcessingReport, opt: &Options, transmission: bool) -> Vec<String> {
    let mut notes = Vec::new();
    if let Some((_, fd)) = preport.decimation_filter {
        if fd < 2.0 * opt.bandwidth {
            notes.push(format!(
                "the decimation low-pass ({fd:.3} Hz) is below twice the bandwidth: the \
                 dynamics are filtered too, consistently on both sides (parallel filtering)"
            ));
        }
    }
    let total_slow: usize = preport.slow_rows.iter().sum();
    if total_slow > 0 {
        notes.push(format!(
            "{total_slow} joint rows of the fit left out as slower than the minimum speed {} (per joint {:?})",
            preport.min_speed, preport.slow_rows
        ));
    }
    if transmission {
        notes.push(
            "with the transmission, IA/FS/FV of a joint's link are its motor's parameters in \
             motor units (tau = R^T (Ia m_dd + Fv m_d + Fs sign(m_d)), m = R q)"
                .into(),
        );
    }
    notes
}

/// The rows of the fit (enough for the parameters) and torques that are not all zero (nothing
/// to fit).
fn check_rows(stats: &mut Statistics, p: usize) -> Result<usize> {
    let rows = stats.rows();
    if rows <= p {
        let l = &stats.logs[0];
        let what = match stats.logs.len() {
            1 => "the log".to_string(),
            n => format!("the {n} logs"),
        };
        let slow: usize = stats.logs.iter().flat_map(|l| &l.slow_rows).sum();
        if slow > 0 {
            return Err(Error::Input(format!(
                "{rows} equations for {p} parameters: {slow} joint rows of {what} were left out \
                 as slower than the minimum speed {} (rad/s or m/s; the joints barely move: a \
                 motion that excites them, or a lower minimum speed)",
                l.min_speed
            )));
        }
        return Err(Error::Input(format!(
            "{rows} equations for {p} parameters after decimation (by {}) and border removal \
             ({} samples at each end): {what} ({} samples) is too short",
            l.decimation,
            l.border,
            stats.logs.iter().map(|l| l.samples).sum::<usize>(),
        )));
    }
    let zero = stats.fit.iter_mut().all(|f| output_sq(f.factor()) == 0.0);
    if zero {
        return Err(Error::Input(format!(
            "{}: the torques are zero on every row of the fit: there is nothing to identify",
            statistics::sources(&stats.logs)
        )));
    }
    Ok(rows)
}

/// IDIM-IV: instruments from a simulation of the current estimate tracking the measured motion,
/// iterated from the weighted least-squares estimate `sol` until no parameter moves by more
/// than 0.02 standard deviations; `sol` becomes the IV estimate.
fn idim_iv(
    logs: &[(&dyn LogSource, Processing)],
    (model, access): (&mut ParameterModel, &mut ModelAccess),
    opt: &Options,
    (ts, sig, rows): (&[Mat<f64>], &[f64], usize),
    sol: &mut LsSolution,
) -> Result<(IvReport, Option<Warning>)> {
    let p = model.count();
    let wls_x = sol.x.clone();
    let mut x = sol.x.clone();
    let mut converged = false;
    let mut last_change = f64::INFINITY;
    let mut deviation = 0.0;
    let mut it = 0;
    while it < opt.iv_iterations {
        it += 1;
        let mut acc: Option<Vec<estimators::IvAccumulator>> = None;
        deviation = 0.0f64;
        for (log, proc) in logs {
            let ivpass = instrument_pass(*log, (model, access), (proc, opt), &x)?;
            deviation = deviation.max(ivpass.instrument_deviation);
            let part = ivpass.iv.expect("instrument accumulators");
            match &mut acc {
                None => acc = Some(part),
                Some(a) => a.iter_mut().zip(&part).for_each(|(a, b)| a.add(b)),
            }
        }
        let acc = acc.expect("at least one log");
        let (x_new, m) = iv_solve(
            &acc.iter()
                .zip(sig)
                .map(|(a, s)| (a, 1.0 / s))
                .collect::<Vec<_>>(),
        )?;
        // residual variance of the weighted rows at the IV estimate
        let res_w: f64 = ts
            .iter()
            .zip(sig)
            .map(|(t, s)| residual_sq(t, &x_new) / (s * s))
            .sum();
        let s2 = res_w / (rows - p) as f64;
        let std: Vec<f64> = (0..p).map(|i| (s2 * m[(i, i)]).max(0.0).sqrt()).collect();
        last_change = x_new
            .iter()
            .zip(&x)
            .zip(&std)
            .map(|((a, b), s)| (a - b).abs() / s.max(f64::MIN_POSITIVE))
            .fold(0.0, f64::max);
        x = x_new;
        sol.x = x.clone();
        sol.std = std;
        sol.sigma2 = s2;
        if last_change < 0.02 {
            converged = true;
            break;
        }
    }
    sol.residual_sq = ts.iter().map(|t| residual_sq(t, &x)).sum();
    let warning = (!converged).then(|| {
        Warning::new(
            WarningKind::IvNotConverged,
            Vec::new(),
            format!(
                "IDIM-IV did not converge in {it} iterations: the last iteration changed a \
                 parameter by {last_change:.2} standard deviations (more iterations, or a slower \
                 tracking loop: a lower IV bandwidth)"
            ),
        )
    });
    let report = IvReport {
        iterations: it,
        converged,
        last_change,
        deviation,
        wls: wls_x,
    };
    Ok((report, warning))
}

/// One pass of IDIM-IV over a log: the instruments from a simulation of the estimate `x`
/// tracking the log's motion.
fn instrument_pass(
    log: &dyn LogSource,
    (model, access): (&mut ParameterModel, &mut ModelAccess),
    (proc, opt): (&Processing, &Options),
    x: &[f64],
) -> Result<PassResult> {
    let f_iv = opt.iv_bandwidth.unwrap_or(opt.bandwidth / 4.0);
    let omega = 2.0 * std::f64::consts::PI * f_iv;
    let substeps = ((proc.dt / 2e-4).ceil() as usize).max(1);
    let k = model.joint_side_drives(&model.base_robot_parameters(x));
    let mut tracking = access.tracking_model(&k, 0.05)?;
    let a = tracking.inertia_diagonal(&access.reference_actuated()?)?;
    let kp: Vec<f64> = a
        .iter()
        .map(|a| a.abs().max(1e-6) * omega * omega)
        .collect();
    let kd: Vec<f64> = a
        .iter()
        .map(|a| a.abs().max(1e-6) * 2.0 * 0.8 * omega)
        .collect();
    let mut ins = Instruments::new(tracking, kp, kd, model.offsets(x), substeps);
    model.coulomb_band = proc.coulomb_band;
    run_pass(log, model, access, proc, Some(&mut ins))
}

/// The prediction of the validation segment with the estimate `x` (decimated rows as fitted,
/// and the raw torques at the log's rate); Err(Some(warning)) when the segment has no sample,
/// Err(None) when there is no segment.
fn validation(
    access: &ModelAccess,
    stats: &mut Statistics,
    x: &[f64],
    preport: &ProcessingReport,
) -> std::result::Result<Validation, Option<Warning>> {
    let (a, b) = preport.validation.ok_or(None)?;
    if preport.validation_samples == 0 {
        return Err(Some(Warning::new(
            WarningKind::Validation,
            Vec::new(),
            format!(
                "the validation segment (from t = {a:.3} s) has no sample after border removal"
            ),
        )));
    }
    let (per_joint, relative_error) = joint_fits(access, &mut stats.validation, x, None);
    let (raw_per_joint, raw_relative_error) =
        joint_fits(access, &mut stats.validation_raw, x, None);
    Ok(Validation {
        from: a,
        to: b,
        relative_error,
        per_joint,
        raw_relative_error,
        raw_per_joint,
    })
}

/// Warnings on the quality of the fit: conditioning, poorly identified parameters, a poor fit,
/// a validation much worse than the fit (or without samples).
fn quality_warnings(
    sol: &LsSolution,
    names: &[String],
    relative_std: &[f64],
    relative_error: f64,
    validation: &std::result::Result<Validation, Option<Warning>>,
) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if sol.condition > 1e4 {
        warnings.push(Warning::new(
            WarningKind::IllConditioned,
            Vec::new(),
            format!(
                "the observation matrix is ill-conditioned (condition number {:.3e} with unit \
                 columns): the motion excites some parameters poorly; their values are \
                 unreliable (see the relative standard deviations; design an exciting motion: \
                 robodyn excite)",
                sol.condition
            ),
        ));
    }
    let poor: Vec<(String, f64)> = names
        .iter()
        .zip(relative_std)
        .filter(|(_, r)| **r > 50.0)
        .map(|(n, r)| (n.clone(), *r))
        .collect();
    if !poor.is_empty() {
        let list: Vec<String> = poor
            .iter()
            .map(|(n, r)| format!("{n} ({r:.0} %)"))
            .collect();
        warnings.push(Warning::new(
            WarningKind::PoorlyIdentified,
            poor.into_iter().map(|(n, _)| n).collect(),
            format!(
                "{} parameter(s) poorly identified (relative standard deviation above 50 %): {} \
                 — their values are not significant (the essential parameters drop them)",
                list.len(),
                list.join(", ")
            ),
        ));
    }
    if relative_error > 0.5 {
        warnings.push(Warning::new(
            WarningKind::PoorFit,
            Vec::new(),
            format!(
                "the model explains the torques poorly: relative error {:.1} % over the fit rows",
                100.0 * relative_error
            ),
        ));
    }
    match validation {
        Ok(v) if v.relative_error > 2.0 * relative_error && v.relative_error > 0.05 => warnings
            .push(Warning::new(
                WarningKind::Validation,
                Vec::new(),
                format!(
                    "the validation segment is predicted much worse than the fit ({:.1} % vs \
                     {:.1} %): the model may be over-fitted or the segment excites other effects",
                    100.0 * v.relative_error,
                    100.0 * relative_error
                ),
            )),
        Err(Some(w)) => warnings.push(w.clone()),
        _ => {}
    }
    warnings
}

/// Essential parameters (see [`EssentialOptions`]).
fn essential_parameters(
    tw: &Mat<f64>,
    ts: &[Mat<f64>],
    (rows, inflation): (usize, f64),
    names: &[String],
    opt: &EssentialOptions,
) -> Result<Essential> {
    let p = tw.ncols() - 1;
    let rel_error = |keep: &[usize], x: &[f64]| -> f64 {
        let mut full = vec![0.0; p];
        for (k, &i) in keep.iter().enumerate() {
            full[i] = x[k];
        }
        let r: f64 = ts.iter().map(|t| residual_sq(t, &full)).sum();
        let y: f64 = ts.iter().map(output_sq).sum();
        (r / y).sqrt()
    };
    let mut keep: Vec<usize> = (0..p).collect();
    let sub = |keep: &[usize]| -> Result<LsSolution> {
        let names: Vec<String> = keep.iter().map(|&i| names[i].clone()).collect();
        let mut sol = least_squares(&restrict(tw, keep), rows, &names)?;
        sol.inflate(inflation);
        Ok(sol)
    };
    let mut sol = sub(&keep)?;
    let e0 = rel_error(&keep, &sol.x);
    loop {
        let rs = sol.relative_std();
        let (worst, &worst_std) = rs
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.partial_cmp(b.1).unwrap_or(std::cmp::Ordering::Equal))
            .expect("at least one parameter");
        if worst_std <= opt.max_relative_std || keep.len() == 1 {
            break;
        }
        let mut trial = keep.clone();
        trial.remove(worst);
        let tsol = sub(&trial)?;
        if rel_error(&trial, &tsol.x) > (1.0 + opt.tolerance) * e0 {
            break;
        }
        keep = trial;
        sol = tsol;
    }
    Ok(Essential {
        relative_std: sol.relative_std(),
        relative_error: rel_error(&keep, &sol.x),
        full_relative_error: e0,
        kept: keep,
        x: sol.x,
    })
}

/// Names of the parameters of a given kind (for reports and tests).
pub fn is_offset(p: &Parameter) -> bool {
    matches!(p.kind, Kind::Offset(_))
}
