//! A minimum-effort point-to-point motion of the Franka Emika Panda by direct multiple shooting,
//! solved twice by the same SQP: once with the sensitivities of the dynamics chained from
//! robodyn's analytical derivatives of the direct model (`direct_dynamics_derivatives_into`:
//! dqdd/dq, dqdd/dqd, A^-1), once with finite differences of the same integrator (the solver
//! and why it is an exact-Hessian SQP rather than Gauss–Newton: `shooting.rs` beside this
//! file).
//!
//! The problem: x = (q, qd); commanded torques Gamma_c = Gamma - g(q) (the torque beyond
//! gravity compensation, which the Panda's controller adds itself) constant on K = 40 intervals
//! of T = 1.5 s; F = two RK4 steps of the direct model per interval; minimize
//! 1/2 sum_k sum_j (Gamma_c,kj / Gamma_max,j)^2 dt (effort relative to the joints' torque
//! limits, 87 N m and 12 N m) from the Panda's "ready" pose at rest to a reach pose at rest; the
//! two finger joints are locked closed (the arm's 7 joints move). Converged when every defect
//! is below 1e-8 and the first-order optimality residual below 1e-6.
//!
//! Run (the timings are wall-clock: pin the process to one quiet core):
//!
//! ```text
//! cargo build --release -p robodyn --example optimal_control
//! taskset -c 1 target/release/examples/optimal_control [ROBOT_FILE] [--rounds R] [--svg PATH]
//! ```
//!
//! ROBOT_FILE defaults to example-robot-data's `panda_description/urdf/panda.urdf` (found
//! through `python3 -c "import cmeel"`, installed with `pip install example-robot-data`); the
//! program stops with a message when it is absent. Another fixed-base robot file (e.g.
//! `robots/rx90.toml`) moves from q = 0 to q = 0.6 rad on every revolute joint, 0.05 m on every
//! prismatic one.
//!
//! Prints: the problem, then per sensitivity route the SQP iterations, the median wall-clock
//! time over R paired rounds (default 5; the two routes alternate in each round) with its
//! range, the cost, the largest defect and the first-order optimality residual; the median of
//! the rounds' time ratios; the same for the process's CPU time (Linux, /proc/self/stat: on a
//! shared machine the wall clock also counts the time other processes had the core); the gap between the two solutions; the optimality residual of the
//! analytical solution measured with finite-difference sensitivities (an independent route);
//! the final state reached by the joint torques Gamma_c + g(q) re-simulated with gravity by the
//! articulated-body method with 8x finer RK4 steps; the SQP iterations of the analytical run.
//! Writes the figure of q(t) and Gamma_c(t) as SVG (default `optimal_control.svg`).

mod shooting;

use robodyn::model::JointType;
use robodyn::report::figure::{render, Curve, Figure, Panel, Style};
use robodyn::Robot;
use shooting::{
    initial_guess, resimulate, solve, stationarity, Options, Problem, Res, Sensitivities,
};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The command line: robot file, paired rounds, SVG path.
struct Args {
    robot: Option<PathBuf>,
    rounds: usize,
    svg: PathBuf,
}

fn parse_args() -> Res<Args> {
    let mut a = Args {
        robot: None,
        rounds: 5,
        svg: PathBuf::from("optimal_control.svg"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--rounds" => {
                let v = value("--rounds")?;
                a.rounds = v
                    .parse()
                    .ok()
                    .filter(|&r| r >= 1)
                    .ok_or(format!("--rounds {v}: a whole number >= 1"))?;
            }
            "--svg" => a.svg = PathBuf::from(value("--svg")?),
            s if s.starts_with("--") => return Err(format!("unknown option {s}").into()),
            s => a.robot = Some(PathBuf::from(s)),
        }
    }
    Ok(a)
}

