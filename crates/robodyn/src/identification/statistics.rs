//! Sufficient statistics of the identification: what the estimate needs of one log, so that a
//! set of logs (a fleet of identical robots, hours of operation, campaigns) is identified as one
//! least-squares problem whose statistics are the sums of the logs' — a map-reduce.
//!
//! Per actuated joint j, the rows of the fit carry W_j^T W_j, W_j^T y_j, y_j^T y_j and their
//! count as the triangular factor T_j of [W_j y_j] (T_j^T T_j = [W_j y_j]^T [W_j y_j];
//! [`TriangularFactor`]): the same information as the sums, without squaring the condition
//! number. The union of row sets is the QR of the stacked factors, so merging is exact up to
//! rounding, in any order. Gautier's weight of joint j (the standard deviation of its error) and
//! the standard deviations of the estimate are then computed from the merged per-joint factors
//! exactly as for one log: one pass per log suffices. The validation segment of each log (and its
//! raw torques) is carried the same way.
//!
//! A [`Statistics`] records the robot it was computed for ([`Fingerprint`]: name, joints,
//! parameters with their grouping equations, geometry, transmission) and the options that shape
//! the rows ([`RowOptions`]); merging statistics of another robot or other options is refused.
//! It serializes to JSON (serde) for files and for the workers of a distributed engine.

use super::data::LogSource;
use super::estimators::TriangularFactor;
use super::model_access::ModelAccess;
use super::observation::ValidationRows;
use super::parameters::ParameterModel;
use super::{Options, ProcessingReport};
use crate::error::{Error, Result};
use serde::{Deserialize, Serialize};

/// The `format` field of a statistics file.
pub const FORMAT: &str = "robodyn-identification-statistics";
/// The version of the statistics format this build reads and writes.
pub const VERSION: u32 = 1;

/// The robot a [`Statistics`] was computed for: what determines the columns of W.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fingerprint {
    /// Robot name.
    pub robot: String,
    /// Frame numbers of the actuated joints.
    pub joints: Vec<usize>,
    /// Their names.
    pub joint_names: Vec<String>,
    /// The identified parameters: name and grouping equation.
    pub parameters: Vec<(String, String)>,
    /// Each frame's geometry: name, antecedent, joint type, actuated, gamma, b, alpha, d, theta,
    /// r (as written in the robot file, with its symbols' values), then the gravity.
    pub geometry: Vec<String>,
    /// The transmission matrix R, when the robot has one.
    pub transmission: Option<Vec<Vec<f64>>>,
}

impl Fingerprint {
    /// The fingerprint of `access`'s robot with the parameters of `model`.
    pub fn of(access: &ModelAccess, model: &ParameterModel) -> Fingerprint {
        let desc = access.description();
        let mut geometry: Vec<String> = desc
            .frames
            .iter()
            .map(|f| {
                format!(
                    "{} ant {} {:?} actuated {} gamma {} b {} alpha {} d {} theta {} r {}",
                    f.name, f.ant, f.joint, f.actuated, f.gamma, f.b, f.alpha, f.d, f.theta, f.r
                )
            })
            .collect();
        geometry.push(format!(
            "gravity {} {} {}",
            desc.gravity[0], desc.gravity[1], desc.gravity[2]
        ));
        // the values of the symbols the geometry names (a symbolic length's number)
        for (name, v) in &desc.symbols {
            if geometry.iter().any(|g| mentions(g, name)) {
                geometry.push(format!("{name} = {v:e}"));
            }
        }
        Fingerprint {
            robot: access.name().to_string(),
            joints: access.actuated_joints().to_vec(),
            joint_names: access.joint_names(),
            parameters: model
                .params
                .iter()
                .map(|p| (p.name.clone(), p.equation.clone()))
                .collect(),
            geometry,
            transmission: access.transmission().map(|t| t.matrix.clone()),
        }
    }

