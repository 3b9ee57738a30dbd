//! The identification report: the table of parameters (name as in the base-parameter report,
//! SI unit, value, standard deviation, relative standard deviation %, grouping equation) with
//! the fit statistics, as text, JSON or CSV; the SVG plot of measured and predicted torques.
//!
//! Numbers follow [`crate::report::number`]: the text report writes the report form (6
//! significant digits for values, 3 for standard deviations and percentages), JSON keeps the
//! full doubles and CSV writes the data form (shortest round-trip).

use super::parameters::Kind;
use super::Identification;
#[cfg(feature = "plot")]
use crate::error::Result;
use crate::model::param;
use crate::report::number::{format_number, Sig};
use serde_json::json;
#[cfg(feature = "plot")]
use std::path::Path;

/// A value of the table: 6 significant digits.
fn value(v: f64) -> Sig {
    Sig(v, 6)
}

/// A standard deviation, a percentage, an error: 3 or 4 significant digits.
fn rough(v: f64) -> Sig {
    Sig(v, 3)
}

/// The SI unit of identified parameter `i`: that of the standard parameter a base parameter
/// is named after (`XXR2`: kg m^2, `MXR2`: kg m, `FV3`: N m s/rad or N s/m by joint 3's type), a
/// motor's drive parameters in motor units (kg m^2, N m, N m s/rad), an offset's N m or N.
pub fn parameter_unit(id: &Identification, i: usize) -> &'static str {
    let prismatic = |j: usize| id.prismatic.get(j - 1).copied().unwrap_or(false);
    match id.parameters[i].kind {
        Kind::Base(r) => {
            let index = id.model.base.base[r];
            param::unit(
                index % STANDARD_COUNT,
                prismatic(index / STANDARD_COUNT + 1),
            )
        }
        Kind::Motor { which, .. } => param::unit(which, false),
        Kind::Joint { joint, which } => param::unit(which, prismatic(id.joints[joint])),
        Kind::Offset(k) => torque_unit(prismatic(id.joints[k])),
    }
}

/// Standard parameters per link.
const STANDARD_COUNT: usize = crate::model::STANDARD_PARAMETERS.len();

/// N for a prismatic joint's force, N m for a revolute joint's torque.
fn torque_unit(prismatic: bool) -> &'static str {
    if prismatic {
        "N"
    } else {
        "N m"
    }
}

/// Plain-text report.
pub fn to_text(id: &Identification) -> String {
    let mut s = processing_text(id);
    s.push_str(&parameter_table(id));
    s.push_str(&joint_table(id));
    if let Some(iv) = &id.iv {
        s.push_str(&format!(
            "\nIDIM-IV: {} iteration(s), {}; last change {} std; simulated motion within {} of \
             the measured one\n",
            iv.iterations,
            if iv.converged {
                "converged"
            } else {
                "NOT converged"
            },
            rough(iv.last_change),
            rough(iv.deviation)
        ));
    }
    if let Some(e) = &id.essential {
        s.push_str(&format!(
            "\nEssential parameters ({} of {}; relative error {} % vs {} % with all):\n",
            e.kept.len(),
            id.x.len(),
            Sig(100.0 * e.relative_error, 4),
            Sig(100.0 * e.full_relative_error, 4)
        ));
        let w = e
            .kept
            .iter()
            .map(|&i| id.parameters[i].name.len())
            .max()
            .unwrap_or(0);
        for (k, &i) in e.kept.iter().enumerate() {
            s.push_str(&format!(
                "  {:<w$}  {:>12} {:<9}  {:>8} %\n",
                id.parameters[i].name,
                value(e.x[k]).to_string(),
                parameter_unit(id, i),
                percent(e.relative_std[k])
            ));
        }
    }
    if let Some(c) = &id.consistent {
        s.push_str(&format!(
            "\nPhysically consistent standard parameters ({}): pseudo-inertia eigenvalues >= {}, \
             inertia matrix eigenvalues >= {} (30 random configurations); the consistent values \
             differ from the unconstrained estimate by at most {} standard deviations (squared \
             Mahalanobis distance {})\n",
            c.solver,
            rough(c.min_pseudo_inertia_eigenvalue),
            rough(c.min_inertia_eigenvalue),
            rough(c.max_deviation),
            rough(c.distance2)
        ));
    }
    for n in &id.notes {
        s.push_str(&format!("\nNote: {n}"));
    }
    if !id.notes.is_empty() {
        s.push('\n');
    }
    for w in &id.warnings {
        s.push_str(&format!("\nWARNING: {w}"));
    }
    if !id.warnings.is_empty() {
        s.push('\n');
    }
    s
}

