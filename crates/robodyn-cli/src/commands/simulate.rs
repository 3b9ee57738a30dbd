//! `robodyn simulate ROBOT --duration T --output traj.csv`: integrate the direct dynamic model
//! of a tree robot under constant torques, a torque time series or a joint PD controller; stream
//! the trajectory to CSV (kept when the run stops early) and optionally plot it as SVG.
//!
//! A closed-chain robot is simulated in its actuated coordinates (columns q<j>, qd<j>, qdd<j>,
//! tau<j> of the actuated joints; q_p re-solved at every evaluation so the loops stay closed),
//! with the extra columns `closure_residual` and the passive joints' q<j>.
//!
//! Joint columns follow `--names` as in `idm`, `ddm` and `regressor`: `q3` (frame number) or
//! `q_shoulder` (joint name), in the CSV, the `--torque-csv` / `--track` input and the plot.

use crate::common::{choices, format_number, parse_list, CliResult, NamesArg, RobotArgs};
use crate::output::{check_distinct, commit_all, Output};
use crate::states::{classify, known_columns, ColumnSpec, Group};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use robodyn::model::param;
use robodyn::simulation::{
    plot_svg, simulate, ClosedChainDynamics, CsvSink, Dynamics, EnergyBalance, Integrator,
    PlotInfo, Recorder, SimOptions, Tee, TimeSeries, TorqueInput, TrajectorySink, TreeDynamics,
    Wrapper,
};
use robodyn::Method;
use std::collections::HashMap;
use std::io::IsTerminal;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Simulated time [s].
    #[arg(long)]
    pub duration: f64,
    /// Fixed RK4 step [s]; without it, adaptive Dormand-Prince 5(4) with --rtol/--atol.
    #[arg(long, conflicts_with_all = ["rtol", "atol"])]
    pub dt: Option<f64>,
    /// Relative tolerance of Dormand-Prince 5(4).
    #[arg(long, default_value_t = 1e-6)]
    pub rtol: f64,
    /// Absolute tolerance of Dormand-Prince 5(4).
    #[arg(long, default_value_t = 1e-9)]
    pub atol: f64,
    /// Time between output rows [s] (default: --dt, or 0.01).
    #[arg(long)]
    pub output_step: Option<f64>,
    /// Initial joint positions, comma separated (movable joints in frame order; default zeros;
    /// closed chains: the actuated joints, default their values in the `assembly`).
    #[arg(long, allow_hyphen_values = true)]
    pub q0: Option<String>,
    /// Initial joint velocities (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qd0: Option<String>,
    /// Floating base: its initial pose x,y,z,qx,qy,qz,qw (position in the world, unit
    /// quaternion; default the origin, identity).
    #[arg(long, allow_hyphen_values = true)]
    pub base_pose: Option<String>,
    /// Floating base: its initial twist vx,vy,vz,wx,wy,wz in the base frame (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub base_twist: Option<String>,
    /// Constant joint torques (default zeros).
    #[arg(long, allow_hyphen_values = true, conflicts_with_all = ["torque_csv", "track"])]
    pub torque: Option<String>,
    /// Torque time series: CSV with columns t, tau<j> (linearly interpolated, held at the ends).
    #[arg(long, conflicts_with = "track")]
    pub torque_csv: Option<PathBuf>,
    /// PD tracking of a reference: CSV with columns t, q<j> and optionally qd<j> (otherwise
    /// the slope of the interpolated q<j>). tau = Kp (q_ref - q) + Kd (qd_ref - qd).
    #[arg(long, requires_all = ["kp", "kd"])]
    pub track: Option<PathBuf>,
    /// Proportional gains of --track: one value for all joints or one per joint.
    #[arg(long, allow_hyphen_values = true, requires = "track")]
    pub kp: Option<String>,
    /// Derivative gains of --track: one value for all joints or one per joint.
    #[arg(long, allow_hyphen_values = true, requires = "track")]
    pub kd: Option<String>,
    /// Direct model of a tree robot (closed chains always use A_cl, H_cl of 10.46–10.48).
    #[arg(long, default_value = "aba", value_parser = choices(&Method::ALL, Method::name, Method::describe))]
    pub method: Method,
    /// Simulate the Coulomb friction as Fs tanh(qd / V) instead of Fs sign(qd) (V in rad/s or
    /// m/s; 0 = exact sign, which makes sticking joints chatter and the steps collapse).
    #[arg(long, default_value_t = 0.01, value_name = "V")]
    pub coulomb_smoothing: f64,
    /// Stop after this many integration steps.
    #[arg(long, default_value_t = robodyn::simulation::DEFAULT_MAX_STEPS)]
    pub max_steps: usize,
    /// Trajectory CSV (`-`: standard output; written all or nothing: see docs/cli.md): t [s], q<j> [rad or m], qd<j> [rad/s or m/s],
    /// qdd<j> [rad/s^2 or m/s^2], tau<j> [N m or N], energy [J] (closed chains: then
    /// closure_residual and the passive q<j>).
    #[arg(long)]
    pub output: PathBuf,
    /// SVG plot: joint positions (revolute and prismatic in separate panels), and the energy
    /// drift E - E(0) [J].
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Stop the run when a joint crosses a limit of the robot file (position, speed or torque;
    /// by default a crossing is reported as a warning and the run goes on).
    #[arg(long)]
    pub stop_at_limits: bool,
    #[command(flatten)]
    pub names: NamesArg,
}

