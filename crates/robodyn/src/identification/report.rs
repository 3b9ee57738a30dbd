//! The identification report: the table of parameters (name as in the base-parameter report,
//! grouping equation, value, standard deviation, relative standard deviation %) with the fit
//! statistics, as text, JSON or CSV; SVG plots of measured and predicted torques.

use super::Identification;
use crate::error::{Error, Result};
use serde_json::json;
use std::path::Path;

fn fmt_num(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e-3 && v.abs() < 1e5 {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

fn fmt_pct(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.2}")
    } else {
        "inf".into()
    }
}

/// Plain-text report.
pub fn to_text(id: &Identification) -> String {
    let mut s = String::new();
    let pr = &id.processing;
    s.push_str(&format!(
        "{}: {} parameters identified ({}) from {}\n\n",
        id.robot,
        id.x.len(),
        id.estimator,
        pr.source
    ));
    s.push_str(&format!(
        "Log: {} samples at {:.6} Hz ({:.4} s)\n",
        pr.samples, pr.sample_rate, pr.duration
    ));
    if pr.derivatives_from_log {
        s.push_str(
            "Velocities and accelerations: the log's qd, qdd columns (not differentiated)\n",
        );
    }
    if let Some((o, fc)) = pr.lowpass {
        s.push_str(&format!(
            "Positions: zero-phase Butterworth low-pass, order {o} forward and backward, cut-off \
             {fc:.4} Hz (default 10 x bandwidth {:.4} Hz, at most 0.4 x sample rate); qd, qdd by \
             central differences\n",
            pr.bandwidth
        ));
    }
    match pr.decimation_filter {
        Some((o, fd)) => s.push_str(&format!(
            "Parallel decimation of W and Y: Butterworth order {o}, cut-off {fd:.4} Hz (0.8 x the \
             new Nyquist frequency), then 1 sample in {} (default floor(0.8 fs / (4 x \
             bandwidth)))\n",
            pr.decimation
        )),
        None => s.push_str("No decimation\n"),
    }
    s.push_str(&format!(
        "Border: {} samples dropped at each end; decimation transient: {} samples\n",
        pr.border, pr.decimation_skip
    ));
    if pr.coulomb_band > 0.0 {
        s.push_str(&format!(
            "Coulomb friction: sign(qd) with a dead band, 0 where |qd| <= {} (rad/s or m/s)\n",
            pr.coulomb_band
        ));
    }
    match pr.validation {
        Some((a, b)) => s.push_str(&format!(
            "Fit: {} decimated samples outside [{a:.4}, {b:.4}) s; validation: {} samples in it\n",
            pr.fit_samples, pr.validation_samples
        )),
        None => s.push_str(&format!(
            "Fit: {} decimated samples (no validation segment)\n",
            pr.fit_samples
        )),
    }
    s.push_str(&format!(
        "Condition number of W (unit columns): {:.4e} (as given: {:.4e})\n",
        id.condition_number, id.condition_number_unscaled
    ));
    s.push_str(&format!(
        "Relative error ||Y - W X|| / ||Y||: {:.4} % (fit)",
        100.0 * id.relative_error
    ));
    if let Some(v) = &id.validation {
        s.push_str(&format!(
            ", {:.4} % (validation; {:.4} % on its raw torques at the log's rate)",
            100.0 * v.relative_error,
            100.0 * v.raw_relative_error
        ));
    }
    s.push_str("\n\n");
    let rows: Vec<[String; 5]> = id
        .parameters
        .iter()
        .enumerate()
        .map(|(i, p)| {
            [
                p.name.clone(),
                fmt_num(id.x[i]),
                fmt_num(id.std[i]),
                fmt_pct(id.relative_std[i]),
                p.equation.clone(),
            ]
        })
        .collect();
    let head = ["parameter", "value", "std", "rel.std %", "equation"];
    let w: Vec<usize> = (0..4)
        .map(|c| {
            rows.iter()
                .map(|r| r[c].len())
                .chain([head[c].len()])
                .max()
                .unwrap_or(1)
        })
        .collect();
    let line = |r: [&str; 5]| {
        format!(
            "{:<w0$}  {:>w1$}  {:>w2$}  {:>w3$}  {}\n",
            r[0],
            r[1],
            r[2],
            r[3],
            r[4],
            w0 = w[0],
            w1 = w[1],
            w2 = w[2],
            w3 = w[3]
        )
    };
    s.push_str(&line(head));
    for r in &rows {
        s.push_str(&line([&r[0], &r[1], &r[2], &r[3], &r[4]]));
    }
    s.push_str("\nPer joint:\n");
    s.push_str(&format!(
        "  {:<6} {:<12} {:>7} {:>12} {:>10} {:>12}{}\n",
        "joint",
        "name",
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
            .map(|v| format!("  {:>17.4}", 100.0 * v.per_joint[k].relative_error))
            .unwrap_or_default();
        s.push_str(&format!(
            "  {:<6} {:<12} {:>7} {:>12.5e} {:>10.4} {:>12}{v}\n",
            f.joint,
            f.name,
            f.rows,
            f.rms,
            100.0 * f.relative_error,
            f.sigma
                .map(|x| format!("{x:.5e}"))
                .unwrap_or_else(|| "-".into()),
        ));
    }
    if let Some(iv) = &id.iv {
        s.push_str(&format!(
            "\nIDIM-IV: {} iteration(s), {}; last change {:.3e} std; simulated motion within \
             {:.3e} of the measured one\n",
            iv.iterations,
            if iv.converged {
                "converged"
            } else {
                "NOT converged"
            },
            iv.last_change,
            iv.deviation
        ));
    }
    if let Some(e) = &id.essential {
        s.push_str(&format!(
            "\nEssential parameters ({} of {}; relative error {:.4} % vs {:.4} % with all):\n",
            e.kept.len(),
            id.x.len(),
            100.0 * e.relative_error,
            100.0 * e.full_relative_error
        ));
        for (k, &i) in e.kept.iter().enumerate() {
            s.push_str(&format!(
                "  {:<10} {:>14}  {:>8} %\n",
                id.parameters[i].name,
                fmt_num(e.x[k]),
                fmt_pct(e.relative_std[k])
            ));
        }
    }
    if let Some(c) = &id.consistent {
        s.push_str(&format!(
            "\nPhysically consistent standard parameters ({}): pseudo-inertia eigenvalues >= \
             {:.3e}, inertia matrix eigenvalues >= {:.3e} (30 random configurations); the \
             consistent values differ from the unconstrained estimate by at most {:.3} standard \
             deviations (squared Mahalanobis distance {:.3})\n",
            c.solver,
            c.min_pseudo_inertia_eigenvalue,
            c.min_inertia_eigenvalue,
            c.max_deviation,
            c.distance2
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

fn finite(v: f64) -> serde_json::Value {
    if v.is_finite() {
        json!(v)
    } else {
        serde_json::Value::Null
    }
}

/// JSON report: `parameters[{name, value, relative_std, std, equation}]`, `condition_number`,
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

/// CSV table: name, value, std, relative_std, equation.
pub fn to_csv(id: &Identification) -> String {
    let mut s = String::from("name,value,std,relative_std,equation\n");
    for (i, p) in id.parameters.iter().enumerate() {
        s.push_str(&format!(
            "{},{:.12e},{:.6e},{},\"{}\"\n",
            p.name,
            id.x[i],
            id.std[i],
            if id.relative_std[i].is_finite() {
                format!("{:.6e}", id.relative_std[i])
            } else {
                "inf".into()
            },
            p.equation.replace('"', "'")
        ));
    }
    s
}

/// A panel: its title and its curves (label, values).
pub type Panel = (String, Vec<(String, Vec<f64>)>);

/// One panel per joint: curves (label, values) against t.
pub fn plot_panels(
    path: &Path,
    title: &str,
    t: &[f64],
    panels: &[Panel],
    y_label: &str,
    bold_first: bool,
) -> Result<()> {
    use plotters::prelude::*;
    let err = |e: String| Error::io(path.display().to_string(), std::io::Error::other(e));
    if t.len() < 2 {
        return Err(err("fewer than two samples to plot".into()));
    }
    let ds = |e: &dyn std::fmt::Display| err(e.to_string());
    let height = 60 + 220 * panels.len() as u32;
    let root = SVGBackend::new(path, (1100, height)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| ds(&e))?;
    let root = root.titled(title, ("sans-serif", 22)).map_err(|e| ds(&e))?;
    let areas = root.split_evenly((panels.len(), 1));
    let colors = [
        RGBColor(20, 20, 20),
        RGBColor(220, 50, 40),
        RGBColor(40, 90, 200),
        RGBColor(30, 150, 60),
        RGBColor(230, 140, 0),
        RGBColor(150, 60, 170),
        RGBColor(0, 160, 170),
        RGBColor(140, 100, 60),
    ];
    let (t0, t1) = (t[0], *t.last().unwrap());
    for (area, (name, curves)) in areas.iter().zip(panels) {
        let (lo, hi) = curves
            .iter()
            .flat_map(|(_, v)| v.iter().copied())
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let (lo, hi) = if !lo.is_finite() {
            (-1.0, 1.0)
        } else if hi - lo < 1e-12 * (1.0 + lo.abs()) {
            (lo - 1.0, hi + 1.0)
        } else {
            let m = 0.05 * (hi - lo);
            (lo - m, hi + m)
        };
        let mut chart = ChartBuilder::on(area)
            .caption(name.as_str(), ("sans-serif", 16))
            .margin(8)
            .x_label_area_size(30)
            .y_label_area_size(70)
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(|e| ds(&e))?;
        chart
            .configure_mesh()
            .x_desc("t [s]")
            .y_desc(y_label)
            .draw()
            .map_err(|e| ds(&e))?;
        for (k, (label, v)) in curves.iter().enumerate() {
            let color = colors[k % colors.len()];
            chart
                .draw_series(LineSeries::new(
                    t.iter().copied().zip(v.iter().copied()),
                    color.stroke_width(if bold_first && k == 0 { 2 } else { 1 }),
                ))
                .map_err(|e| ds(&e))?
                .label(label.as_str())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color));
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| ds(&e))?;
    }
    root.present().map_err(|e| ds(&e))?;
    Ok(())
}

/// Measured and predicted torques of the validation segment, one panel per joint (the torques
/// after the parallel decimation filter, as fitted).
pub fn plot_fit(path: &Path, id: &Identification) -> Result<()> {
    let rows = &id.validation_rows;
    if rows.t.len() < 2 {
        return Err(Error::Input(
            "no validation rows to plot: give a validation segment (--validation FROM:TO) and \
             --plot"
                .into(),
        ));
    }
    let pred = id.predicted_validation();
    let v = id.validation.as_ref();
    let panels: Vec<Panel> = id
        .joints
        .iter()
        .enumerate()
        .map(|(k, j)| {
            let err = v
                .map(|v| {
                    format!(
                        " (relative error {:.2} %)",
                        100.0 * v.per_joint[k].relative_error
                    )
                })
                .unwrap_or_default();
            (
                format!("joint {j} ({}){err}", id.joint_names[k]),
                vec![
                    (
                        "measured".to_string(),
                        rows.y.iter().map(|y| y[k]).collect(),
                    ),
                    ("predicted".to_string(), pred.iter().map(|y| y[k]).collect()),
                ],
            )
        })
        .collect();
    plot_panels(
        path,
        &format!(
            "{}: measured and predicted torques on the validation segment ({})",
            id.robot, id.estimator
        ),
        &rows.t,
        &panels,
        "torque [N m] / force [N]",
        true,
    )
}