/// A relative standard deviation in %: 3 significant digits, all the digits of its whole part
/// (`1.48`, `26.3`, `2894`), or `inf` (a parameter estimated as 0).
fn percent(v: f64) -> String {
    if !v.is_finite() {
        "inf".into()
    } else {
        let whole = if v.abs() >= 1.0 {
            v.abs().log10().floor() as usize + 1
        } else {
            0
        };
        Sig(v, whole.max(3)).to_string()
    }
}

/// The title, the log and its processing, the fit's condition number and error.
fn processing_text(id: &Identification) -> String {
    let pr = &id.processing;
    let hz = |f: f64| Sig(f, 6);
    let mut s = format!(
        "{}: {} parameters identified ({}) from {}\n\n",
        id.robot,
        id.x.len(),
        id.estimator,
        pr.source
    );
    s.push_str(&format!(
        "Log: {} samples at {} Hz ({} s)\n",
        pr.samples,
        hz(pr.sample_rate),
        Sig(pr.duration, 6)
    ));
    if pr.derivatives_from_log {
        s.push_str(
            "Velocities and accelerations: the log's qd, qdd columns (not differentiated)\n",
        );
    }
    if let Some((o, fc)) = pr.lowpass {
        s.push_str(&format!(
            "Positions: zero-phase Butterworth low-pass, order {o} forward and backward, cut-off \
             {} Hz (default 10 x bandwidth {} Hz, at most 0.4 x sample rate); qd, qdd by \
             central differences\n",
            hz(fc),
            hz(pr.bandwidth)
        ));
    }
    match pr.decimation_filter {
        Some((o, fd)) => s.push_str(&format!(
            "Parallel decimation of W and Y: Butterworth order {o}, cut-off {} Hz (0.8 x the new \
             Nyquist frequency), then 1 sample in {} (default: the low-pass at twice the \
             position cut-off, or at 10 x bandwidth without it)\n",
            hz(fd),
            pr.decimation
        )),
        None => s.push_str("No decimation\n"),
    }
    if pr.std_inflation != 1.0 {
        s.push_str(&format!(
            "Standard deviations: the decimated residuals are correlated by the decimation \
             low-pass; the covariance is multiplied by its noise gain {:.3} (exact for white \
             torque noise at the log's rate)\n",
            pr.std_inflation
        ));
    }
    s.push_str(&format!(
        "Border: {} samples dropped at each end; decimation transient: {} samples\n",
        pr.border, pr.decimation_skip
    ));
    if pr.coulomb_band > 0.0 {
        s.push_str(&format!(
            "Coulomb friction: sign(qd) with a dead band, 0 where |qd| <= {} (rad/s or m/s)\n",
            Sig(pr.coulomb_band, 6)
        ));
    }
    match pr.validation {
        Some((a, b)) => s.push_str(&format!(
            "Fit: {} decimated samples outside [{}, {}) s; validation: {} samples in it\n",
            pr.fit_samples,
            Sig(a, 6),
            Sig(b, 6),
            pr.validation_samples
        )),
        None => s.push_str(&format!(
            "Fit: {} decimated samples (no validation segment)\n",
            pr.fit_samples
        )),
    }
    s.push_str(&format!(
        "Condition number of W (unit columns): {} (as given: {})\n",
        Sig(id.condition_number, 4),
        Sig(id.condition_number_unscaled, 4)
    ));
    s.push_str(&format!(
        "Relative error ||Y - W X|| / ||Y||: {} % (fit)",
        Sig(100.0 * id.relative_error, 4)
    ));
    if let Some(v) = &id.validation {
        s.push_str(&format!(
            ", {} % (validation; {} % on its raw torques at the log's rate)",
            Sig(100.0 * v.relative_error, 4),
            Sig(100.0 * v.raw_relative_error, 4)
        ));
    }
    s.push_str("\n\n");
    s
}

