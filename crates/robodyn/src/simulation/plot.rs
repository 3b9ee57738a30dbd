//! The figure of a simulated trajectory ([`plot_svg`]): the joint positions (revolute and
//! prismatic joints in panels of their own units; a closed chain's passive joints dotted; a
//! tracked reference dashed in its joint's colour), the tracking error q_ref - q when a
//! reference was tracked, and the energy balance E - E(0), captioned by what it measures in
//! this run. Drawn by [`crate::report::figure`].

use super::input::TimeSeries;
use super::output::Recorder;
use crate::error::{Error, Result};
use crate::report::figure::{write_svg, Curve, Figure, Panel, Style};
use crate::report::number::{format_number, Sig};
use std::path::Path;

/// What E - E(0) of a run measures (the caption of the energy panel).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EnergyBalance {
    /// No joint torque and no friction: E is conserved, so E - E(0) is the integration drift.
    #[default]
    Drift,
    /// No joint torque, friction: E - E(0) is the work of friction (<= 0).
    Friction,
    /// Joint torques applied: E - E(0) is the work of the torques and of friction.
    Work,
}

/// What a plot says besides the trajectory.
#[derive(Clone, Debug, Default)]
pub struct PlotInfo {
    /// Title: the robot and the conditions of the run.
    pub title: String,
    /// Why the run stopped before its end (marked on the plot), if it did.
    pub stopped: Option<String>,
    /// Labels `<l>` of the prismatic joints' `q<l>` columns (plotted in metres, apart from the
    /// revolute joints' radians): `3` for `q3`, `_slider` for `q_slider`.
    pub prismatic: Vec<String>,
    /// Labels of the passive joints' `q<l>` columns (a closed chain's extra columns): drawn
    /// dotted and marked "(passive)".
    pub passive: Vec<String>,
    /// The tracked reference, if any: its first columns are q_ref of the simulated joints, in
    /// the order of the trajectory's `tau<l>` columns (as [`super::TorqueInput::Pd`] holds it).
    pub reference: Option<TimeSeries>,
    /// What the energy panel shows.
    pub energy: EnergyBalance,
}

/// SVG plot of a recorded trajectory: see the [module](self). A run that stopped early is
/// marked where it stopped and says why.
pub fn plot_svg(path: &Path, rec: &Recorder, info: &PlotInfo) -> Result<()> {
    let err = |e: String| Error::io(path.display().to_string(), std::io::Error::other(e));
    let t = rec
        .series("t")
        .ok_or_else(|| err("the trajectory has no column t".into()))?;
    if t.is_empty() {
        return Err(err("the trajectory is empty: nothing to plot".into()));
    }
    // a single row still gets an axis
    let t = if t.len() == 1 { vec![t[0], t[0]] } else { t };
    let joints = joint_labels(rec);
    let reference = reference_values(rec, info, &t);
    let t_end = *t.last().unwrap();
    let mut fig = Figure {
        title: info.title.clone(),
        note: info.stopped.as_ref().map(|why| stop_note(why, t_end)),
        x_label: "t [s]".into(),
        panels: Vec::new(),
        mark: info.stopped.as_ref().map(|_| t_end),
        colors: joints.len(),
    };
    for prismatic in [false, true] {
        fig.panels
            .extend(joint_panels(rec, info, &joints, &reference, prismatic));
    }
    if rec.column("energy").is_some() {
        fig.panels.push(energy_panel(
            &column(rec, "energy"),
            info.energy,
            joints.len(),
        ));
    }
    if fig.panels.is_empty() {
        return Err(err(
            "the trajectory has no q or energy column: nothing to plot".into(),
        ));
    }
    write_svg(path, &t, &fig)
}

/// Column `name` of `rec` (empty when absent), a single row doubled to match the time axis.
fn column(rec: &Recorder, name: &str) -> Vec<f64> {
    let mut v = rec.series(name).unwrap_or_default();
    if v.len() == 1 {
        v.push(v[0]);
    }
    v
}

/// "stopped early at t = 1.2 s: why" (the reason cut at 140 characters).
fn stop_note(why: &str, t_end: f64) -> String {
    let mut why = stop_reason(why);
    if why.chars().count() > 140 {
        why = why.chars().take(137).collect::<String>() + "...";
    }
    format!("stopped early at t = {} s: {why}", format_number(t_end))
}