/// Column label `<l>` of each movable joint (by frame number), so that its columns are
/// `q<l>`, `qd<l>`, `tau<l>`: the frame number, or `_<joint name>` with `--names joint` (the
/// rule of [`NamesArg::column`], shared with idm, ddm and regressor).
fn joint_labels(robot: &robodyn::Robot, names: &NamesArg) -> HashMap<usize, String> {
    let c = robot.coordinates();
    (0..c.len())
        .map(|k| (c.frame(k), names.column("", c, k)))
        .collect()
}

/// The dynamics with its joint columns labelled by `--names`.
struct Labelled<'d> {
    inner: Box<dyn Dynamics + 'd>,
    labels: Vec<String>,
    extra: Vec<String>,
}

impl Wrapper for Labelled<'_> {
    fn inner(&self) -> &dyn Dynamics {
        &*self.inner
    }
    fn inner_mut(&mut self) -> &mut dyn Dynamics {
        &mut *self.inner
    }
    fn labels(&self) -> Vec<String> {
        self.labels.clone()
    }
    /// The inner system's names (a floating base's columns) with the joints' relabelled.
    fn column_names(&self) -> [Vec<String>; 4] {
        let mut names = self.inner.column_names();
        for (names, p) in names.iter_mut().zip(["q", "qd", "qdd", "tau"]) {
            let base = names.len() - self.labels.len();
            for (k, l) in self.labels.iter().enumerate() {
                names[base + k] = format!("{p}{l}");
            }
        }
        names
    }
    fn extra_columns(&self) -> Vec<String> {
        self.extra.clone()
    }
}

/// Checks every trajectory row against the robot's joint limits: the first crossing of each
/// joint and kind is remembered (and stops the run with `--stop-at-limits`).
struct LimitWatch<'a> {
    sink: &'a mut dyn TrajectorySink,
    /// (column, joint, what, low, high, unit)
    /// (column, joint as named in messages, frame number, what, low, high, unit)
    checks: Vec<(usize, String, usize, &'static str, f64, f64, &'static str)>,
    limits: &'a std::collections::BTreeMap<usize, robodyn::model::JointLimits>,
    /// Joint (frame number) of each label of the columns.
    joint_of: HashMap<String, usize>,
    units: Vec<(usize, bool)>,
    crossed: Vec<String>,
    seen: std::collections::BTreeSet<(usize, &'static str)>,
    stop: bool,
    /// Rows written.
    rows: usize,
}

impl LimitWatch<'_> {
    /// The crossings, on standard error.
    fn warn(&self) {
        for m in &self.crossed {
            eprintln!("robodyn: warning: {m}");
        }
        if !self.crossed.is_empty() {
            eprintln!(
                "robodyn: warning: the simulation does not enforce joint limits \
                 (--stop-at-limits stops the run at the first crossing)"
            );
        }
    }
}

