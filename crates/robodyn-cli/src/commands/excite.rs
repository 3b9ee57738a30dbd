//! `robodyn excite ROBOT --period T --harmonics N --output traj.csv`: an exciting trajectory for
//! identification, a finite Fourier series per actuated joint whose coefficients minimize the
//! condition number of the base-parameter observation matrix under position, velocity,
//! acceleration and torque limits, starting and ending at rest.

use crate::commands::identify::positive;
use crate::common::format_number;
use crate::common::{choices, parse_list, CliResult, RobotArgs};
use robodyn::algorithms::regressor::RotorMode;
use robodyn::identification::excitation::{design, Design, DesignOptions, Limits};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::parameters::{ParameterModel, ParameterOptions};
use robodyn::report::figure::{write_svg, Curve, Figure, Panel, Style};
use robodyn::report::Sig;
use serde_json::json;
use std::path::PathBuf;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Text for reading.
    Text,
    /// JSON for programs (every number a full double).
    Json,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Period T of the Fourier series (s).
    #[arg(long, value_parser = positive)]
    pub period: f64,
    /// Harmonics per joint (at least 2).
    #[arg(long)]
    pub harmonics: usize,
    /// Start and end position of the actuated joints (default: the assembly's, else zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub start: Option<String>,
    /// Lower position limits (one value for all joints or one per joint; default: the robot
    /// file's `limits`, else none).
    #[arg(long, allow_hyphen_values = true)]
    pub q_min: Option<String>,
    /// Upper position limits.
    #[arg(long, allow_hyphen_values = true)]
    pub q_max: Option<String>,
    /// Velocity limits (required here or in the robot file).
    #[arg(long)]
    pub qd_max: Option<String>,
    /// Acceleration limits (required here or in the robot file).
    #[arg(long)]
    pub qdd_max: Option<String>,
    /// Torque limits (the robot file's parameters; default: the file's `limits`, else none).
    #[arg(long)]
    pub tau_max: Option<String>,
    /// Samples per period at which the observation matrix is evaluated.
    #[arg(long, default_value_t = 100)]
    pub samples: usize,
    /// Nelder-Mead iterations.
    #[arg(long, default_value_t = 1500)]
    pub iterations: u64,
    /// Random starting trajectories tried before the optimization.
    #[arg(long, default_value_t = 20)]
    pub restarts: usize,
    /// Seed of the random starting trajectories and of the base-parameter method's samples.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Which rotor inertias are parameters (as identify).
    #[arg(long, default_value = "actuated", value_parser = choices(&RotorMode::ALL, RotorMode::name, RotorMode::describe))]
    pub rotor: RotorMode,
    /// Leave out the Coulomb and viscous friction parameters (as identify).
    #[arg(long)]
    pub no_friction: bool,
    /// Add a constant torque offset per joint to the parameters (as identify).
    #[arg(long)]
    pub offsets: bool,
    /// Rate of the CSV rows (Hz).
    #[arg(long, default_value_t = 200.0, value_parser = positive)]
    pub rate: f64,
    /// Periods written to the CSV.
    #[arg(long, default_value_t = 1)]
    pub periods: usize,
    /// CSV: t, q<j>, qd<j>, qdd<j> of the actuated joints (a reference for the robot's
    /// controller, e.g. `robodyn simulate --track`).
    #[arg(long)]
    pub output: PathBuf,
    /// SVG plot of the positions, velocities and accelerations (one panel per quantity and
    /// unit: revolute and prismatic joints apart).
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Format of the report on standard output (the trajectory goes to --output).
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

fn per_joint(name: &str, s: Option<&str>, n: usize) -> CliResult<Option<Vec<f64>>> {
    let Some(s) = s else { return Ok(None) };
    let v = parse_list(name, s)?;
    match v.len() {
        1 => Ok(Some(vec![v[0]; n])),
        k if k == n => Ok(Some(v)),
        k => Err(
            format!("--{name} has {k} values: give one, or one per actuated joint ({n})").into(),
        ),
    }
}

/// Rows of the CSV at most (a larger file is a mistake of --rate or --periods).
const MAX_ROWS: f64 = 1e8;

