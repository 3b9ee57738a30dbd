//! Payload identification: the 10 standard inertial parameters of a load fixed on a link (XX,
//! XY, XZ, YY, YZ, ZZ about the link's origin O_L in its frame R_L, MX, MY, MZ, M), from logs of
//! the robot carrying it (Khalil & Dombre §12.6).
//!
//! A payload adds phi to link L's standard parameters, so it changes the base parameters by
//! M_L phi, M_L the columns of L's parameters in the base-parameter map (x = map K): the
//! torques become W (X + M_L phi). Two forms:
//!
//! - the robot known (a robot file, e.g. as identified): W M_L phi = tau - W X_robot, the
//!   unknowns phi (and the torque offsets when they are identified);
//! - before/after: logs without the payload (W X = tau) and with it (W (X + M_L phi) = tau),
//!   identified together, the unknowns X and phi.
//!
//! What is identifiable: only M_L phi reaches the torques, so the combinations of phi in the
//! null space of M_L never do (structural: e.g. on the first link of a vertical axis only ZZ);
//! the logs' motion may leave more undetermined. Both are found by the rank of a singular value
//! decomposition with unit-norm columns, tolerance [`IDENTIFIABILITY_TOLERANCE`]; a parameter is
//! reported (value and standard deviation) only when it is determined on its own, and the free
//! combinations are named.

use super::data::LogSource;
use super::model_access::ModelAccess;
use super::parameters::{Kind, ParameterModel};
use super::stacked::{
    combination, solve, Block, BlockMap, StackedSolution, IDENTIFIABILITY_TOLERANCE,
};
use super::{log_statistics, Estimator, Options, ProcessingReport};
use crate::algorithms::regressor::PARAMS_PER_LINK;
use crate::error::{Error, Result};
use faer::Mat;

pub use super::stacked::IDENTIFIABILITY_TOLERANCE as RANK_TOLERANCE;

/// Names of the payload's parameters, in order (about O_L, in R_L).
pub const PAYLOAD_PARAMETERS: [&str; 10] =
    ["XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"];

/// The payload's standard parameters of a rigid body of mass `m` whose centre of mass is at
/// `c` in R_L and whose inertia about its centre of mass, in R_L's axes, is `i_c` (symmetric):
/// J = I_c + m (|c|² 1 - c c^T) about O_L (Huygens–Steiner), first moments m c.
pub fn rigid_body(m: f64, c: [f64; 3], i_c: [[f64; 3]; 3]) -> [f64; 10] {
    let c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    let j = |a: usize, b: usize| {
        let d = if a == b { c2 } else { 0.0 };
        i_c[a][b] + m * (d - c[a] * c[b])
    };
    [
        j(0, 0),
        j(0, 1),
        j(0, 2),
        j(1, 1),
        j(1, 2),
        j(2, 2),
        m * c[0],
        m * c[1],
        m * c[2],
        m,
    ]
}

/// M_L: the change of the identified parameters x per unit of each of link `link`'s 10
/// standard inertial parameters (p rows of 10; offsets rows zero).
pub fn payload_columns(
    access: &ModelAccess,
    model: &ParameterModel,
    link: usize,
) -> Result<Vec<Vec<f64>>> {
    if link == 0 || link > access.nl() {
        return Err(Error::Input(format!(
            "{}: no link {link} to carry a payload (links 1 to {})",
            access.name(),
            access.nl()
        )));
    }
    let first = PARAMS_PER_LINK * (link - 1);
    let m: Vec<Vec<f64>> = model
        .map
        .iter()
        .map(|terms| {
            let mut row = vec![0.0; 10];
            for &(i, c) in terms {
                if (first..first + 10).contains(&i) {
                    row[i - first] += c;
                }
            }
            row
        })
        .collect();
    if m.iter().all(|r| r.iter().all(|v| *v == 0.0)) {
        return Err(Error::Input(format!(
            "{}: a payload on link {link} changes none of the identified parameters (the link \
             does not move or carries no dynamics): nothing to identify",
            access.name()
        )));
    }
    Ok(m)
}

/// The logs of a payload identification.
pub enum PayloadLogs<'a> {
    /// The robot's parameters are known (those of the robot file): logs with the payload.
    Known(Vec<&'a dyn LogSource>),
    /// Logs without the payload and logs with it, identified together with the robot's
    /// parameters.
    BeforeAfter {
        /// Without the payload.
        before: Vec<&'a dyn LogSource>,
        /// With it.
        after: Vec<&'a dyn LogSource>,
    },
}