impl TrajectorySink for LimitWatch<'_> {
    fn begin(&mut self, headers: &[String]) -> robodyn::Result<()> {
        for (c, h) in headers.iter().enumerate() {
            for (prefix, what) in [("qd", "speed"), ("tau", "torque"), ("q", "position")] {
                let Some(&j) = h.strip_prefix(prefix).and_then(|s| self.joint_of.get(s)) else {
                    continue;
                };
                let Some(l) = self.limits.get(&j) else {
                    break;
                };
                let prismatic = self.units.iter().any(|&(k, p)| k == j && p);
                let (lo, hi, unit) = match what {
                    "position" => (l.q_min, l.q_max, if prismatic { "m" } else { "rad" }),
                    "speed" => (
                        l.qd.map(|x| -x),
                        l.qd,
                        if prismatic { "m/s" } else { "rad/s" },
                    ),
                    _ => (
                        l.tau.map(|x| -x),
                        l.tau,
                        if prismatic { "N" } else { "N m" },
                    ),
                };
                if let (Some(lo), Some(hi)) = (lo, hi) {
                    // `joint 5`, or `joint 5 (extend)` with --names joint
                    let named = match h[prefix.len()..].strip_prefix('_') {
                        Some(name) => format!("joint {j} ({name})"),
                        None => format!("joint {j}"),
                    };
                    self.checks.push((c, named, j, what, lo, hi, unit));
                }
                break;
            }
        }
        self.sink.begin(headers)
    }
    fn row(&mut self, values: &[f64]) -> robodyn::Result<()> {
        self.sink.row(values)?;
        self.rows += 1;
        for (c, named, j, what, lo, hi, unit) in &self.checks {
            let (c, j, what, lo, hi, unit) = (*c, *j, *what, *lo, *hi, *unit);
            let x = values[c];
            if (x < lo || x > hi) && self.seen.insert((j, what)) {
                let m = format!(
                    "{named} crosses its {what} limit at t = {} s: {} {unit} outside [{}, {}]",
                    format_number(values[0]),
                    format_number(x),
                    format_number(lo),
                    format_number(hi)
                );
                if self.stop {
                    return Err(robodyn::Error::Numerical(format!("{m} (--stop-at-limits)")));
                }
                self.crossed.push(m);
            }
        }
        Ok(())
    }
    fn finish(&mut self) -> robodyn::Result<()> {
        self.sink.finish()
    }
}

fn joint_values(
    name: &str,
    s: Option<&str>,
    joints: &[usize],
    what: &str,
    default: Option<&[f64]>,
) -> CliResult<Vec<f64>> {
    let Some(s) = s else {
        return Ok(default.map_or_else(|| vec![0.0; joints.len()], <[f64]>::to_vec));
    };
    let v = parse_list(name, s)?;
    if v.len() != joints.len() {
        return Err(format!(
            "--{name} has {} values, the robot has {} {what} ({joints:?})",
            v.len(),
            joints.len()
        )
        .into());
    }
    Ok(v)
}

fn gains(name: &str, s: &str, n: usize) -> CliResult<Vec<f64>> {
    let v = parse_list(name, s)?;
    match v.len() {
        1 => Ok(vec![v[0]; n]),
        k if k == n => Ok(v),
        k => Err(format!("--{name} has {k} values: give one, or one per joint ({n})").into()),
    }
}

