//! Simulation: integrator orders on an ODE with known solution, energy conservation and
//! dissipation, power balance, inputs, partial output of diverging runs, the SVG plot.

use robodyn::algorithms::direct_dynamics::Method;
use robodyn::algorithms::energy::{kinetic_energy, potential_energy};
use robodyn::model::param;
use robodyn::simulation::{
    plot_svg, simulate, CsvSink, Dynamics, Integrator, Ode, Recorder, SimOptions, Stepper,
    TimeSeries, TorqueInput, TreeDynamics,
};
use robodyn::{Error, Expr, Robot};
use robodyn_testing::{random_state, random_tree_description, rng, TreeOptions};
use std::path::PathBuf;

/// y0' = y1, y1' = -y0: y = [cos t, -sin t].
struct Oscillator;
impl Ode for Oscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> robodyn::Result<()> {
        dy[0] = y[1];
        dy[1] = -y[0];
        Ok(())
    }
}

fn oscillator_error(y: &[f64], t: f64) -> f64 {
    (y[0] - t.cos()).abs().max((y[1] + t.sin()).abs())
}

fn fixed_step_error(dopri: bool, h: f64, t_end: f64) -> f64 {
    let mut st = Stepper::new(Integrator::Rk4 { dt: h }, 2);
    let mut y = vec![1.0, 0.0];
    let steps = (t_end / h).round() as usize;
    for s in 0..steps {
        let t = s as f64 * h;
        if dopri {
            st.dopri5_step(&mut Oscillator, t, &y, h).unwrap();
            y.copy_from_slice(st.y_new());
        } else {
            st.rk4_step(&mut Oscillator, t, &mut y, h).unwrap();
        }
    }
    oscillator_error(&y, t_end)
}

#[test]
fn rk4_converges_with_order_four() {
    let e: Vec<f64> = [0.2, 0.1, 0.05]
        .iter()
        .map(|&h| fixed_step_error(false, h, 4.0))
        .collect();
    for w in e.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((3.8..4.2).contains(&order), "RK4 order {order} ({e:?})");
    }
}

#[test]
fn dopri5_converges_with_order_five_and_estimates_its_error() {
    let e: Vec<f64> = [0.4, 0.2, 0.1]
        .iter()
        .map(|&h| fixed_step_error(true, h, 4.0))
        .collect();
    for w in e.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((4.7..5.5).contains(&order), "DOPRI5 order {order} ({e:?})");
    }
    // the embedded estimate is a local error of order 5 (embedded 4th-order method)
    let local = |h: f64| {
        let mut st = Stepper::new(Integrator::Rk4 { dt: h }, 2);
        st.dopri5_step(&mut Oscillator, 0.3, &[0.3f64.cos(), -0.3f64.sin()], h)
            .unwrap();
        st.error()[0].abs().max(st.error()[1].abs())
    };
    let order = (local(0.2) / local(0.1)).log2();
    assert!((4.6..5.4).contains(&order), "local error order {order}");
}

#[test]
fn dopri5_adaptive_meets_its_tolerance() {
    let mut prev = f64::INFINITY;
    for tol in [1e-5, 1e-8, 1e-11] {
        let integ = Integrator::Dopri5 {
            rtol: tol,
            atol: tol,
            h0: None,
            h_max: None,
        };
        let mut st = Stepper::new(integ, 2);
        let (mut t, mut y) = (0.0, vec![1.0, 0.0]);
        st.advance(&mut Oscillator, &mut t, &mut y, 10.0).unwrap();
        assert_eq!(t, 10.0);
        let e = oscillator_error(&y, 10.0);
        assert!(e < 100.0 * tol, "tol {tol}: error {e}");
        assert!(e < prev);
        prev = e;
    }
}

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("robodyn-sim-{}-{name}", std::process::id()))
}

/// A random 6-joint tree without wrenches; friction as asked (viscous only), moving base off.
fn robot6(seed: u64, viscous: bool) -> Robot {
    let mut r = rng(seed);
    let opt = TreeOptions {
        friction: viscous,
        wrenches: false,
        ..TreeOptions::default()
    };
    let mut d = random_tree_description(&mut r, 6, &opt);
    for l in d.links.iter_mut() {
        l.params[param::FS] = Expr::zero();
    }
    Robot::new(d).unwrap()
}