/// The parameter table: name, unit, value, std, rel.std %, equation.
fn parameter_table(id: &Identification) -> String {
    let rows: Vec<[String; 6]> = id
        .parameters
        .iter()
        .enumerate()
        .map(|(i, p)| {
            [
                p.name.clone(),
                parameter_unit(id, i).to_string(),
                value(id.x[i]).to_string(),
                rough(id.std[i]).to_string(),
                percent(id.relative_std[i]),
                p.equation.clone(),
            ]
        })
        .collect();
    let head = ["parameter", "unit", "value", "std", "rel.std %", "equation"].map(String::from);
    let w: Vec<usize> = (0..5)
        .map(|c| {
            rows.iter()
                .chain([&head])
                .map(|r| r[c].len())
                .max()
                .unwrap_or(1)
        })
        .collect();
    let mut s = String::new();
    for r in std::iter::once(&head).chain(&rows) {
        s.push_str(&format!(
            "{:<w0$}  {:<w1$}  {:>w2$}  {:>w3$}  {:>w4$}  {}\n",
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            r[5],
            w0 = w[0],
            w1 = w[1],
            w2 = w[2],
            w3 = w[3],
            w4 = w[4]
        ));
    }
    s
}

/// The per-joint fit: rows, RMS error, relative error, WLS sigma (validation error).
fn joint_table(id: &Identification) -> String {
    let mut s = String::from("\nPer joint (RMS and sigma in the joint's unit):\n");
    s.push_str(&format!(
        "  {:<6} {:<12} {:<4} {:>7} {:>10} {:>10} {:>12}{}\n",
        "joint",
        "name",
        "unit",
        "rows",
        "RMS",
        "rel.err %",
        "sigma (WLS)",
        if id.validation.is_some() {
            "  valid. rel.err %"
        } else {
            ""
        }
    ));
    for (k, f) in id.per_joint.iter().enumerate() {
        let v = id
            .validation
            .as_ref()
            .map(|v| {
                format!(
                    "  {:>17}",
                    Sig(100.0 * v.per_joint[k].relative_error, 4).to_string()
                )
            })
            .unwrap_or_default();
        let prismatic = id.prismatic.get(f.joint - 1).copied().unwrap_or(false);
        s.push_str(&format!(
            "  {:<6} {:<12} {:<4} {:>7} {:>10} {:>10} {:>12}{v}\n",
            f.joint,
            f.name,
            torque_unit(prismatic),
            f.rows,
            Sig(f.rms, 4).to_string(),
            Sig(100.0 * f.relative_error, 4).to_string(),
            f.sigma
                .map(|x| Sig(x, 4).to_string())
                .unwrap_or_else(|| "-".into()),
        ));
    }
    s
}