    /// Err naming the first difference from `other` (`what` says where `other` comes from).
    fn check(&self, other: &Fingerprint, what: &str) -> Result<()> {
        let differ = |field: &str, a: String, b: String| {
            Err(Error::Input(format!(
                "{what} are of another robot or parameter set: its {field} is {b}, here {a}; \
                 statistics merge only for one robot model with the same parameters"
            )))
        };
        if self.robot != other.robot {
            return differ("name", q(&self.robot), q(&other.robot));
        }
        if self.joints != other.joints || self.joint_names != other.joint_names {
            return differ(
                "actuated joints",
                format!("{:?}", self.joint_names),
                format!("{:?}", other.joint_names),
            );
        }
        if let Some(k) = first_difference(&self.geometry, &other.geometry) {
            return differ(
                "geometry",
                line(&self.geometry, k),
                line(&other.geometry, k),
            );
        }
        if self.transmission != other.transmission {
            return differ(
                "transmission",
                format!("{:?}", self.transmission),
                format!("{:?}", other.transmission),
            );
        }
        if let Some(k) = first_difference(&self.parameters, &other.parameters) {
            let show = |v: &[(String, String)]| {
                v.get(k)
                    .map_or("(none)".to_string(), |(n, e)| format!("{n} = {e}"))
            };
            return differ(
                &format!("parameter {}", k + 1),
                show(&self.parameters),
                show(&other.parameters),
            );
        }
        Ok(())
    }
}

fn q(s: &str) -> String {
    format!("`{s}`")
}

fn line(v: &[String], k: usize) -> String {
    v.get(k).map_or("(none)".to_string(), |s| q(s))
}

fn first_difference<T: PartialEq>(a: &[T], b: &[T]) -> Option<usize> {
    (0..a.len().max(b.len())).find(|&k| a.get(k) != b.get(k))
}

/// Whether `text` names the symbol `name` (as a whole word).
fn mentions(text: &str, name: &str) -> bool {
    text.split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .any(|w| w == name)
}

/// The options of [`Options`] that shape the rows of W and Y (the parameters and the processing
/// of each log): statistics merge only when they are equal, and are identified with them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RowOptions {
    /// Which rotor inertias are parameters (`RotorMode::name`).
    pub rotors: String,
    /// Friction parameters.
    pub friction: bool,
    /// Offset parameters.
    pub offsets: bool,
    /// Seed of the base-parameter method.
    pub seed: u64,
    /// Joint-space bandwidth (Hz).
    pub bandwidth: f64,
    /// Cut-off of the position low-pass (Hz).
    pub cutoff: Option<f64>,
    /// Order of the position low-pass.
    pub filter_order: usize,
    /// Decimation factor.
    pub decimation: Option<usize>,
    /// Samples dropped at each end.
    pub border: Option<usize>,
    /// Validation segment (fractions of each log).
    pub validation: Option<(f64, f64)>,
    /// The log's qd, qdd used when given.
    pub use_log_derivatives: bool,
    /// Drive gains.
    pub gains: Option<Vec<f64>>,
    /// Minimum speed of a row (None: the default).
    pub min_speed: Option<f64>,
    /// Dead band of the Coulomb sign.
    pub coulomb_band: Option<f64>,
}

impl RowOptions {
    /// The row-shaping part of `opt`.
    pub fn of(opt: &Options) -> RowOptions {
        RowOptions {
            rotors: opt.parameters.rotors.name().to_string(),
            friction: opt.parameters.friction,
            offsets: opt.parameters.offsets,
            seed: opt.parameters.seed,
            bandwidth: opt.bandwidth,
            cutoff: opt.cutoff,
            filter_order: opt.filter_order,
            decimation: opt.decimation,
            border: opt.border,
            validation: opt.validation,
            use_log_derivatives: opt.use_log_derivatives,
            gains: opt.gains.clone(),
            min_speed: opt.min_speed,
            coulomb_band: opt.coulomb_band,
        }
    }