/// Read a time series (`--torque-csv`, `--track`): column `t` and, per group of `prefixes`
/// (prefix, required, what its absence means), the columns `<prefix><l>` of every joint label;
/// the columns are checked by the rule of `idm`'s tables (a misspelt one is an error, an unknown
/// one a warning: it is ignored). Whether every optional group is present.
fn read_series(
    path: &std::path::Path,
    prefixes: &[(&str, bool, &'static str)],
    joints: &[String],
    all_labels: &[String],
) -> CliResult<(TimeSeries, bool)> {
    let file = path.display().to_string();
    let f = std::fs::File::open(path).map_err(|e| format!("{file}: {e}"))?;
    let t = robodyn::io::table::Table::from_reader(std::io::BufReader::new(f), &file)?;
    let tc = t
        .find("t")
        .ok_or_else(|| format!("{file}: missing column `t` (the time, s)"))?;
    let spec = ColumnSpec {
        groups: prefixes
            .iter()
            .map(|&(prefix, required, absent)| Group {
                prefix: prefix.into(),
                names: joints.iter().map(|j| format!("{prefix}{j}")).collect(),
                required,
                absent,
            })
            .collect(),
        known: known_columns(all_labels, false),
        declared: &[],
        fate: "ignored",
        carry_option: false,
        hint: None,
    };
    let c = classify(&t.headers, &spec, &file)?;
    let cols: Vec<usize> = c.groups.iter().flatten().flatten().copied().collect();
    let times = t.rows.iter().map(|r| r[tc]).collect();
    let values = t
        .rows
        .iter()
        .map(|r| cols.iter().map(|&c| r[c]).collect())
        .collect();
    let s = TimeSeries::new(times, values).map_err(|e| format!("{file}: {e}"))?;
    Ok((s, c.groups.iter().all(Option::is_some)))
}

/// More output rows than this (a CSV of about 100 GB) is refused: an output step far too small.
const MAX_ROWS: f64 = 1e9;

/// The numeric options, checked before any file is touched.
fn check_options(a: &Args) -> CliResult {
    let positive = |name: &str, v: Option<f64>| -> CliResult {
        match v {
            Some(x) if !(x.is_finite() && x > 0.0) => {
                Err(format!("--{name} {x}: must be a positive finite number").into())
            }
            _ => Ok(()),
        }
    };
    positive("duration", Some(a.duration))?;
    positive("dt", a.dt)?;
    positive("output-step", a.output_step)?;
    if a.dt.is_none() {
        positive("rtol", Some(a.rtol))?;
        positive("atol", Some(a.atol))?;
    }
    if a.max_steps == 0 {
        return Err("--max-steps 0: must be at least 1".into());
    }
    let step = a.output_step.or(a.dt).unwrap_or(0.01);
    let rows = a.duration / step;
    if rows > MAX_ROWS {
        return Err(format!(
            "--duration {} with an output step of {} s gives {} rows, more than {MAX_ROWS:.0e} \
             (give a larger --output-step)",
            format_number(a.duration),
            format_number(step),
            if rows.is_finite() {
                format!("{rows:.1e}")
            } else {
                "more than 1e308".into()
            }
        )
        .into());
    }
    if !(a.coulomb_smoothing.is_finite() && a.coulomb_smoothing >= 0.0) {
        return Err("--coulomb-smoothing must be a finite number >= 0".into());
    }
    Ok(())
}

/// The dynamics of the run: a tree's, or a closed chain's on the branch of its assembly; its
/// joints (frame numbers), what they are in messages, and the default q0.
type Model<'r> = (
    Box<dyn Dynamics + 'r>,
    Vec<usize>,
    &'static str,
    Option<Vec<f64>>,
);

fn model<'r>(robot: &'r robodyn::Robot, a: &Args) -> CliResult<Model<'r>> {
    let smoothing = Some(a.coulomb_smoothing);
    if robot.is_tree() {
        let d = TreeDynamics::new(robot, a.method).with_coulomb_smoothing(smoothing);
        let joints = d.joints().to_vec();
        return Ok((Box::new(d), joints, "movable tree joints", None));
    }
    let chain = robodyn::ClosedChain::new(robot)?;
    let branch = chain.assembly_branch().map_err(|e| {
        format!(
            "the simulation starts on the branch of the assembly configuration, which cannot \
             be used: {e}"
        )
    })?;
    let q0 = branch.q_a().to_vec();
    let d = ClosedChainDynamics::new(chain, branch).with_coulomb_smoothing(smoothing);
    let joints = d.chain().coordinates().frames().to_vec();
    Ok((
        Box::new(d),
        joints,
        "actuated joints (closed chain)",
        Some(q0),
    ))
}