fn dopri(tol: f64) -> Integrator {
    Integrator::Dopri5 {
        rtol: tol,
        atol: tol,
        h0: None,
        h_max: None,
    }
}

fn run_recorded(
    robot: &Robot,
    method: Method,
    input: &TorqueInput,
    q0: &[f64],
    qd0: &[f64],
    opts: &SimOptions,
) -> Recorder {
    let mut dynm = TreeDynamics::new(robot, method);
    let mut rec = Recorder::default();
    simulate(&mut dynm, input, q0, qd0, opts, &mut rec, &mut |_| {}).unwrap();
    rec
}

fn initial_state(robot: &Robot, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let n = robot.movable_joints().len();
    let [q, qd, _] = random_state(&mut rng(seed), n);
    (q, qd.iter().map(|x| 0.5 * x).collect())
}

/// No friction, no torque, gravity on: total energy over 10 s of RK45 drifts < 1e-6 relative.
#[test]
fn energy_is_conserved_without_friction() {
    for (seed, method) in [(31, Method::ArticulatedBody), (32, Method::Composite)] {
        let robot = robot6(seed, false);
        let (q0, qd0) = initial_state(&robot, seed + 100);
        let n = q0.len();
        let opts = SimOptions {
            duration: 10.0,
            integrator: dopri(1e-11),
            output_dt: 0.05,
            max_steps: None,
        };
        let rec = run_recorded(
            &robot,
            method,
            &TorqueInput::Constant(vec![0.0; n]),
            &q0,
            &qd0,
            &opts,
        );
        let e = rec.series("energy").unwrap();
        assert_eq!(e.len(), 201);
        // scale: the largest kinetic energy reached (potential energy has an arbitrary origin)
        let mut tmax: f64 = 0.0;
        for row in &rec.rows {
            let (q, qd) = (&row[1..1 + n], &row[1 + n..1 + 2 * n]);
            tmax = tmax.max(kinetic_energy(&robot, q, qd).unwrap());
        }
        let scale = e[0].abs().max(tmax);
        let drift = e.iter().fold(0.0f64, |a, x| a.max((x - e[0]).abs())) / scale;
        eprintln!("{method:?}: relative energy drift over 10 s: {drift:e} (scale {scale})");
        assert!(drift < 1e-6, "{method:?}: drift {drift:e}");
        assert!(
            tmax > 1e-3,
            "the robot must move for the test to mean something"
        );
    }
}

/// Viscous friction, no torque: the energy decreases at every output step.
#[test]
fn energy_decreases_with_viscous_friction() {
    let robot = robot6(33, true);
    let (q0, qd0) = initial_state(&robot, 133);
    let n = q0.len();
    let opts = SimOptions {
        duration: 5.0,
        integrator: dopri(1e-10),
        output_dt: 0.01,
        max_steps: None,
    };
    let rec = run_recorded(
        &robot,
        Method::ArticulatedBody,
        &TorqueInput::Constant(vec![0.0; n]),
        &q0,
        &qd0,
        &opts,
    );
    let e = rec.series("energy").unwrap();
    let scale = e.iter().fold(1.0f64, |a, x| a.max(x.abs()));
    for (k, w) in e.windows(2).enumerate() {
        assert!(
            w[1] <= w[0] + 1e-9 * scale,
            "step {k}: {} -> {}",
            w[0],
            w[1]
        );
    }
    assert!(
        e[0] - e[e.len() - 1] > 1e-3 * scale,
        "friction must dissipate energy"
    );
}