    /// Err naming the first option that differs from `other`'s.
    fn check(&self, other: &RowOptions, what: &str) -> Result<()> {
        let a = serde_json::to_value(self).expect("options serialize");
        let b = serde_json::to_value(other).expect("options serialize");
        let (serde_json::Value::Object(a), serde_json::Value::Object(b)) = (a, b) else {
            unreachable!("a struct serializes to an object")
        };
        for (k, v) in &a {
            let w = &b[k];
            if v != w {
                return Err(Error::Input(format!(
                    "{what} were computed with the option {k} = {w}, here {k} = {v}: statistics \
                     merge and are identified only with the options that shaped their rows (the \
                     parameters and the processing of the logs)"
                )));
            }
        }
        Ok(())
    }
}

/// The sufficient statistics of the identification from one log or a set of logs of one robot
/// (see the module documentation).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Statistics {
    /// [`FORMAT`].
    pub format: String,
    /// [`VERSION`].
    pub version: u32,
    /// The robot and parameters.
    pub fingerprint: Fingerprint,
    /// The options that shaped the rows.
    pub options: RowOptions,
    /// The processing of each log, in merge order.
    pub logs: Vec<ProcessingReport>,
    /// Per log (same order), the diagonals of its fit factors: the same log merged twice (its
    /// rows counted twice, standard deviations too small by sqrt 2) is recognized and refused.
    pub digests: Vec<Vec<f64>>,
    /// One factor per actuated joint of the fit rows.
    pub fit: Vec<TriangularFactor>,
    /// The same for the validation segments' rows.
    pub validation: Vec<TriangularFactor>,
    /// The same for the validation segments' raw torques at the logs' rates.
    pub validation_raw: Vec<TriangularFactor>,
    /// Decimated validation rows for a plot (kept in memory only, never serialized).
    #[serde(skip)]
    pub validation_rows: ValidationRows,
}

impl Statistics {
    /// Rows of the fit (all joints).
    pub fn rows(&self) -> usize {
        self.fit.iter().map(|f| f.rows()).sum()
    }

    /// Add the rows of `other` (another log, or another set of logs, of the same robot with the
    /// same options): refused with the first difference otherwise.
    pub fn merge(&mut self, other: &Statistics) -> Result<()> {
        let what = format!("the statistics of {}", sources(&other.logs));
        self.options.check(&other.options, &what)?;
        self.fingerprint.check(&other.fingerprint, &what)?;
        for (k, d) in other.digests.iter().enumerate() {
            // a log without fit rows (every row slower than the minimum speed) adds nothing:
            // twice it counts nothing twice, and two such logs have the same empty digest
            let empty = d.iter().all(|v| *v == 0.0);
            if let Some(m) = self.digests.iter().position(|e| e == d && !empty) {
                return Err(Error::Input(format!(
                    "{what}: log {} has the rows of {}, already merged: the same log twice \
                     would count its rows twice (standard deviations too small)",
                    other.logs[k].source, self.logs[m].source
                )));
            }
        }
        let pairs = [
            (&mut self.fit, &other.fit),
            (&mut self.validation, &other.validation),
            (&mut self.validation_raw, &other.validation_raw),
        ];
        for (mine, theirs) in pairs {
            for (a, b) in mine.iter_mut().zip(theirs) {
                a.merge(&mut b.clone());
            }
        }
        self.logs.extend(other.logs.iter().cloned());
        self.digests.extend(other.digests.iter().cloned());
        let (rows, more) = (&mut self.validation_rows, &other.validation_rows);
        rows.t.extend_from_slice(&more.t);
        rows.y.extend_from_slice(&more.y);
        rows.w.extend_from_slice(&more.w);
        Ok(())
    }

    /// The statistics of every part together (in order); an error for an empty list.
    pub fn merged(parts: &[Statistics]) -> Result<Statistics> {
        let (first, rest) = parts.split_first().ok_or_else(|| {
            Error::Input("no statistics to identify from: give at least one".into())
        })?;
        let mut all = first.clone();
        for s in rest {
            all.merge(s)?;
        }
        Ok(all)
    }

    /// Err unless these statistics are of `access`'s robot with `model`'s parameters and the
    /// row options of `opt`.
    pub fn check_against(
        &self,
        access: &ModelAccess,
        model: &ParameterModel,
        opt: &Options,
    ) -> Result<()> {
        let what = format!("the statistics of {}", sources(&self.logs));
        RowOptions::of(opt).check(&self.options, &what)?;
        Fingerprint::of(access, model).check(&self.fingerprint, &what)
    }

