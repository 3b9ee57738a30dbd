//! Drive gains identified jointly with the dynamic parameters (Gautier & Briot's global
//! identification; Khalil & Dombre ch. 12): a log of motor currents i gives the equations
//! W X = diag(g) i, homogeneous in (X, g) — the currents alone determine the parameters and the
//! gains up to one common scale. A reference fixes the scale:
//!
//! - logs of the same robot with measured joint torques, W X = tau (a torque sensor, or a
//!   campaign on a test bench), or
//! - logs of currents with a known payload fixed on a link: its standard parameters phi enter
//!   as W (X + M_L phi) = diag(g) i, where M_L maps the link's standard parameters onto the
//!   base parameters (the payload's known inertia gives the scale).
//!
//! Every log is processed as [`super::identify`] processes it (filters, decimation, borders,
//! validation segment), into its per-joint factors of [W y] with y the currents (gains of 1);
//! the equations of all logs are stacked in the unknowns (X, g) and solved together
//! ([`super::stacked`]): ordinary, or weighted per log and joint as Gautier's WLS.

use super::data::{Effort, LogSource, RawSample};
use super::model_access::ModelAccess;
use super::parameters::{Parameter, ParameterModel};
use super::payload::{payload_columns, PAYLOAD_PARAMETERS};
use super::stacked::{combination, identity_columns, solve, Block, BlockMap};
use super::{log_statistics, Estimator, Options, ProcessingReport};
use crate::error::{Error, Result};

/// A log whose effort columns are read as motor currents (`i<j>`), whatever its source says:
/// for logs in memory ([`super::data::MemoryLog`] holds torques).
pub struct Currents<'a>(pub &'a dyn LogSource);

impl LogSource for Currents<'_> {
    fn name(&self) -> String {
        self.0.name()
    }
    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        self.0.read(visit)
    }
    fn effort(&self) -> Effort {
        Effort::Current
    }
    fn repeatable(&self) -> bool {
        self.0.repeatable()
    }
}

/// What fixes the scale of the gains.
pub enum GainReference<'a> {
    /// Logs of the same robot with measured joint torques (`tau<j>`).
    Torques(Vec<&'a dyn LogSource>),
    /// Logs of currents with a known payload on frame `link`: its 10 standard parameters
    /// (XX, XY, XZ, YY, YZ, ZZ about O_link in R_link, MX, MY, MZ, M).
    Payload {
        /// Frame number of the link carrying the payload.
        link: usize,
        /// The payload's standard parameters.
        parameters: [f64; 10],
        /// The logs of currents with the payload.
        logs: Vec<&'a dyn LogSource>,
    },
}

/// The identified drive gains and parameters.
#[derive(Clone, Debug)]
pub struct GainIdentification {
    /// Robot name.
    pub robot: String,
    /// Frame numbers of the actuated joints (one motor each).
    pub joints: Vec<usize>,
    /// Their names.
    pub joint_names: Vec<String>,
    /// Drive gain of each motor (torque per unit of current: N m/A, or N/A).
    pub gains: Vec<f64>,
    /// Their standard deviations.
    pub gains_std: Vec<f64>,
    /// The dynamic parameters identified with them.
    pub parameters: Vec<Parameter>,
    /// Their estimate.
    pub x: Vec<f64>,
    /// Their standard deviations.
    pub std: Vec<f64>,
    /// `OLS` or `WLS`.
    pub estimator: String,
    /// Condition number of the stacked equations with unit-norm columns.
    pub condition_number: f64,
    /// RMS of the residual of the stacked equations (N m or N).
    pub residual_rms: f64,
    /// Rows of the stacked equations.
    pub rows: usize,
    /// The reference, in words.
    pub reference: String,
    /// The processing of each log: the logs of currents, then the reference's.
    pub logs: Vec<ProcessingReport>,
    /// Covariance factor for the correlated residuals of the decimation (see
    /// [`ProcessingReport::std_inflation`]).
    pub std_inflation: f64,
}