/// dE/dt = tau' qd - Fv qd' qd along a PD-tracking run with viscous friction: the energy change
/// between output points equals the trapezoid of the power up to the trapezoid error
/// dt^3/12 max|P''| (P'' from second differences) plus the integration tolerance.
#[test]
fn power_balance_along_the_trajectory() {
    let robot = robot6(34, true);
    let joints = robot.movable_joints();
    let n = joints.len();
    let (q0, qd0) = initial_state(&robot, 134);
    let fv: Vec<f64> = joints.iter().map(|&j| robot.numeric().link(j).fv).collect();
    // reference: q_ref(t) = q0 + 0.5 sin(2 t), qd_ref = cos(2 t), sampled every 0.05 s (the
    // torque is then continuous in t; its kinks at the samples fall on output points)
    let times: Vec<f64> = (0..=80).map(|k| k as f64 * 0.05).collect();
    let values = times
        .iter()
        .map(|t| {
            let mut v: Vec<f64> = q0.iter().map(|q| q + 0.5 * (2.0 * t).sin()).collect();
            v.extend(std::iter::repeat_n((2.0 * t).cos(), n));
            v
        })
        .collect();
    let input = TorqueInput::Pd {
        reference: TimeSeries::new(times, values).unwrap(),
        with_velocity: true,
        kp: vec![40.0; n],
        kd: vec![4.0; n],
    };
    let dt = 0.005;
    let opts = SimOptions {
        duration: 3.0,
        integrator: dopri(1e-11),
        output_dt: dt,
        max_steps: None,
    };
    let rec = run_recorded(&robot, Method::Composite, &input, &q0, &qd0, &opts);
    let power: Vec<f64> = rec
        .rows
        .iter()
        .map(|r| {
            (0..n)
                .map(|k| {
                    let qd = r[1 + n + k];
                    let tau = r[1 + 3 * n + k];
                    tau * qd - fv[k] * qd * qd
                })
                .sum()
        })
        .collect();
    let e = rec.series("energy").unwrap();
    let pscale = power.iter().fold(1.0f64, |a, x| a.max(x.abs()));
    let escale = e.iter().fold(1.0f64, |a, x| a.max(x.abs()));
    let mut worst: f64 = 0.0;
    for k in 1..e.len() - 2 {
        let de = e[k + 1] - e[k];
        let trap = 0.5 * dt * (power[k] + power[k + 1]);
        // |P''| bound from second differences around the interval
        let p2 = [k, k + 1]
            .iter()
            .map(|&i| (power[i + 1] - 2.0 * power[i] + power[i - 1]).abs() / (dt * dt))
            .fold(0.0f64, f64::max);
        let tol = 2.0 * dt.powi(3) / 12.0 * p2 + 1e-8 * escale + 1e-12 * pscale;
        worst = worst.max((de - trap).abs() / tol);
        assert!(
            (de - trap).abs() <= tol,
            "t = {}: dE = {de}, power integral {trap}, tol {tol}",
            rec.rows[k][0]
        );
    }
    eprintln!("power balance: worst |dE - int P| / tol = {worst}");
}

/// RK4 and DOPRI5 give the same trajectory (two integrators, two direct methods).
#[test]
fn rk4_and_dopri5_agree_on_a_robot() {
    let robot = robot6(35, true);
    let (q0, qd0) = initial_state(&robot, 135);
    let n = q0.len();
    let input = TorqueInput::Constant((0..n).map(|k| k as f64 - 1.0).collect());
    let mk = |integrator| SimOptions {
        duration: 1.0,
        integrator,
        output_dt: 0.1,
        max_steps: None,
    };
    let a = run_recorded(
        &robot,
        Method::Composite,
        &input,
        &q0,
        &qd0,
        &mk(Integrator::Rk4 { dt: 1e-3 }),
    );
    let b = run_recorded(
        &robot,
        Method::ArticulatedBody,
        &input,
        &q0,
        &qd0,
        &mk(dopri(1e-10)),
    );
    assert_eq!(a.rows.len(), 11);
    assert_eq!(b.rows.len(), 11);
    for (ra, rb) in a.rows.iter().zip(&b.rows) {
        assert_eq!(ra[0], rb[0]);
        for c in 1..1 + 2 * n {
            assert!(
                (ra[c] - rb[c]).abs() <= 1e-6 * (1.0 + rb[c].abs()),
                "t = {} column {}: {} vs {}",
                ra[0],
                a.headers[c],
                ra[c],
                rb[c]
            );
        }
    }
}