/// The torque input: constant, a series (`--torque-csv`) or PD tracking (`--track`).
fn torque_input(
    a: &Args,
    joints: &[usize],
    what: &str,
    labels: &[String],
    all: &[String],
) -> CliResult<TorqueInput> {
    let n = joints.len();
    Ok(if let Some(p) = &a.torque_csv {
        TorqueInput::Series(read_series(p, &[("tau", true, "")], labels, all)?.0)
    } else if let Some(p) = &a.track {
        let velocity = (
            "qd",
            false,
            "the reference velocity is the slope of the interpolated q",
        );
        let (reference, with_velocity) = read_series(p, &[("q", true, ""), velocity], labels, all)?;
        TorqueInput::Pd {
            reference,
            with_velocity,
            kp: gains("kp", a.kp.as_deref().unwrap_or_default(), n)?,
            kd: gains("kd", a.kd.as_deref().unwrap_or_default(), n)?,
        }
    } else {
        TorqueInput::Constant(joint_values(
            "torque",
            a.torque.as_deref(),
            joints,
            what,
            None,
        )?)
    })
}

/// A floating robot's state and input: the base pose and twist before the joints' values, and
/// a free base (zero wrench on it). Refused for a robot whose base does not float.
fn with_base(
    robot: &robodyn::Robot,
    a: &Args,
    q0: Vec<f64>,
    qd0: Vec<f64>,
    input: TorqueInput,
) -> CliResult<(Vec<f64>, Vec<f64>, TorqueInput)> {
    if !robot.is_floating() {
        if let Some(flag) = [
            ("--base-pose", &a.base_pose),
            ("--base-twist", &a.base_twist),
        ]
        .iter()
        .find_map(|(f, v)| v.is_some().then_some(f))
        {
            return Err(format!(
                "{flag}: the robot's base is {} (a floating base is `base = \"floating\"` in \
                 TOML, `is_floating = 1` in .par)",
                robot.base_kind().name()
            )
            .into());
        }
        return Ok((q0, qd0, input));
    }
    let values = |name: &str, s: &Option<String>, default: &[f64]| -> CliResult<Vec<f64>> {
        let Some(s) = s else {
            return Ok(default.to_vec());
        };
        let v = parse_list(name, s)?;
        if v.len() != default.len() {
            return Err(format!(
                "--{name} has {} values, {} expected",
                v.len(),
                default.len()
            )
            .into());
        }
        Ok(v)
    };
    let pose = values(
        "base-pose",
        &a.base_pose,
        &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
    )?;
    let twist = values("base-twist", &a.base_twist, &[0.0; 6])?;
    let norm = pose[3..].iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > robodyn::model::QUATERNION_TOLERANCE {
        return Err(format!(
            "--base-pose: the quaternion ({}, {}, {}, {}) has norm {norm}, not 1",
            pose[3], pose[4], pose[5], pose[6]
        )
        .into());
    }
    if matches!(input, TorqueInput::Pd { .. }) {
        return Err(
            "--track: a PD input acts on joint positions and needs a fixed base; give \
                    --torque or --torque-csv for a floating robot"
                .into(),
        );
    }
    Ok((
        pose.into_iter().chain(q0).collect(),
        twist.into_iter().chain(qd0).collect(),
        input.with_free_base(6),
    ))
}

/// A progress bar on a terminal's standard error (hidden otherwise).
fn progress_bar() -> CliResult<ProgressBar> {
    let bar = if std::io::stderr().is_terminal() {
        ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr())
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{bar:40} {percent:>3}% t = {msg} s, elapsed {elapsed}, eta {eta}",
        )
        .map_err(|e| e.to_string())?,
    );
    Ok(bar)
}

/// The simulated system with its columns named as `--names` says (a closed chain's passive
/// joints' `q<j>` too), its joints (frame numbers), what they are, the default q0, and the
/// label of every movable joint by frame number.
#[allow(clippy::type_complexity)]
fn labelled_model<'r>(
    robot: &'r robodyn::Robot,
    a: &Args,
) -> CliResult<(
    Labelled<'r>,
    Vec<usize>,
    &'static str,
    Option<Vec<f64>>,
    HashMap<usize, String>,
)> {
    let (dynamics, joints, what, q0_default) = model(robot, a)?;
    if joints.is_empty() {
        return Err("the robot has no movable joint: nothing to simulate".into());
    }
    let label = joint_labels(robot, &a.names);
    let labels: Vec<String> = joints.iter().map(|j| label[j].clone()).collect();
    // the passive joints' q<j> of a closed chain follow the same rule
    let extra = dynamics
        .extra_columns()
        .into_iter()
        .map(
            |h| match h.strip_prefix('q').and_then(|s| s.parse::<usize>().ok()) {
                Some(j) if label.contains_key(&j) => format!("q{}", label[&j]),
                _ => h,
            },
        )
        .collect();
    let dynamics = Labelled {
        inner: dynamics,
        labels,
        extra,
    };
    Ok((dynamics, joints, what, q0_default, label))
}