/// example-robot-data's Panda URDF, through the Python package that installs it.
fn default_panda() -> Res<PathBuf> {
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(\
             cmeel.__file__)), 'cmeel.prefix', 'share', 'example-robot-data', 'robots', \
             'panda_description', 'urdf', 'panda.urdf'))",
        ])
        .output();
    let path = match out {
        Ok(o) if o.status.success() => PathBuf::from(String::from_utf8_lossy(&o.stdout).trim()),
        _ => PathBuf::new(),
    };
    if path.is_file() {
        Ok(path)
    } else {
        Err(
            "the Panda URDF of example-robot-data was not found (pip install \
             example-robot-data, or pass a robot file: optimal_control robots/rx90.toml)"
                .into(),
        )
    }
}

/// The problem for `robot`: the Panda's ready pose to a reach pose, else q = 0 to 0.6 rad /
/// 0.05 m on every joint.
fn problem(robot: &Robot) -> Problem {
    let c = robot.coordinates();
    let n = robot.dof();
    let panda = (1..=7).all(|j| c.names().iter().any(|s| s == &format!("panda_joint{j}")));
    let (start, goal): (Vec<f64>, Vec<f64>) = (0..n)
        .map(|k| match (panda, c.name(k)) {
            (true, "panda_joint1") => (0.0, 1.2),
            (true, "panda_joint2") => (-0.785, 0.3),
            (true, "panda_joint3") => (0.0, -0.4),
            (true, "panda_joint4") => (-2.356, -1.6),
            (true, "panda_joint5") => (0.0, 0.3),
            (true, "panda_joint6") => (1.571, 1.9),
            (true, "panda_joint7") => (0.785, 1.1),
            (true, _) => (0.02, 0.02),
            (false, _) if is_prismatic(robot, k) => (0.0, 0.05),
            (false, _) => (0.0, 0.6),
        })
        .unzip();
    Problem {
        x_start: start.into_iter().chain(vec![0.0; n]).collect(),
        q_goal: goal,
        horizon: 1.5,
        intervals: 40,
        substeps: 2,
        weights: (0..n)
            .map(|k| match (panda, c.name(k)) {
                // the Panda's torque limits (URDF `effort`): 87 N m, 12 N m for joints 5-7
                (true, "panda_joint5" | "panda_joint6" | "panda_joint7") => 1.0 / (12.0 * 12.0),
                (true, _) => 1.0 / (87.0 * 87.0),
                _ => 1.0,
            })
            .collect(),
    }
}

/// The robot of `path`; the Panda's two finger joints locked closed (fixed frames at q = 0):
/// the motion is the arm's, and 15 g fingers free to slide would be a stiff, nearly massless
/// part of the linearized dynamics.
fn load_robot(path: &Path) -> Res<Robot> {
    let mut d = robodyn::io::load_description(path)?;
    for f in d.frames.iter_mut() {
        if f.name.starts_with("panda_finger_joint") {
            f.joint = JointType::Fixed;
            f.actuated = false;
        }
    }
    Ok(Robot::new(d)?)
}

fn is_prismatic(robot: &Robot, k: usize) -> bool {
    robot.frame(robot.coordinates().frame(k)).joint == JointType::Prismatic
}

/// One route's runs: the solutions' wall-clock and CPU times (s) and the last solution.
struct Runs {
    how: Sensitivities,
    times: Vec<f64>,
    cpu: Vec<f64>,
    solution: Option<shooting::Solution>,
}

/// The CPU time of this process (user + system, s) from /proc/self/stat (Linux; 10 ms ticks
/// at the usual 100 Hz), or None elsewhere: on a shared machine it is what the process used,
/// where the wall clock also counts the time other processes had the core.
fn cpu_time() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // the fields after the command name (which is in parentheses): utime, stime are 14, 15
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let m = s.len() / 2;
    if s.len() % 2 == 1 {
        s[m]
    } else {
        0.5 * (s[m - 1] + s[m])
    }
}