fn finite(v: f64) -> serde_json::Value {
    if v.is_finite() {
        json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// JSON report: `parameters[{name, unit, value, relative_std, std, equation}]`, `condition_number`,
/// `relative_error` and `per_joint[{joint, rms, relative_error}]`, with the processing, the
/// validation, the essential parameters, IDIM-IV and the consistent parameters when computed.
pub fn to_json(id: &Identification) -> serde_json::Value {
    let pr = &id.processing;
    let joints = |v: &[super::JointFit]| -> Vec<serde_json::Value> {
        v.iter()
            .map(|f| {
                json!({
                    "joint": f.joint,
                    "name": f.name,
                    "rows": f.rows,
                    "rms": f.rms,
                    "relative_error": f.relative_error,
                    "sigma": f.sigma,
                })
            })
            .collect()
    };
    let mut o = json!({
        "robot": id.robot,
        "estimator": id.estimator,
        "parameters": id.parameters.iter().enumerate().map(|(i, p)| json!({
            "name": p.name,
            "unit": parameter_unit(id, i),
            "equation": p.equation,
            "value": id.x[i],
            "std": id.std[i],
            "relative_std": finite(id.relative_std[i]),
        })).collect::<Vec<_>>(),
        "condition_number": id.condition_number,
        "condition_number_unscaled": id.condition_number_unscaled,
        "relative_error": id.relative_error,
        "per_joint": joints(&id.per_joint),
        "processing": {
            "source": pr.source,
            "samples": pr.samples,
            "sample_rate": pr.sample_rate,
            "duration": pr.duration,
            "bandwidth": pr.bandwidth,
            "derivatives_from_log": pr.derivatives_from_log,
            "lowpass": pr.lowpass.map(|(o, f)| json!({"order": o, "cutoff": f})),
            "decimation": pr.decimation,
            "decimation_filter": pr.decimation_filter.map(|(o, f)| json!({"order": o, "cutoff": f})),
            "border": pr.border,
            "decimation_skip": pr.decimation_skip,
            "std_inflation": pr.std_inflation,
            "min_speed": pr.min_speed,
            "coulomb_band": pr.coulomb_band,
            "fit_samples": pr.fit_samples,
            "validation_samples": pr.validation_samples,
        },
        "warnings": id.warnings.iter().map(|w| json!({
            "kind": w.kind.as_str(),
            "parameters": w.parameters,
            "message": w.message,
        })).collect::<Vec<_>>(),
        "notes": id.notes,
    });
    if let Some(v) = &id.validation {
        o["validation"] = json!({
            "from": v.from,
            "to": v.to,
            "relative_error": v.relative_error,
            "per_joint": joints(&v.per_joint),
            "raw": {
                "relative_error": v.raw_relative_error,
                "per_joint": joints(&v.raw_per_joint),
            },
        });
    }
    if let Some(e) = &id.essential {
        o["essential"] = json!({
            "parameters": e.kept.iter().enumerate().map(|(k, &i)| json!({
                "name": id.parameters[i].name,
                "value": e.x[k],
                "relative_std": finite(e.relative_std[k]),
            })).collect::<Vec<_>>(),
            "relative_error": e.relative_error,
            "full_relative_error": e.full_relative_error,
        });
    }
    if let Some(iv) = &id.iv {
        o["iv"] = json!({
            "iterations": iv.iterations,
            "converged": iv.converged,
            "last_change": finite(iv.last_change),
            "deviation": iv.deviation,
            "wls": iv.wls,
        });
    }
    if let Some(c) = &id.consistent {
        o["consistent"] = json!({
            "solver": c.solver,
            "standard": c.standard,
            "values": c.x,
            "deviation": c.deviation,
            "max_deviation": c.max_deviation,
            "mahalanobis_distance2": c.distance2,
            "min_pseudo_inertia_eigenvalue": c.min_pseudo_inertia_eigenvalue,
            "min_inertia_eigenvalue": c.min_inertia_eigenvalue,
        });
    }
    o
}

/// CSV table: name, value, std, relative_std (%), equation, unit; numbers in the data form
/// (shortest round-trip), `inf` for the relative standard deviation of a zero estimate.
pub fn to_csv(id: &Identification) -> String {
    let mut s = String::from("name,value,std,relative_std,equation,unit\n");
    for (i, p) in id.parameters.iter().enumerate() {
        s.push_str(&format!(
            "{},{},{},{},\"{}\",{}\n",
            p.name,
            format_number(id.x[i]),
            format_number(id.std[i]),
            format_number(id.relative_std[i]),
            p.equation.replace('"', "'"),
            parameter_unit(id, i)
        ));
    }
    s
}

/// Measured and predicted torques of the validation segment, one panel per joint in its unit
/// (the torques after the parallel decimation filter, as fitted): measured solid, predicted
/// dashed, the panel's title with the joint's validation error.
#[cfg(feature = "plot")]
pub fn plot_fit(path: &Path, id: &Identification) -> Result<()> {
    use crate::error::Error;
    use crate::report::figure::{write_svg, Curve, Figure, Panel, Style};
    let rows = &id.validation_rows;
    if rows.t.len() < 2 {
        return Err(Error::Setting {
            option: "identification::Options::validation",
            reason:
                "no validation rows to plot: the plot shows the validation segment of the log, \
                     and none was given"
                    .into(),
        });
    }
    let pred = id.predicted_validation();
    let v = id.validation.as_ref();
    let panels = id
        .joints
        .iter()
        .enumerate()
        .map(|(k, &j)| {
            let err = v
                .map(|v| {
                    format!(
                        ", validation error {} %",
                        Sig(100.0 * v.per_joint[k].relative_error, 3)
                    )
                })
                .unwrap_or_default();
            let prismatic = id.prismatic.get(j - 1).copied().unwrap_or(false);
            Panel {
                title: format!("joint {j} ({}){err}", id.joint_names[k]),
                y_label: format!("tau{j} [{}]", torque_unit(prismatic)),
                curves: vec![
                    Curve::new(
                        "measured",
                        rows.y.iter().map(|y| y[k]).collect(),
                        0,
                        Style::Solid,
                    ),
                    Curve::new(
                        "predicted",
                        pred.iter().map(|y| y[k]).collect(),
                        1,
                        Style::Dashed,
                    ),
                ],
                ..Panel::default()
            }
        })
        .collect();
    let fig = Figure {
        title: format!(
            "{}: measured and predicted joint torques on the validation segment ({})",
            id.robot, id.estimator
        ),
        x_label: "t [s]".into(),
        panels,
        colors: 2,
        ..Figure::default()
    };
    write_svg(path, &rows.t, &fig)
}