/// One estimated quantity: None where the data do not determine it on its own.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// Its name.
    pub name: String,
    /// Its value.
    pub value: Option<f64>,
    /// Its standard deviation.
    pub std: Option<f64>,
}

/// The identified payload.
#[derive(Clone, Debug)]
pub struct PayloadIdentification {
    /// Robot name.
    pub robot: String,
    /// Frame number of the link carrying the payload.
    pub link: usize,
    /// The payload's parameters in [`PAYLOAD_PARAMETERS`] order (about O_link, in R_link).
    pub payload: Vec<Estimate>,
    /// Rank of M_L (how many combinations of the payload's parameters change the dynamics at
    /// all), of 10.
    pub structural_rank: usize,
    /// The combinations that never change the torques (the null space of M_L), in words.
    pub structural_null: Vec<String>,
    /// Rank of the payload's part given these logs (of 10).
    pub rank: usize,
    /// The combinations these logs do not determine (the structural ones included), in words.
    pub undetermined: Vec<String>,
    /// Relative singular-value tolerance of the rank tests.
    pub tolerance: f64,
    /// The other unknowns: the torque offsets (robot known), or the robot's parameters
    /// (before/after).
    pub others: Vec<Estimate>,
    /// `OLS` or `WLS`.
    pub estimator: String,
    /// Condition number of the determined directions (unit-norm columns).
    pub condition_number: f64,
    /// ||tau - predicted|| / ||tau|| over the fit rows of every log (robot known: of the
    /// torques less the robot's model, i.e. the payload's share).
    pub relative_error: f64,
    /// Rows used.
    pub rows: usize,
    /// The processing of each log (before, then after).
    pub logs: Vec<ProcessingReport>,
}

impl PayloadIdentification {
    /// The report as JSON (`robodyn identify --payload LINK --format json`, Python's
    /// `PayloadIdentification.report`): robot, link, estimator, payload and others (name,
    /// value, std; null where not determined), ranks, the combinations not determined,
    /// tolerance, condition number, relative error, rows, logs.
    pub fn to_json(&self) -> serde_json::Value {
        let est = |v: &[Estimate]| -> Vec<serde_json::Value> {
            v.iter()
                .map(|e| serde_json::json!({"name": e.name, "value": e.value, "std": e.std}))
                .collect()
        };
        serde_json::json!({
            "robot": self.robot,
            "link": self.link,
            "estimator": self.estimator,
            "payload": est(&self.payload),
            "structural_rank": self.structural_rank,
            "structural_null": self.structural_null,
            "rank": self.rank,
            "undetermined": self.undetermined,
            "tolerance": self.tolerance,
            "others": est(&self.others),
            "condition_number": self.condition_number,
            "relative_error": self.relative_error,
            "rows": self.rows,
            "logs": self.logs.iter().map(|l| l.source.clone()).collect::<Vec<_>>(),
        })
    }
}

/// Identify the payload on link `link` of `access`'s robot (see the module documentation).
/// `opt` as for [`super::identify`] (IDIM-IV refused).
pub fn identify_payload(
    access: &mut ModelAccess,
    link: usize,
    logs: &PayloadLogs,
    opt: &Options,
) -> Result<PayloadIdentification> {
    opt.validate()?;
    if opt.estimator == Estimator::Iv {
        return Err(Error::Setting {
            option: "identification::Options::estimator",
            reason: "IDIM-IV is not available for payload identification: use OLS or WLS".into(),
        });
    }
    let mut model = ParameterModel::build(access, &opt.parameters)?;
    let m = payload_columns(access, &model, link)?;
    let p = model.count();
    let (before, after, known) = match logs {
        PayloadLogs::Known(after) => (&[][..], &after[..], true),
        PayloadLogs::BeforeAfter { before, after } => (&before[..], &after[..], false),
    };
    if after.is_empty() || (!known && before.is_empty()) {
        return Err(Error::Input(
            "payload identification needs logs with the payload (and, without the robot's \
             parameters, logs without it)"
                .into(),
        ));
    }
    // the unknowns: robot known, phi then the offsets; before/after, x then phi
    let offsets: Vec<usize> = (0..p)
        .filter(|&c| matches!(model.params[c].kind, Kind::Offset(_)))
        .collect();
    let (u, phi_at) = if known {
        (10 + offsets.len(), 0)
    } else {
        (p + 10, p)
    };
    let x_known: Vec<f64> = model.values(&access.standard_parameters());
    let mut with = vec![vec![0.0; u]; p];
    let mut without = vec![vec![0.0; u]; p];
    for c in 0..p {
        with[c][phi_at..phi_at + 10].copy_from_slice(&m[c]);
        if !known {
            with[c][c] = 1.0;
            without[c][c] = 1.0;
        }
    }
    for (k, &c) in offsets.iter().enumerate() {
        if known {
            with[c][10 + k] = 1.0;
        }
    }
    let mut blocks = Vec::new();
    let mut reports = Vec::new();
    for (group, columns) in [(before, &without), (after, &with)] {
        for log in group {
            let map = BlockMap {
                columns,
                y_unknown: None,
                y_weight: 1.0,
                known: known.then_some(&x_known[..]),
            };
            let (mut stats, _) = log_statistics(access, &mut model, *log, opt)?;
            let inflation = stats.logs[0].std_inflation;
            for f in stats.fit.iter_mut() {
                let rows = f.rows();
                blocks.push(map.apply(f.factor(), rows, inflation));
            }
            reports.extend(stats.logs);
        }
    }
    let sol = solve(&blocks, opt.estimator == Estimator::Wls)?;
    let structural = structural_rank(&m)?;
    Ok(report(
        access,
        (link, &model, &offsets, known),
        &sol,
        structural,
        (opt, reports),
    ))
}

