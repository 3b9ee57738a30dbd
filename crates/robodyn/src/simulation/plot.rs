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
    let column = |name: &str| -> Vec<f64> {
        let mut v = rec.series(name).unwrap_or_default();
        if v.len() == 1 {
            v.push(v[0]);
        }
        v
    };
    let joints = joint_labels(rec);
    let reference = reference_values(rec, info, &t);
    let mut fig = Figure {
        title: info.title.clone(),
        note: info.stopped.as_ref().map(|why| {
            let mut why = stop_reason(why);
            if why.chars().count() > 140 {
                why = why.chars().take(137).collect::<String>() + "...";
            }
            format!(
                "stopped early at t = {} s: {why}",
                format_number(*t.last().unwrap())
            )
        }),
        x_label: "t [s]".into(),
        panels: Vec::new(),
        mark: info.stopped.as_ref().map(|_| *t.last().unwrap()),
        colors: joints.len(),
    };
    for (prismatic, unit) in [(false, "rad"), (true, "m")] {
        let of_kind: Vec<(usize, &String)> = joints
            .iter()
            .enumerate()
            .filter(|(_, l)| info.prismatic.contains(l) == prismatic)
            .collect();
        if of_kind.is_empty() {
            continue;
        }
        let kind = if prismatic { "prismatic" } else { "revolute" };
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
            let q = column(&format!("q{l}"));
            let passive = info.passive.contains(l);
            let (label, style) = if passive {
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
        if !errors.curves.is_empty() {
            positions.keys = vec![
                ("simulated".into(), Style::Solid),
                ("reference".into(), Style::Dashed),
            ];
        }
        fig.panels.push(positions);
        if !errors.curves.is_empty() {
            fig.panels.push(errors);
        }
    }
    if rec.column("energy").is_some() {
        let e = column("energy");
        let e0 = e[0];
        let what = match info.energy {
            EnergyBalance::Drift => {
                "energy drift E - E(0): no torque and no friction conserve E, this is the \
                 integration error"
            }
            EnergyBalance::Friction => "energy change E - E(0): the work of friction",
            EnergyBalance::Work => {
                "energy change E - E(0): the work of the joint torques and of friction"
            }
        };
        fig.panels.push(Panel {
            title: format!("{what} (E(0) = {} J)", Sig(e0, 4)),
            y_label: "E - E(0) [J]".into(),
            // near-black: no joint's colour
            curves: vec![Curve::new(
                "E - E(0)",
                e.iter().map(|x| x - e0).collect(),
                joints.len(),
                Style::Solid,
            )
            .unlisted()],
            ..Panel::default()
        });
    }
    if fig.panels.is_empty() {
        return Err(err(
            "the trajectory has no q or energy column: nothing to plot".into(),
        ));
    }
    write_svg(path, &t, &fig)
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