pub fn run(a: Args) -> CliResult {
    let rows = output_rows(&a)?;
    let desc = a.robot.description()?.0;
    let mut access = ModelAccess::new(desc)?;
    let joints = access.actuated_joints().to_vec();
    let start = match per_joint("start", a.start.as_deref(), joints.len())? {
        Some(v) => v,
        None => access.reference_actuated()?,
    };
    let limits = joint_limits(&a, &access, &joints)?;
    let mut params = ParameterModel::build(
        &mut access,
        &ParameterOptions {
            rotors: a.rotor,
            friction: !a.no_friction,
            offsets: a.offsets,
            seed: a.seed,
            ..ParameterOptions::default()
        },
    )?;
    let opt = DesignOptions {
        period: a.period,
        harmonics: a.harmonics,
        start,
        limits,
        samples: a.samples,
        iterations: a.iterations,
        restarts: a.restarts,
        seed: a.seed,
    };
    let d = design(&mut access, &mut params, &opt)?;
    write_files(&a, &access, &joints, &d, rows)?;
    let out = match a.format {
        Format::Text => summary_text(&a, &access, &joints, params.count(), &d),
        Format::Json => summary_json(&a, &access, &joints, &d)?,
    };
    crate::common::print_out(&out)
}

/// The output files checked and the number of CSV rows, before the design (which takes a
/// while).
fn output_rows(a: &Args) -> CliResult<usize> {
    let files = [
        ("--output", Some(a.output.as_path())),
        ("--plot", a.plot.as_deref()),
    ];
    crate::output::check_distinct(&files)?;
    if a.periods == 0 {
        return Err("--periods must be at least 1".into());
    }
    let rows = a.period * a.periods as f64 * a.rate;
    if rows > MAX_ROWS {
        return Err(format!(
            "--period {} x --periods {} x --rate {} = {rows:e} rows: at most {MAX_ROWS:e}",
            a.period, a.periods, a.rate
        )
        .into());
    }
    Ok(rows.round() as usize)
}

/// The limits of each actuated joint: the command line's, else the robot file's; velocity and
/// acceleration limits are required.
fn joint_limits(a: &Args, access: &ModelAccess, joints: &[usize]) -> CliResult<Vec<Limits>> {
    let n = joints.len();
    let cli = |name: &str, s: &Option<String>| per_joint(name, s.as_deref(), n);
    let (qmin, qmax, qd, qdd, tau) = (
        cli("q-min", &a.q_min)?,
        cli("q-max", &a.q_max)?,
        cli("qd-max", &a.qd_max)?,
        cli("qdd-max", &a.qdd_max)?,
        cli("tau-max", &a.tau_max)?,
    );
    let mut limits = Vec::with_capacity(n);
    for (k, &j) in joints.iter().enumerate() {
        let f = access.limits(j);
        let pick = |c: &Option<Vec<f64>>, file: Option<f64>| c.as_ref().map(|v| v[k]).or(file);
        let need = |v: Option<f64>, what: &str, opt: &str| -> CliResult<f64> {
            v.ok_or_else(|| {
                format!(
                    "joint {j}: no {what} limit: give --{opt} or `limits` in the robot file's frame {j}"
                )
                .into()
            })
        };
        limits.push(Limits {
            q_min: pick(&qmin, f.q_min),
            q_max: pick(&qmax, f.q_max),
            qd: need(pick(&qd, f.qd), "velocity", "qd-max")?,
            qdd: need(pick(&qdd, f.qdd), "acceleration", "qdd-max")?,
            tau: pick(&tau, f.tau),
        });
    }
    Ok(limits)
}

/// The trajectory's CSV (`rows` + 1 rows at `--rate`) and its plot: all or nothing, both files
/// put in place once both are written.
fn write_files(
    a: &Args,
    access: &ModelAccess,
    joints: &[usize],
    d: &Design,
    rows: usize,
) -> CliResult {
    let n = joints.len();
    let mut file = crate::output::Output::create(Some(&a.output))?;
    let mut plot_file = a
        .plot
        .as_deref()
        .map(|p| crate::output::Output::create(Some(p)))
        .transpose()?;
    let out = file.writer();
    let mut header = vec!["t".to_string()];
    for p in ["q", "qd", "qdd"] {
        header.extend(joints.iter().map(|j| format!("{p}{j}")));
    }
    writeln!(out, "{}", header.join(","))?;
    let mut series: Vec<Vec<Vec<f64>>> = vec![vec![Vec::new(); n]; 3];
    let mut times = Vec::new();
    for k in 0..=rows {
        let t = k as f64 / a.rate;
        let s = d.trajectory.eval(t % a.period);
        let mut line = vec![format_number(t)];
        for (v, ser) in s.iter().zip(series.iter_mut()) {
            for j in 0..n {
                line.push(format_number(v[j]));
                ser[j].push(v[j]);
            }
        }
        times.push(t);
        writeln!(out, "{}", line.join(","))?;
    }
    out.flush()?;
    if let Some(plot_file) = &mut plot_file {
        let prismatic: Vec<bool> = joints.iter().map(|&j| access.is_prismatic(j)).collect();
        let title = format!(
            "{}: exciting trajectory, {} harmonics, period {} s, condition number {}",
            access.name(),
            a.harmonics,
            format_number(a.period),
            Sig(d.condition, 4)
        );
        plot_file
            .write_by_path(|p| excitation_figure(p, &title, &times, &series, joints, &prismatic))?;
    }
    crate::output::commit_all([Some(file), plot_file].into_iter().flatten().collect())?;
    eprintln!("wrote {}", a.output.display());
    if let Some(p) = &a.plot {
        eprintln!("wrote {}", p.display());
    }
    Ok(())
}