/// R paired rounds: in each, the analytical and the finite-difference solves back to back.
fn timed_rounds(robot: &Robot, p: &Problem, rounds: usize) -> Res<[Runs; 2]> {
    let mut runs = [Sensitivities::Analytical, Sensitivities::CentralDifferences].map(|how| Runs {
        how,
        times: Vec::new(),
        cpu: Vec::new(),
        solution: None,
    });
    for _ in 0..rounds {
        for r in runs.iter_mut() {
            let (x, u) = initial_guess(robot, p)?;
            let (t, c) = (Instant::now(), cpu_time());
            let sol = solve(robot, p, &Options::new(r.how), x, u)
                .map_err(|e| format!("{} sensitivities: {e}", r.how.name()))?;
            r.times.push(t.elapsed().as_secs_f64());
            if let (Some(c0), Some(c1)) = (c, cpu_time()) {
                r.cpu.push(c1 - c0);
            }
            r.solution = Some(sol);
        }
    }
    Ok(runs)
}

/// The table of the two routes and the ratio of their times.
fn report_runs(robot: &Robot, p: &Problem, runs: &[Runs; 2]) -> Res<()> {
    println!(
        "{:<20} {:>10} {:>26} {:>12} {:>11} {:>13}",
        "sensitivities",
        "iterations",
        "wall-clock median [range]",
        "cost",
        "max defect",
        "stationarity"
    );
    for r in runs {
        let s = r.solution.as_ref().expect("one round at least");
        let lo = r.times.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = r.times.iter().copied().fold(0.0, f64::max);
        let st = stationarity(robot, p, &s.x, &s.u, r.how)?;
        println!(
            "{:<20} {:>10} {:>10.4} s [{:.4}-{:.4}] {:>12.6e} {:>11.1e} {:>13.1e}",
            r.how.name(),
            s.iterations,
            median(&r.times),
            lo,
            hi,
            s.cost,
            s.max_defect,
            st
        );
    }
    let ratios: Vec<f64> = runs[1]
        .times
        .iter()
        .zip(&runs[0].times)
        .map(|(f, a)| f / a)
        .collect();
    println!(
        "finite differences / analytical, wall-clock: {:.2}x (median of {} rounds' ratios)",
        median(&ratios),
        ratios.len()
    );
    if runs.iter().all(|r| r.cpu.len() == r.times.len()) {
        let cpu: Vec<f64> = runs[1]
            .cpu
            .iter()
            .zip(&runs[0].cpu)
            .map(|(f, a)| f / a)
            .collect();
        println!(
            "CPU time (this process), median: analytical {:.2} s, finite differences {:.2} s, \
             ratio {:.2}x (median of the rounds' ratios)",
            median(&runs[0].cpu),
            median(&runs[1].cpu),
            median(&cpu)
        );
    }
    Ok(())
}

/// The checks a user can read: the two solutions' gap, the analytical solution's optimality
/// measured with finite differences, and its torques re-simulated (articulated bodies, 8x finer).
fn report_checks(robot: &Robot, p: &Problem, runs: &[Runs; 2]) -> Res<()> {
    let [a, f] = [&runs[0], &runs[1]].map(|r| r.solution.as_ref().expect("solved"));
    let gap =
        a.u.iter()
            .zip(&f.u)
            .map(|(x, y)| (x - y).amax())
            .fold(0.0, f64::max);
    println!("max |Gamma_analytical - Gamma_differences| = {gap:.2e}");
    let st = stationarity(robot, p, &a.x, &a.u, Sensitivities::CentralDifferences)?;
    println!(
        "analytical solution, optimality residual with finite-difference sensitivities: {st:.1e}"
    );
    let end = resimulate(robot, p, &a.u, 8 * p.substeps)?
        .pop()
        .expect("x_0 at least");
    let miss = (end - p.x_goal()).amax();
    println!(
        "joint torques Gamma_c + g(q) re-simulated with gravity (articulated bodies, RK4 {}x \
         finer): |x(T) - x_goal| = {miss:.1e}",
        8
    );
    println!("SQP iterations (analytical): cost, largest defect, max |dGamma|, step length");
    for (i, h) in a.history.iter().enumerate() {
        println!(
            "  {:>2}  {:>12.6e}  {:>9.2e}  {:>9.2e}  {}",
            i + 1,
            h.cost,
            h.max_defect,
            h.step,
            h.alpha
        );
    }
    Ok(())
}