#[test]
fn time_series_interpolates_and_validates() {
    let s = TimeSeries::new(
        vec![0.0, 1.0, 3.0],
        vec![vec![0.0, 1.0], vec![2.0, 1.0], vec![6.0, -1.0]],
    )
    .unwrap();
    let mut out = [0.0; 2];
    s.sample(0.5, 0..2, &mut out);
    assert_eq!(out, [1.0, 1.0]);
    s.sample(2.0, 0..2, &mut out);
    assert_eq!(out, [4.0, 0.0]);
    s.sample(-1.0, 0..2, &mut out);
    assert_eq!(out, [0.0, 1.0]);
    s.sample(7.0, 0..2, &mut out);
    assert_eq!(out, [6.0, -1.0]);
    s.slope(2.0, 0..2, &mut out);
    assert_eq!(out, [2.0, -1.0]);
    assert!(TimeSeries::new(vec![0.0, 0.0], vec![vec![1.0], vec![2.0]]).is_err());
    assert!(TimeSeries::new(vec![0.0, 1.0], vec![vec![1.0], vec![2.0, 3.0]]).is_err());
    assert!(TimeSeries::new(vec![], vec![]).is_err());
    // PD with an explicit velocity reference
    let pd = TorqueInput::Pd {
        reference: TimeSeries::new(vec![0.0, 1.0], vec![vec![1.0, 0.5], vec![3.0, 0.5]]).unwrap(),
        with_velocity: true,
        kp: vec![10.0],
        kd: vec![2.0],
    };
    let mut tau = [0.0];
    pd.torque(0.5, &[1.5], &[0.25], &mut tau);
    assert_eq!(tau[0], 10.0 * (2.0 - 1.5) + 2.0 * (0.5 - 0.25));
    assert!(pd.validate(2).is_err());
}

/// A system with q'' = q^2 blows up in finite time (q0 = 1, qd0 = 0: t* ~ 2.97).
struct BlowUp;
impl Dynamics for BlowUp {
    fn dof(&self) -> usize {
        1
    }
    fn labels(&self) -> Vec<String> {
        vec!["1".into()]
    }
    fn accel(
        &mut self,
        _t: f64,
        q: &[f64],
        _: &[f64],
        _: &[f64],
        qdd: &mut [f64],
    ) -> robodyn::Result<()> {
        qdd[0] = q[0] * q[0];
        Ok(())
    }
    fn energy(&mut self, q: &[f64], qd: &[f64]) -> robodyn::Result<f64> {
        Ok(0.5 * qd[0] * qd[0] - q[0].powi(3) / 3.0)
    }
    fn extra_columns(&self) -> Vec<String> {
        vec!["q_squared".into()]
    }
    fn extra_values(&mut self, q: &[f64], _: &[f64], out: &mut [f64]) -> robodyn::Result<()> {
        out[0] = q[0] * q[0];
        Ok(())
    }
}

#[test]
fn diverging_simulation_stops_and_keeps_the_csv() {
    for (name, integrator) in [
        ("rk4", Integrator::Rk4 { dt: 0.01 }),
        ("dopri", dopri(1e-8)),
    ] {
        let path = tmp(&format!("blowup-{name}.csv"));
        let mut sink = CsvSink::create(&path).unwrap();
        let opts = SimOptions {
            duration: 10.0,
            integrator,
            output_dt: 0.1,
            max_steps: None,
        };
        let err = simulate(
            &mut BlowUp,
            &TorqueInput::Constant(vec![0.0]),
            &[1.0],
            &[0.0],
            &opts,
            &mut sink,
            &mut |_| {},
        )
        .unwrap_err();
        drop(sink);
        let msg = err.to_string();
        assert!(matches!(err, Error::Numerical(_)), "{name}: {msg}");
        assert!(
            msg.starts_with("simulation stopped at t = "),
            "{name}: {msg}"
        );
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "t,q1,qd1,qdd1,tau1,energy,q_squared");
        // rows up to about the blow-up time t* = 2.974 are kept (a fixed-step scheme may
        // overshoot t* by a few output steps before its state overflows)
        eprintln!("{name}: {msg}; {} lines", lines.len());
        assert!(
            lines.len() >= 25 && lines.len() <= 40,
            "{name}: {} lines",
            lines.len()
        );
        let last: Vec<f64> = lines[lines.len() - 1]
            .split(',')
            .map(|x| x.parse().unwrap())
            .collect();
        assert!(last.iter().all(|x| x.is_finite()));
        assert!(last[0] > 2.0 && last[0] < 3.8, "{name}: last t {}", last[0]);
        std::fs::remove_file(&path).ok();
    }
}