pub fn run(a: Args) -> CliResult {
    check_options(&a)?;
    check_distinct(&[("--output", Some(&a.output)), ("--plot", a.plot.as_deref())])?;
    let robot = a.robot.load()?;
    crate::common::transmission_note(&robot, "simulate");
    let (mut dynamics, joints, what, q0_default, label) = labelled_model(&robot, &a)?;
    let n = joints.len();
    let labels = dynamics.labels.clone();
    // the initial state and the input (the columns of its files checked)
    let q0 = joint_values("q0", a.q0.as_deref(), &joints, what, q0_default.as_deref())?;
    let qd0 = joint_values("qd0", a.qd0.as_deref(), &joints, what, None)?;
    let all_labels: Vec<String> = label.values().cloned().collect();
    let input = torque_input(&a, &joints, what, &labels, &all_labels)?;
    let (q0, qd0, input) = with_base(&robot, &a, q0, qd0, input)?;
    let n = if robot.is_floating() { robot.nv() } else { n };
    let integrator = Integrator::fixed_or_adaptive(a.dt, a.rtol, a.atol);
    let opts = SimOptions {
        duration: a.duration,
        integrator,
        output_dt: a.output_step.or(a.dt).unwrap_or(0.01),
        max_steps: Some(a.max_steps),
    };
    integrator.validate()?;
    input.validate(n)?;
    // the files are made now (a missing directory is an error before the run) and put in
    // place at the end
    let mut csv_out = Output::create(Some(&a.output))?;
    let plot_out = a
        .plot
        .as_deref()
        .map(|p| Output::create(Some(p)))
        .transpose()?;
    let out_name = csv_out.name().to_string();
    let mut csv = CsvSink::new(csv_out.writer(), out_name.clone());
    let mut rec = Recorder::default();
    let bar = progress_bar()?;
    let duration = a.duration;
    let mut progress = |t: f64| {
        bar.set_position(((t / duration) * 1000.0).round() as u64);
        bar.set_message(format!("{t:.3}"));
    };
    let prismatic: Vec<(usize, bool)> = (1..=robot.nl())
        .map(|j| (j, robot.description().frame(j).joint.sigma() == 1))
        .collect();
    let mut tee;
    let mut watch = LimitWatch {
        sink: if a.plot.is_some() {
            tee = Tee(&mut csv, &mut rec);
            &mut tee
        } else {
            &mut csv
        },
        checks: Vec::new(),
        limits: &robot.description().limits,
        joint_of: label.iter().map(|(&j, l)| (l.clone(), j)).collect(),
        units: prismatic,
        crossed: Vec::new(),
        seen: Default::default(),
        stop: a.stop_at_limits,
        rows: 0,
    };
    let result = simulate(
        &mut dynamics,
        &input,
        &q0,
        &qd0,
        &opts,
        &mut watch,
        &mut progress,
    );
    bar.finish_and_clear();
    // `--output - | head`: the reader has what it wanted; end quietly
    if let Err(e) = &result {
        if crate::common::is_broken_pipe(e) {
            return Ok(());
        }
    }
    watch.warn();
    let rows = watch.rows;
    drop(watch);
    drop(csv);
    let info = PlotInfo {
        title: plot_title(&robot, &a),
        stopped: result.as_ref().err().map(|e| e.to_string()),
        prismatic: prismatic_labels(&robot, &label),
        passive: passive_labels(&robot, &joints, &label),
        reference: match &input {
            TorqueInput::Pd { reference, .. } => Some(reference.clone()),
            _ => None,
        },
        energy: energy_balance(&robot, &input),
    };
    finish(result, rows, &rec, csv_out, plot_out, &info)
}