/// The figure: q(t) at the nodes and the piecewise-constant Gamma(t), revolute and prismatic
/// joints in panels of their own units. Written through a temporary file, then renamed.
fn plot(robot: &Robot, p: &Problem, s: &shooting::Solution, path: &Path, title: String) -> Res<()> {
    let n = robot.dof();
    let dt = p.dt();
    // each interval drawn from its start to its end: Gamma constant, q linear between nodes
    let t: Vec<f64> = (0..p.intervals)
        .flat_map(|k| [k as f64 * dt, (k + 1) as f64 * dt])
        .collect();
    let mut panels = Vec::new();
    for prismatic in [false, true] {
        let joints: Vec<usize> = (0..n)
            .filter(|&k| is_prismatic(robot, k) == prismatic)
            .collect();
        if joints.is_empty() {
            continue;
        }
        let (kind, qu, tu) = if prismatic {
            ("prismatic joints (fingers)", "m", "N")
        } else {
            ("revolute joints", "rad", "N m")
        };
        let label = |k: usize| robot.coordinates().name(k).to_string();
        let q = joints
            .iter()
            .map(|&k| {
                let y = (0..p.intervals)
                    .flat_map(|i| [s.x[i][k], s.x[i + 1][k]])
                    .collect();
                Curve::new(label(k), y, k, Style::Solid)
            })
            .collect();
        let g = joints
            .iter()
            .map(|&k| {
                let y = (0..p.intervals)
                    .flat_map(|i| [s.u[i][k], s.u[i][k]])
                    .collect();
                Curve::new(label(k), y, k, Style::Solid)
            })
            .collect();
        panels.push(Panel {
            title: format!("joint positions q(t), {kind}"),
            y_label: format!("q [{qu}]"),
            curves: q,
            ..Panel::default()
        });
        panels.push(Panel {
            title: format!(
                "commanded torques Gamma_c(t) = Gamma - g(q), constant per interval, {kind}"
            ),
            y_label: format!("Gamma_c [{tu}]"),
            curves: g,
            ..Panel::default()
        });
    }
    let fig = Figure {
        title,
        x_label: "t [s]".into(),
        panels,
        colors: n,
        ..Figure::default()
    };
    let svg = render(&t, &fig)?;
    let tmp = path.with_extension("svg.tmp");
    std::fs::write(&tmp, svg)?;
    std::fs::rename(&tmp, path)?;
    Ok(())
}

fn main() {
    if let Err(e) = run() {
        eprintln!("optimal_control: {e}");
        std::process::exit(1);
    }
}

fn run() -> Res<()> {
    let args = parse_args()?;
    let path = match args.robot {
        Some(p) => p,
        None => default_panda()?,
    };
    let robot = load_robot(&path)?;
    if robot.is_floating() {
        return Err(format!(
            "{}: a floating-base robot; this example needs a fixed base",
            path.display()
        )
        .into());
    }
    let p = problem(&robot);
    println!(
        "{} ({} joints): minimum effort 1/2 sum Gamma_c' W Gamma_c dt (Gamma_c = Gamma - g(q)), \
         K = {} intervals, T = {} s, RK4 with {} steps per interval, from rest to rest",
        robot.name(),
        robot.dof(),
        p.intervals,
        p.horizon,
        p.substeps
    );
    let runs = timed_rounds(&robot, &p, args.rounds)?;
    report_runs(&robot, &p, &runs)?;
    report_checks(&robot, &p, &runs)?;
    let s = runs[0].solution.as_ref().expect("solved");
    let title = format!(
        "{}: minimum-effort motion, direct multiple shooting (K = {}, T = {} s), cost {:.4e}",
        robot.name(),
        p.intervals,
        p.horizon,
        s.cost
    );
    plot(&robot, &p, s, &args.svg, title)?;
    println!("figure: {}", args.svg.display());
    Ok(())
}