/// A massless chain end: the simulation stops at t = 0 naming the joint.
#[test]
fn singular_robot_stops_at_once_naming_the_joint() {
    let mut d = random_tree_description(
        &mut rng(36),
        3,
        &TreeOptions {
            p_serial: 1.0,
            p_fixed: 0.0,
            ..TreeOptions::default()
        },
    );
    for k in 0..=param::FV {
        d.links[2].params[k] = Expr::zero();
    }
    let robot = Robot::new(d).unwrap();
    let mut dynm = TreeDynamics::new(&robot, Method::ArticulatedBody);
    let mut rec = Recorder::default();
    let opts = SimOptions {
        duration: 1.0,
        integrator: Integrator::Rk4 { dt: 0.01 },
        output_dt: 0.1,
        max_steps: None,
    };
    let err = simulate(
        &mut dynm,
        &TorqueInput::Constant(vec![0.0; 3]),
        &[0.0; 3],
        &[0.0; 3],
        &opts,
        &mut rec,
        &mut |_| {},
    )
    .unwrap_err();
    let m = err.to_string();
    assert!(
        m.starts_with("simulation stopped at t = 0: ") && m.contains("of joint 3 is singular"),
        "{err}"
    );
    assert!(rec.rows.is_empty());
    assert_eq!(rec.headers[0], "t");
}

#[test]
fn bad_options_are_input_errors() {
    let robot = robot6(37, false);
    let n = robot.movable_joints().len();
    let mut dynm = TreeDynamics::new(&robot, Method::Composite);
    let ok = SimOptions {
        duration: 1.0,
        integrator: Integrator::Rk4 { dt: 0.01 },
        output_dt: 0.1,
        max_steps: None,
    };
    let zero = vec![0.0; n];
    let cases = [
        (
            SimOptions {
                duration: -1.0,
                ..ok
            },
            TorqueInput::Constant(zero.clone()),
            n,
        ),
        (
            SimOptions {
                integrator: Integrator::Rk4 { dt: 0.0 },
                ..ok
            },
            TorqueInput::Constant(zero.clone()),
            n,
        ),
        (
            SimOptions {
                integrator: dopri(-1.0),
                ..ok
            },
            TorqueInput::Constant(zero.clone()),
            n,
        ),
        (ok, TorqueInput::Constant(vec![0.0; n + 1]), n),
        (ok, TorqueInput::Constant(zero.clone()), n + 1),
    ];
    for (opts, input, len) in cases {
        let mut rec = Recorder::default();
        let e = simulate(
            &mut dynm,
            &input,
            &vec![0.0; len],
            &vec![0.0; len],
            &opts,
            &mut rec,
            &mut |_| {},
        );
        assert!(matches!(e, Err(Error::Input(_))), "{e:?}");
    }
}

#[test]
fn energy_parts_match_hand_computation() {
    // one prismatic joint along z0 carrying a point mass: U = -g' (M P + MS), T = 1/2 (M + Ia) qd^2
    let mut d = robodyn::RobotDescription::new("slider", 1, 1);
    d.frame_mut(1).joint = robodyn::model::JointType::Prismatic;
    let l = &mut d.links[0];
    for p in l.params.iter_mut() {
        *p = Expr::zero();
    }
    l.params[param::M] = Expr::num(2.0);
    l.params[param::MZ] = Expr::num(0.6);
    l.params[param::IA] = Expr::num(0.5);
    l.params[param::XX] = Expr::num(0.1);
    l.params[param::YY] = Expr::num(0.1);
    l.params[param::ZZ] = Expr::num(0.1);
    d.gravity = [0.0, 0.0, -9.81].map(Expr::num);
    let robot = Robot::new(d).unwrap();
    let t = kinetic_energy(&robot, &[0.4], &[3.0]).unwrap();
    assert!((t - 0.5 * 2.5 * 9.0).abs() < 1e-12);
    let u = potential_energy(&robot, &[0.4]).unwrap();
    assert!((u - 9.81 * (2.0 * 0.4 + 0.6)).abs() < 1e-12);
    // the simulator's energy column (its own T = 1/2 qd' A qd and U) at t = 0
    let opts = SimOptions {
        duration: 1e-3,
        integrator: Integrator::Rk4 { dt: 1e-3 },
        output_dt: 1e-3,
        max_steps: None,
    };
    let rec = run_recorded(
        &robot,
        Method::Composite,
        &TorqueInput::Constant(vec![0.0]),
        &[0.4],
        &[3.0],
        &opts,
    );
    assert!((rec.series("energy").unwrap()[0] - (t + u)).abs() < 1e-12);
}