/// The rank and null space of M_L (unit-norm columns).
fn structural_rank(m: &[Vec<f64>]) -> Result<StackedSolution> {
    let p = m.len();
    let matrix = Mat::from_fn(p, 11, |r, c| if c < 10 { m[r][c] } else { 0.0 });
    solve(
        &[Block {
            matrix,
            rows: p.max(11),
            inflation: 1.0,
        }],
        false,
    )
}

fn report(
    access: &ModelAccess,
    (link, model, offsets, known): (usize, &ParameterModel, &[usize], bool),
    sol: &StackedSolution,
    structural: StackedSolution,
    (opt, logs): (&Options, Vec<ProcessingReport>),
) -> PayloadIdentification {
    let phi_at = if known { 0 } else { model.count() };
    let estimate = |k: usize, name: String| Estimate {
        name,
        value: sol.identifiable[k].then(|| sol.x[k]),
        std: sol.identifiable[k].then(|| sol.std[k]),
    };
    let payload = (0..10)
        .map(|i| estimate(phi_at + i, PAYLOAD_PARAMETERS[i].to_string()))
        .collect();
    let others = if known {
        offsets
            .iter()
            .enumerate()
            .map(|(k, &c)| estimate(10 + k, model.params[c].name.clone()))
            .collect()
    } else {
        (0..model.count())
            .map(|c| estimate(c, model.params[c].name.clone()))
            .collect()
    };
    let names: Vec<String> = PAYLOAD_PARAMETERS.iter().map(|s| s.to_string()).collect();
    let structural_null: Vec<String> = structural
        .null_space
        .iter()
        .map(|d| combination(d, &names))
        .collect();
    // the payload's part of the data's null space, beyond the structural one
    let mut all_names: Vec<String> = Vec::new();
    for k in 0..sol.x.len() {
        if (phi_at..phi_at + 10).contains(&k) {
            all_names.push(PAYLOAD_PARAMETERS[k - phi_at].to_string());
        } else if known {
            all_names.push(model.params[offsets[k - 10]].name.clone());
        } else {
            all_names.push(model.params[k].name.clone());
        }
    }
    let undetermined: Vec<String> = sol
        .null_space
        .iter()
        .filter(|d| d[phi_at..phi_at + 10].iter().any(|v| v.abs() > 1e-6))
        .map(|d| combination(d, &all_names))
        .collect();
    let payload_null = sol
        .null_space
        .iter()
        .filter(|d| d[phi_at..phi_at + 10].iter().any(|v| v.abs() > 1e-6))
        .count();
    PayloadIdentification {
        robot: access.name().to_string(),
        link,
        payload,
        structural_rank: structural.rank,
        structural_null,
        rank: 10 - payload_null.min(10),
        undetermined,
        tolerance: IDENTIFIABILITY_TOLERANCE,
        others,
        estimator: match opt.estimator {
            Estimator::Ols => "OLS".into(),
            _ => "WLS".into(),
        },
        condition_number: sol.condition,
        relative_error: sol.relative_error,
        rows: sol.rows,
        logs,
    }
}