/// The design in text: condition numbers, the binding limit, each joint's peaks.
fn summary_text(
    a: &Args,
    access: &ModelAccess,
    joints: &[usize],
    parameters: usize,
    d: &Design,
) -> String {
    let mut out = String::new();
    outln!(
        out,
        "{}: excitation trajectory, {} harmonics, period {} s, {} parameters",
        access.name(),
        a.harmonics,
        a.period,
        parameters
    );
    outln!(
        out,
        "condition number of W (unit columns, {} samples): {} (best random start {}; {} \
         evaluations)",
        a.samples,
        Sig(d.condition, 4),
        Sig(d.initial_condition, 4),
        d.evaluations
    );
    outln!(
        out,
        "scaled to the {} limit of joint {}",
        d.binding.what,
        joints[d.binding.joint]
    );
    outln!(
        out,
        "  joint  max|q-start|       max|qd|      max|qdd|      max|tau|  (units: rad, \
         rad/s, rad/s^2, N m; m, m/s, m/s^2, N for a prismatic joint)"
    );
    for (k, j) in joints.iter().enumerate() {
        let p = d.peaks[k].map(|x| Sig(x, 6).to_string());
        let kind = if access.is_prismatic(*j) {
            " (prismatic)"
        } else {
            ""
        };
        outln!(
            out,
            "  {j:<5} {:>13} {:>13} {:>13} {:>13}{kind}",
            p[0],
            p[1],
            p[2],
            p[3]
        );
    }
    out
}

/// The design in JSON (every number a full double).
fn summary_json(a: &Args, access: &ModelAccess, joints: &[usize], d: &Design) -> CliResult<String> {
    let mut out = String::new();
    outln!(
        out,
        "{}",
        serde_json::to_string_pretty(&json!({
            "robot": access.name(),
            "period": a.period,
            "harmonics": a.harmonics,
            "condition_number": d.condition,
            "initial_condition_number": d.initial_condition,
            "evaluations": d.evaluations,
            "binding": {"joint": joints[d.binding.joint], "limit": d.binding.what},
            "start": d.trajectory.start,
            "a": d.trajectory.a,
            "b": d.trajectory.b,
            "peaks": joints.iter().zip(&d.peaks).map(|(j, p)| json!({
                "joint": j, "q": p[0], "qd": p[1], "qdd": p[2], "tau": p[3]})).collect::<Vec<_>>(),
        }))?
    );
    Ok(out)
}

/// The figure of an exciting trajectory: positions, velocities and accelerations of the
/// actuated joints, one panel per quantity and unit (revolute and prismatic joints apart),
/// joint k in colour k in every panel.
fn excitation_figure(
    path: &std::path::Path,
    title: &str,
    t: &[f64],
    series: &[Vec<Vec<f64>>],
    joints: &[usize],
    prismatic: &[bool],
) -> CliResult {
    const QUANTITIES: [(&str, &str, [&str; 2]); 3] = [
        ("joint positions", "q", ["rad", "m"]),
        ("joint velocities", "qd", ["rad/s", "m/s"]),
        ("joint accelerations", "qdd", ["rad/s^2", "m/s^2"]),
    ];
    let mut panels = Vec::new();
    for (k, (what, symbol, units)) in QUANTITIES.iter().enumerate() {
        for (kind, unit, is_prismatic) in
            [("revolute", units[0], false), ("prismatic", units[1], true)]
        {
            let curves: Vec<Curve> = joints
                .iter()
                .enumerate()
                .filter(|(i, _)| prismatic[*i] == is_prismatic)
                .map(|(i, j)| {
                    Curve::new(
                        format!("{symbol}{j}"),
                        series[k][i].clone(),
                        i,
                        Style::Solid,
                    )
                })
                .collect();
            if curves.is_empty() {
                continue;
            }
            let kind = if prismatic.iter().all(|&p| p == is_prismatic) {
                String::new()
            } else {
                format!(", {kind} joints")
            };
            panels.push(Panel {
                title: format!("{what}{kind}"),
                y_label: format!("{symbol} [{unit}]"),
                curves,
                ..Panel::default()
            });
        }
    }
    let fig = Figure {
        title: title.to_string(),
        x_label: "t [s]".into(),
        panels,
        colors: joints.len(),
        ..Figure::default()
    };
    write_svg(path, t, &fig)?;
    Ok(())
}