/// The panels of the revolute (`prismatic` false, rad) or prismatic (m) joints: their positions
/// (the passive joints dotted, a tracked reference dashed) and, when a reference was tracked,
/// the tracking errors. None when the robot has no joint of that kind.
fn joint_panels(
    rec: &Recorder,
    info: &PlotInfo,
    joints: &[String],
    reference: &[(String, Vec<f64>)],
    prismatic: bool,
) -> Vec<Panel> {
    let of_kind: Vec<(usize, &String)> = joints
        .iter()
        .enumerate()
        .filter(|(_, l)| info.prismatic.contains(l) == prismatic)
        .collect();
    if of_kind.is_empty() {
        return Vec::new();
    }
    let (kind, unit) = if prismatic {
        ("prismatic", "m")
    } else {
        ("revolute", "rad")
    };
    let mut positions = Panel {
        title: format!("joint positions, {kind} joints"),
        y_label: format!("q [{unit}]"),
        ..Panel::default()
    };
    let mut errors = Panel {
        title: format!("tracking error q_ref - q, {kind} joints"),
        y_label: format!("q_ref - q [{unit}]"),
        ..Panel::default()
    };
    for &(k, l) in &of_kind {
        let q = column(rec, &format!("q{l}"));
        let (label, style) = if info.passive.contains(l) {
            (format!("q{l} (passive)"), Style::Dotted)
        } else {
            (format!("q{l}"), Style::Solid)
        };
        positions
            .curves
            .push(Curve::new(label, q.clone(), k, style));
        if let Some(r) = reference.iter().find(|(rl, _)| rl == l).map(|(_, r)| r) {
            positions
                .curves
                .push(Curve::new(format!("q{l} ref"), r.clone(), k, Style::Dashed).unlisted());
            let e = r.iter().zip(&q).map(|(r, q)| r - q).collect();
            errors
                .curves
                .push(Curve::new(format!("q{l}"), e, k, Style::Solid));
        }
    }
    if errors.curves.is_empty() {
        return vec![positions];
    }
    positions.keys = vec![
        ("simulated".into(), Style::Solid),
        ("reference".into(), Style::Dashed),
    ];
    vec![positions, errors]
}

/// The panel of E - E(0), captioned by what it measures in this run, in colour `color` (past the
/// joints' colours: near-black).
fn energy_panel(e: &[f64], balance: EnergyBalance, color: usize) -> Panel {
    let e0 = e[0];
    let what = match balance {
        EnergyBalance::Drift => {
            "energy drift E - E(0): no torque and no friction conserve E, this is the \
             integration error"
        }
        EnergyBalance::Friction => "energy change E - E(0): the work of friction",
        EnergyBalance::Work => {
            "energy change E - E(0): the work of the joint torques and of friction"
        }
    };
    Panel {
        title: format!("{what} (E(0) = {} J)", Sig(e0, 4)),
        y_label: "E - E(0) [J]".into(),
        curves: vec![Curve::new(
            "E - E(0)",
            e.iter().map(|x| x - e0).collect(),
            color,
            Style::Solid,
        )
        .unlisted()],
        ..Panel::default()
    }
}

/// The `<l>` of every `q<l>` column (q<frame> or q_<joint name>, not qd.. / qdd..), in order.
fn joint_labels(rec: &Recorder) -> Vec<String> {
    rec.headers
        .iter()
        .filter_map(|h| h.strip_prefix('q'))
        .filter(|s| {
            (!s.is_empty() && s.bytes().all(|b| b.is_ascii_digit()))
                || s.strip_prefix('_').is_some_and(|n| !n.is_empty())
        })
        .map(str::to_string)
        .collect()
}

/// q_ref at the recorded times, per simulated joint label (the `tau<l>` columns' order).
fn reference_values(rec: &Recorder, info: &PlotInfo, t: &[f64]) -> Vec<(String, Vec<f64>)> {
    let Some(series) = &info.reference else {
        return Vec::new();
    };
    let labels: Vec<String> = rec
        .headers
        .iter()
        .filter_map(|h| h.strip_prefix("tau").map(str::to_string))
        .collect();
    let n = labels.len().min(series.width());
    let mut values = vec![Vec::with_capacity(t.len()); n];
    let mut row = vec![0.0; n];
    for &ti in t {
        series.sample(ti, 0..n, &mut row);
        for (v, r) in values.iter_mut().zip(&row) {
            v.push(*r);
        }
    }
    labels.into_iter().zip(values).collect()
}

/// What stopped a run, for the plot: the last line of the error (the reason), or the first line
/// without a leading "simulation stopped at t = ..: ".
fn stop_reason(e: &str) -> String {
    let lines: Vec<&str> = e.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    match lines.as_slice() {
        [] => String::new(),
        [one] => match one.strip_prefix("simulation stopped at t = ") {
            Some(rest) => rest.split_once(": ").map_or(rest, |(_, r)| r).to_string(),
            None => one.to_string(),
        },
        [.., last] => last.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::stop_reason;

    #[test]
    fn stop_reasons() {
        let e = "simulation stopped at t = 0.71: q_a = [..] cannot be reached\n  the motion \
                 reached a singular configuration";
        assert_eq!(
            stop_reason(e),
            "the motion reached a singular configuration"
        );
        assert_eq!(
            stop_reason("simulation stopped at t = 0.5: step size underflow"),
            "step size underflow"
        );
    }
}