/// Put the run's files in place: all of them after a complete run; after a run that stopped
/// early, the trajectory up to the stop (and its plot); nothing when not one row was computed.
fn finish(
    result: robodyn::Result<robodyn::simulation::SimSummary>,
    rows: usize,
    rec: &Recorder,
    csv: Output,
    plot: Option<Output>,
    info: &PlotInfo,
) -> CliResult {
    let csv_name = csv.name().to_string();
    if rows == 0 {
        let e = result.err().map_or_else(String::new, |e| e.to_string());
        return Err(format!("{e}\n  nothing was written ({csv_name} is unchanged)").into());
    }
    let mut outputs = vec![csv];
    let mut plotted = String::new();
    if let Some(mut p) = plot.filter(|_| !rec.rows.is_empty()) {
        match p.write_by_path(|path| plot_svg(path, rec, info)) {
            Ok(()) => {
                plotted = format!(", its plot in {}", p.name());
                outputs.push(p);
            }
            // a complete run whose plot fails writes nothing
            Err(e) if result.is_ok() => return Err(format!("{e} (nothing was written)").into()),
            Err(e) => plotted = format!(" (the plot could not be written: {e})"),
        }
    }
    commit_all(outputs)?;
    match result {
        Ok(s) => {
            eprintln!(
                "simulated {} s: {} rows in {csv_name}, {} steps ({} rejected), {} model \
                 evaluations",
                format_number(s.t_end),
                s.rows,
                s.stats.accepted,
                s.stats.rejected,
                s.stats.evaluations
            );
            Ok(())
        }
        Err(e) => Err(format!(
            "{e}\n  the trajectory computed up to the stop is in {csv_name}{plotted}"
        )
        .into()),
    }
}

/// Plot title: the robot and the conditions of the run.
fn plot_title(robot: &robodyn::Robot, a: &Args) -> String {
    let input = if a.track.is_some() {
        "PD tracking"
    } else if a.torque_csv.is_some() {
        "torque series"
    } else if a.torque.is_some() {
        "constant torques"
    } else {
        "zero torques"
    };
    let scheme = match a.dt {
        Some(dt) => format!("RK4, dt = {} s", format_number(dt)),
        None => format!(
            "Dormand-Prince 5(4), rtol {}, atol {}",
            format_number(a.rtol),
            format_number(a.atol)
        ),
    };
    format!("{}: {input}, {scheme}", robot.name())
}

/// Labels (as in the q<l> columns) of the movable joints that are not simulated coordinates:
/// a closed chain's passive joints.
fn passive_labels(
    robot: &robodyn::Robot,
    simulated: &[usize],
    label: &HashMap<usize, String>,
) -> Vec<String> {
    (1..=robot.nl())
        .filter(|j| robot.description().frame(*j).joint.is_movable() && !simulated.contains(j))
        .filter_map(|j| label.get(&j).cloned())
        .collect()
}

/// What E - E(0) measures: the work of the torques, of friction alone, or the drift.
fn energy_balance(robot: &robodyn::Robot, input: &TorqueInput) -> EnergyBalance {
    let driven = match input {
        TorqueInput::Constant(tau) => tau.iter().any(|&x| x != 0.0),
        _ => true,
    };
    let k = robot.standard_parameters();
    let per_link = robodyn::model::STANDARD_PARAMETERS.len();
    let friction = k
        .chunks(per_link)
        .any(|link| link[param::FS] != 0.0 || link[param::FV] != 0.0);
    match (driven, friction) {
        (true, _) => EnergyBalance::Work,
        (false, true) => EnergyBalance::Friction,
        (false, false) => EnergyBalance::Drift,
    }
}

/// Labels (as in the q<l> columns) of the prismatic joints.
fn prismatic_labels(robot: &robodyn::Robot, label: &HashMap<usize, String>) -> Vec<String> {
    (1..=robot.description().nj)
        .filter(|&j| robot.description().frame(j).joint.sigma() == 1)
        .map(|j| label.get(&j).cloned().unwrap_or_else(|| j.to_string()))
        .collect()
}