#[test]
fn plot_is_written() {
    let robot = robot6(38, true);
    let (q0, qd0) = initial_state(&robot, 138);
    let n = q0.len();
    let opts = SimOptions {
        duration: 0.5,
        integrator: Integrator::Rk4 { dt: 0.005 },
        output_dt: 0.01,
        max_steps: None,
    };
    let rec = run_recorded(
        &robot,
        Method::ArticulatedBody,
        &TorqueInput::Constant(vec![0.0; n]),
        &q0,
        &qd0,
        &opts,
    );
    let path = tmp("plot.svg");
    let info = robodyn::simulation::PlotInfo {
        title: "robot6: zero torques".into(),
        ..Default::default()
    };
    plot_svg(&path, &rec, &info).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg"));
    // drawn at 4x (curves of 2 displayed px are 8 canvas units, axes 4, legend keys 12): one
    // curve per joint plus the energy change
    assert_eq!(svg.matches("stroke-width=\"8\"").count(), n + 1);
    assert!(svg.contains("width=\"1100\""), "displayed size");
    for want in ["robot6: zero torques", "q [rad]", "E - E(0) [J]", "t [s]"] {
        assert!(svg.contains(want), "{want}");
    }
    // a legend entry per joint
    for j in 1..=n {
        assert!(
            svg.lines().any(|l| l.trim() == format!("q{j}")),
            "legend q{j}"
        );
    }
    assert!(!svg.contains("stopped early"));
    let stopped = robodyn::simulation::PlotInfo {
        stopped: Some("simulation stopped at t = 0.5: step size underflow".into()),
        ..info
    };
    plot_svg(&path, &rec, &stopped).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.contains("stopped early at t = 0.5 s: step size underflow"));
    std::fs::remove_file(&path).ok();
    assert!(plot_svg(
        &path,
        &Recorder::default(),
        &robodyn::simulation::PlotInfo::default()
    )
    .is_err());
}

/// Strong Coulomb friction on a robot at rest: with the exact sign the sticking joints chatter
/// and the step budget runs out (an error, not a hang); with tanh smoothing the run completes
/// and the stuck joints barely move.
#[test]
fn coulomb_sticking_needs_smoothing() {
    let mut d = random_tree_description(
        &mut rng(39),
        4,
        &TreeOptions {
            p_fixed: 0.0,
            p_prismatic: 0.0,
            wrenches: false,
            ..TreeOptions::default()
        },
    );
    for l in d.links.iter_mut() {
        l.params[param::FS] = Expr::num(200.0);
    }
    let robot = Robot::new(d).unwrap();
    let opts = SimOptions {
        duration: 1.0,
        integrator: dopri(1e-8),
        output_dt: 0.1,
        max_steps: Some(20_000),
    };
    let input = TorqueInput::Constant(vec![0.0; 4]);
    let mut exact = TreeDynamics::new(&robot, Method::ArticulatedBody);
    let mut rec = Recorder::default();
    let e = simulate(
        &mut exact,
        &input,
        &[0.0; 4],
        &[0.0; 4],
        &opts,
        &mut rec,
        &mut |_| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("max_steps = 20000"), "{e}");
    let mut smooth =
        TreeDynamics::new(&robot, Method::ArticulatedBody).with_coulomb_smoothing(Some(1e-2));
    let mut rec = Recorder::default();
    let s = simulate(
        &mut smooth,
        &input,
        &[0.0; 4],
        &[0.0; 4],
        &opts,
        &mut rec,
        &mut |_| {},
    )
    .unwrap();
    assert_eq!(s.t_end, 1.0);
    let last = rec.rows.last().unwrap();
    // gravity torques are at most a few tens of N m here: the friction (200) holds the joints,
    // the smoothed law lets them creep at |qd| < v = 0.01
    for k in 0..4 {
        assert!(
            last[1 + 4 + k].abs() < 1e-2,
            "qd{} = {}",
            k + 1,
            last[1 + 4 + k]
        );
    }
}