impl GainIdentification {
    /// The report as JSON (`robodyn identify --estimate-gains --format json`, Python's
    /// `GainIdentification.report`): robot, estimator, reference, gains (joint, name, value,
    /// std), parameters (name, equation, value, std), condition number, residual RMS, rows,
    /// std inflation, logs.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "robot": self.robot,
            "estimator": self.estimator,
            "reference": self.reference,
            "gains": (0..self.gains.len()).map(|k| serde_json::json!({
                "joint": self.joints[k], "name": self.joint_names[k],
                "value": self.gains[k], "std": self.gains_std[k]})).collect::<Vec<_>>(),
            "parameters": self.parameters.iter().enumerate().map(|(k, p)| serde_json::json!({
                "name": p.name, "equation": p.equation,
                "value": self.x[k], "std": self.std[k]})).collect::<Vec<_>>(),
            "condition_number": self.condition_number,
            "residual_rms": self.residual_rms,
            "rows": self.rows,
            "std_inflation": self.std_inflation,
            "logs": self.logs.iter().map(|l| l.source.clone()).collect::<Vec<_>>(),
        })
    }
}

/// Identify the drive gains of `access`'s robot and its parameters from logs of motor
/// `currents` ([`Effort::Current`]; [`Currents`] marks a log in memory) and a `reference`
/// fixing the scale. `opt` as for [`super::identify`], without gains; IDIM-IV is refused.
/// A transmission must be diagonal (each motor drives one joint); the robot must have no
/// external wrench (its torques would not scale with the gains).
pub fn identify_gains(
    access: &mut ModelAccess,
    currents: &[&dyn LogSource],
    reference: &GainReference,
    opt: &Options,
) -> Result<GainIdentification> {
    check_options(access, currents, opt)?;
    let mut model = ParameterModel::build(access, &opt.parameters)?;
    let (n, p) = (model.joints_count(), model.count());
    let u = p + n;
    let ones = Options {
        gains: Some(vec![1.0; n]),
        ..opt.clone()
    };
    let columns = identity_columns(p, u);
    let mut blocks = Vec::new();
    let mut logs = Vec::new();
    let mut add = |log: &dyn LogSource,
                   known: Option<&[f64]>,
                   current: bool,
                   (access, model): (&mut ModelAccess, &mut ParameterModel)|
     -> Result<()> {
        let o = if current { &ones } else { opt };
        let (mut stats, _) = log_statistics(access, model, log, o)?;
        let inflation = stats.logs[0].std_inflation;
        for (k, f) in stats.fit.iter_mut().enumerate() {
            let rows = f.rows();
            let map = BlockMap {
                columns: &columns,
                y_unknown: current.then_some((p + k, -1.0)),
                y_weight: if current { 0.0 } else { 1.0 },
                known,
            };
            blocks.push(map.apply(f.factor(), rows, inflation));
        }
        logs.extend(stats.logs);
        Ok(())
    };
    for log in currents {
        check_effort(*log, Effort::Current)?;
        add(*log, None, true, (access, &mut model))?;
    }
    let described = match reference {
        GainReference::Torques(refs) => {
            if refs.is_empty() {
                return Err(Error::Input(
                    "no reference log of joint torques: the currents fix the gains only up to \
                     a common scale"
                        .into(),
                ));
            }
            for log in refs {
                check_effort(*log, Effort::Torque)?;
                add(*log, None, false, (access, &mut model))?;
            }
            format!("{} log(s) of joint torques", refs.len())
        }
        GainReference::Payload {
            link,
            parameters,
            logs: refs,
        } => {
            let m = payload_columns(access, &model, *link)?;
            let known: Vec<f64> = m
                .iter()
                .map(|row| row.iter().zip(parameters).map(|(a, b)| a * b).sum())
                .collect();
            if refs.is_empty() {
                return Err(Error::Input(
                    "no log with the known payload: the currents fix the gains only up to a \
                     common scale"
                        .into(),
                ));
            }
            for log in refs {
                check_effort(*log, Effort::Current)?;
                add(*log, Some(&known), true, (access, &mut model))?;
            }
            let terms: Vec<String> = PAYLOAD_PARAMETERS
                .iter()
                .zip(parameters)
                .map(|(n, v)| format!("{n} = {v}"))
                .collect();
            format!(
                "{} log(s) of currents with a known payload on link {link} ({})",
                refs.len(),
                terms.join(", ")
            )
        }
    };
    finish(access, &model, &blocks, opt, (described, logs))
}

