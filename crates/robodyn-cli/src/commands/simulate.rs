//! `robodyn simulate ROBOT --duration T --output traj.csv`: integrate the direct dynamic model
//! of a tree robot under constant torques, a torque time series or a joint PD controller; stream
//! the trajectory to CSV (kept when the run stops early) and optionally plot it as SVG.
//!
//! A closed-chain robot is simulated in its actuated coordinates (columns q<j>, qd<j>, qdd<j>,
//! tau<j> of the actuated joints; q_p re-solved at every evaluation so the loops stay closed),
//! with the extra columns `closure_residual` and the passive joints' q<j>.

use crate::commands::ddm::MethodArg;
use crate::common::{parse_list, CliResult, RobotArgs, Table};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use robodyn::simulation::{
    plot_svg, simulate, ClosedChainDynamics, CsvSink, Dynamics, Integrator, Recorder, SimOptions,
    Tee, TimeSeries, TorqueInput, TreeDynamics,
};
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
    /// Proportional gains: one value for all joints or one per joint.
    #[arg(long, allow_hyphen_values = true)]
    pub kp: Option<String>,
    /// Derivative gains: one value for all joints or one per joint.
    #[arg(long, allow_hyphen_values = true)]
    pub kd: Option<String>,
    /// Direct model of a tree robot (closed chains always use A_cl, H_cl of 10.46–10.48).
    #[arg(long, value_enum, default_value = "aba")]
    pub method: MethodArg,
    /// Simulate the Coulomb friction as Fs tanh(qd / V) instead of Fs sign(qd) (V in rad/s or
    /// m/s; 0 = exact sign, which makes sticking joints chatter and the steps collapse).
    #[arg(long, default_value_t = 0.01, value_name = "V")]
    pub coulomb_smoothing: f64,
    /// Stop after this many integration steps.
    #[arg(long, default_value_t = 5_000_000)]
    pub max_steps: usize,
    /// Trajectory CSV: t, q<j>, qd<j>, qdd<j>, tau<j>, energy (closed chains: then
    /// closure_residual and the passive q<j>).
    #[arg(long)]
    pub output: PathBuf,
    /// SVG plot of the joint positions and the total energy.
    #[arg(long)]
    pub plot: Option<PathBuf>,
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

/// Column indices of `<prefix><j>` for every joint and prefix, in order; an optional prefix
/// whose columns are all absent is skipped (the flag says whether all optional ones were found).
fn series_columns(
    t: &Table,
    prefixes: &[(&str, bool)],
    joints: &[usize],
) -> CliResult<(Vec<usize>, bool)> {
    let mut cols = Vec::new();
    let mut all_optional_present = true;
    for (prefix, optional) in prefixes {
        let present: Vec<Option<usize>> = joints
            .iter()
            .map(|j| t.find(&format!("{prefix}{j}")))
            .collect();
        if *optional && present.iter().all(Option::is_none) {
            all_optional_present = false;
            continue;
        }
        for j in joints {
            cols.push(t.column(&format!("{prefix}{j}"))?);
        }
    }
    Ok((cols, all_optional_present))
}

fn read_series(
    path: &std::path::Path,
    prefixes: &[(&str, bool)],
    joints: &[usize],
) -> CliResult<(TimeSeries, bool)> {
    let t = Table::read(path)?;
    let tc = t.column("t")?;
    let (cols, with_optional) = series_columns(&t, prefixes, joints)?;
    let times = t.rows.iter().map(|r| r[tc]).collect();
    let values = t
        .rows
        .iter()
        .map(|r| cols.iter().map(|&c| r[c]).collect())
        .collect();
    let s = TimeSeries::new(times, values).map_err(|e| format!("{}: {e}", t.file))?;
    Ok((s, with_optional))
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    if !(a.coulomb_smoothing.is_finite() && a.coulomb_smoothing >= 0.0) {
        return Err("--coulomb-smoothing must be a finite number >= 0".into());
    }
    let smoothing = Some(a.coulomb_smoothing);
    let (mut dynamics, joints, what, q0_default): (Box<dyn Dynamics + '_>, _, _, _) =
        if robot.is_tree() {
            let d = TreeDynamics::new(&robot, a.method.into()).with_coulomb_smoothing(smoothing);
            let joints = d.joints().to_vec();
            (Box::new(d), joints, "movable tree joints", None)
        } else {
            let chain = robodyn::ClosedChain::new(&robot)?;
            let branch = chain.assembly_branch().map_err(|e| {
                format!(
                    "the simulation starts on the branch of the assembly configuration, which \
                     cannot be used: {e}"
                )
            })?;
            let q0 = branch.q_a().to_vec();
            let d = ClosedChainDynamics::new(chain, branch).with_coulomb_smoothing(smoothing);
            let joints = d.chain().coordinates().frames().to_vec();
            (
                Box::new(d),
                joints,
                "actuated joints (closed chain)",
                Some(q0),
            )
        };
    let n = joints.len();
    if n == 0 {
        return Err("the robot has no movable joint: nothing to simulate".into());
    }
    let q0 = joint_values("q0", a.q0.as_deref(), &joints, what, q0_default.as_deref())?;
    let qd0 = joint_values("qd0", a.qd0.as_deref(), &joints, what, None)?;
    let input = if let Some(p) = &a.torque_csv {
        TorqueInput::Series(read_series(p, &[("tau", false)], &joints)?.0)
    } else if let Some(p) = &a.track {
        let (reference, with_velocity) = read_series(p, &[("q", false), ("qd", true)], &joints)?;
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
            &joints,
            what,
            None,
        )?)
    };
    let integrator = match a.dt {
        Some(dt) => Integrator::Rk4 { dt },
        None => Integrator::Dopri5 {
            rtol: a.rtol,
            atol: a.atol,
            h0: None,
            h_max: None,
        },
    };
    let opts = SimOptions {
        duration: a.duration,
        integrator,
        output_dt: a.output_step.or(a.dt).unwrap_or(0.01),
        max_steps: Some(a.max_steps),
    };
    let mut csv = CsvSink::create(&a.output)?;
    let mut rec = Recorder::default();
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
    let duration = a.duration;
    let mut progress = |t: f64| {
        bar.set_position(((t / duration) * 1000.0).round() as u64);
        bar.set_message(format!("{t:.3}"));
    };
    let result = if a.plot.is_some() {
        simulate(
            dynamics.as_mut(),
            &input,
            &q0,
            &qd0,
            &opts,
            &mut Tee(&mut csv, &mut rec),
            &mut progress,
        )
    } else {
        simulate(
            dynamics.as_mut(),
            &input,
            &q0,
            &qd0,
            &opts,
            &mut csv,
            &mut progress,
        )
    };
    bar.finish_and_clear();
    drop(csv);
    let plotted = match (&a.plot, &result) {
        (Some(p), _) if !rec.rows.is_empty() => Some(plot_svg(p, &rec)),
        _ => None,
    };
    match result {
        Ok(s) => {
            eprintln!(
                "simulated {} s: {} rows in {}, {} steps ({} rejected), {} model evaluations",
                s.t_end,
                s.rows,
                a.output.display(),
                s.stats.accepted,
                s.stats.rejected,
                s.stats.evaluations
            );
            if let Some(r) = plotted {
                r?;
            }
            Ok(())
        }
        Err(e) => Err(format!(
            "{e}\n  the trajectory computed up to the stop is in {}{}",
            a.output.display(),
            match (&a.plot, plotted) {
                (Some(p), Some(Ok(()))) => format!(", its plot in {}", p.display()),
                _ => String::new(),
            }
        )
        .into()),
    }
}