    /// The JSON text (every number a full double: merging the read statistics gives the same
    /// numbers as merging the computed ones).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("statistics serialize")
    }

    /// Statistics read from JSON text (`source` names it in errors): checks the format, its
    /// version and the consistency of the factors' sizes.
    pub fn from_json(text: &str, source: &str) -> Result<Statistics> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| Error::Input(format!("{source}: not JSON: {e}")))?;
        if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
            return Err(Error::Input(format!(
                "{source}: not identification statistics (no \"format\": \"{FORMAT}\"; they are \
                 written by `Statistics::to_json`)"
            )));
        }
        let version = value.get("version").and_then(|v| v.as_u64());
        if version != Some(VERSION as u64) {
            return Err(Error::Input(format!(
                "{source}: statistics format version {version:?}, this build reads version \
                 {VERSION}"
            )));
        }
        let s: Statistics = serde_json::from_value(value)
            .map_err(|e| Error::Input(format!("{source}: invalid statistics: {e}")))?;
        s.check_sizes(source)?;
        Ok(s)
    }

    /// One factor per joint in each group, each of p + 1 columns.
    fn check_sizes(&self, source: &str) -> Result<()> {
        let n = self.fingerprint.joints.len();
        let p = self.fingerprint.parameters.len();
        for (name, group) in [
            ("fit", &self.fit),
            ("validation", &self.validation),
            ("validation_raw", &self.validation_raw),
        ] {
            if group.len() != n || group.iter().any(|f| f.params() != p) {
                return Err(Error::Input(format!(
                    "{source}: the {name} factors do not match the robot's {n} joints and {p} \
                     parameters"
                )));
            }
        }
        Ok(())
    }
}

/// The logs' names for messages: `a.csv`, or `3 logs (a.csv, b.csv, ...)`.
pub fn sources(logs: &[ProcessingReport]) -> String {
    match logs {
        [one] => one.source.clone(),
        _ => {
            let names: Vec<&str> = logs.iter().take(3).map(|l| l.source.as_str()).collect();
            let more = if logs.len() > 3 { ", ..." } else { "" };
            format!("{} logs ({}{more})", logs.len(), names.join(", "))
        }
    }
}

/// The statistics of one log: its rows and processing (`identify` of one log is
/// [`super::identify_from_statistics`] of them, with the same numbers).
pub fn statistics(
    access: &mut ModelAccess,
    log: &dyn LogSource,
    opt: &Options,
) -> Result<Statistics> {
    opt.validate()?;
    let mut model = ParameterModel::build(access, &opt.parameters)?;
    let (stats, _) = super::log_statistics(access, &mut model, log, opt)?;
    Ok(stats)
}

/// The statistics of many logs of one robot with one set of options, the robot's models and
/// its parameter model (the numerical base parameters) built once: a worker of a distributed
/// engine keeps one and calls [`StatisticsBuilder::statistics`] per log. The same numbers as
/// [`statistics`] of each log.
pub struct StatisticsBuilder {
    access: ModelAccess,
    model: super::parameters::ParameterModel,
    opt: Options,
}

impl StatisticsBuilder {
    /// The builder of `access`'s robot with the options `opt` (checked).
    pub fn new(mut access: ModelAccess, opt: Options) -> Result<StatisticsBuilder> {
        opt.validate()?;
        let model = super::parameters::ParameterModel::build(&mut access, &opt.parameters)?;
        Ok(StatisticsBuilder { access, model, opt })
    }

    /// The statistics of one log.
    pub fn statistics(&mut self, log: &dyn LogSource) -> Result<Statistics> {
        let (stats, _) = super::log_statistics(&mut self.access, &mut self.model, log, &self.opt)?;
        Ok(stats)
    }

    /// The options the statistics are computed with.
    pub fn options(&self) -> &Options {
        &self.opt
    }

    /// The robot's models.
    pub fn access(&self) -> &ModelAccess {
        &self.access
    }
}