/// The options and the robot allow gain identification.
fn check_options(access: &ModelAccess, currents: &[&dyn LogSource], opt: &Options) -> Result<()> {
    opt.validate()?;
    if opt.gains.is_some() {
        return Err(Error::Setting {
            option: "identification::Options::gains",
            reason: "the drive gains are the unknowns here: give none".into(),
        });
    }
    if opt.estimator == Estimator::Iv {
        return Err(Error::Setting {
            option: "identification::Options::estimator",
            reason: "IDIM-IV is not available for drive-gain identification: use OLS or WLS".into(),
        });
    }
    if currents.is_empty() {
        return Err(Error::Input(
            "no log of motor currents: give at least one".into(),
        ));
    }
    if let Some(t) = access.transmission() {
        let coupled = t
            .matrix
            .iter()
            .enumerate()
            .any(|(i, row)| row.iter().enumerate().any(|(j, v)| i != j && *v != 0.0));
        if coupled {
            return Err(Error::Input(format!(
                "{}: the transmission couples motors and joints (off-diagonal entries of R): \
                 drive-gain identification needs one motor per joint",
                access.name()
            )));
        }
    }
    let desc = access.description();
    if let Some(j) = desc
        .links
        .iter()
        .position(|l| l.wrench.iter().any(|e| !e.is_zero()))
    {
        return Err(Error::Input(format!(
            "{}: link {} has an external wrench, whose torques do not scale with the drive \
             gains: drive-gain identification needs a robot without external wrenches",
            access.name(),
            j + 1
        )));
    }
    Ok(())
}

fn check_effort(log: &dyn LogSource, expected: Effort) -> Result<()> {
    if log.effort() == expected {
        return Ok(());
    }
    Err(Error::Input(match expected {
        Effort::Current => format!(
            "{}: motor currents (i<j> columns) expected, the log has joint torques",
            log.name()
        ),
        Effort::Torque => format!(
            "{}: joint torques (tau<j> columns) expected for the reference, the log has motor \
             currents",
            log.name()
        ),
    }))
}

/// Solve the stacked equations; every unknown must be determined.
fn finish(
    access: &ModelAccess,
    model: &ParameterModel,
    blocks: &[Block],
    opt: &Options,
    (reference, logs): (String, Vec<ProcessingReport>),
) -> Result<GainIdentification> {
    let (n, p) = (model.joints_count(), model.count());
    let sol = solve(blocks, opt.estimator == Estimator::Wls)?;
    let mut names = model.names();
    names.extend(access.actuated_joints().iter().map(|j| format!("g{j}")));
    if let Some(d) = sol.null_space.first() {
        return Err(Error::Numerical(format!(
            "the drive gains and parameters are not all determined by these logs (rank {} of \
             {}, tolerance {:e} on the unit-column singular values): {} is free; excite the \
             robot more or give a reference that fixes the scale",
            sol.rank,
            p + n,
            super::stacked::IDENTIFIABILITY_TOLERANCE,
            combination(d, &names)
        )));
    }
    Ok(GainIdentification {
        robot: access.name().to_string(),
        joints: access.actuated_joints().to_vec(),
        joint_names: access.joint_names(),
        gains: sol.x[p..].to_vec(),
        gains_std: sol.std[p..].to_vec(),
        parameters: model.params.clone(),
        x: sol.x[..p].to_vec(),
        std: sol.std[..p].to_vec(),
        estimator: match opt.estimator {
            Estimator::Ols => "OLS".into(),
            _ => "WLS".into(),
        },
        condition_number: sol.condition,
        residual_rms: (sol.residual_sq / sol.rows.max(1) as f64).sqrt(),
        rows: sol.rows,
        reference,
        logs,
        std_inflation: sol.inflation,
    })
}
