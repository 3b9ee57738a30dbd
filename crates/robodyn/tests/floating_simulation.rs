//! Simulation of floating-base robots: the base pose integrated on the group (its quaternion
//! unit to rounding, never renormalized), checked against the laws a free body obeys, which the
//! simulator does not use: with no external force but gravity, the centre of mass follows the
//! parabola of its initial position and velocity, the linear momentum grows by M g t, the
//! angular momentum about the centre of mass stays constant, and without friction the energy is
//! conserved; and the quaternion columns agree with the base angular velocity.

use robodyn::model::{LinkDesc, Robot};
use robodyn::simulation::{simulate, Integrator, Recorder, SimOptions, TorqueInput, TreeDynamics};
use robodyn::Expr;
use robodyn::Method;
use robodyn_testing::{random_inertial, random_tree_description, rng, TreeOptions};

/// A random floating tree: `n` links on a random base body, no friction, no wrenches.
fn floating_tree(seed: u64, n: usize, gravity: [f64; 3]) -> Robot {
    let mut r = rng(seed);
    let opt = TreeOptions {
        friction: false,
        wrenches: false,
        // no link fixed on the base: the base body is link 0 alone
        p_fixed: 0.0,
        gravity: Some(gravity),
        ..TreeOptions::default()
    };
    let mut desc = random_tree_description(&mut r, n, &opt);
    let mut base = LinkDesc::zero("base");
    for (k, v) in random_inertial(&mut r).iter().enumerate() {
        base.params[k] = Expr::num(*v);
    }
    desc.floating_base = Some(base);
    Robot::new(desc).unwrap()
}

/// A state with a spinning base and moving joints.
fn initial_state(robot: &Robot, seed: u64) -> (Vec<f64>, Vec<f64>) {
    use rand::Rng;
    let mut r = rng(seed);
    let n = robot.dof();
    let quat = nalgebra::UnitQuaternion::from_scaled_axis(nalgebra::Vector3::new(0.3, -0.5, 0.8));
    let c = quat.quaternion().coords;
    let mut q = vec![0.2, -0.1, 1.5, c[0], c[1], c[2], c[3]];
    q.extend((0..n).map(|_| r.random_range(-1.0..1.0)));
    let mut v = vec![0.4, -0.3, 1.0, 2.0, -3.0, 4.0];
    v.extend((0..n).map(|_| r.random_range(-1.0..1.0)));
    (q, v)
}

fn run(robot: &Robot, q0: &[f64], v0: &[f64], duration: f64) -> Recorder {
    let mut dynamics = TreeDynamics::new(robot, Method::ArticulatedBody);
    let opts = SimOptions {
        duration,
        integrator: Integrator::Dopri5 {
            rtol: 1e-11,
            atol: 1e-12,
            h0: None,
            h_max: None,
        },
        output_dt: 0.01,
        max_steps: None,
    };
    let mut rec = Recorder::default();
    let input = TorqueInput::Constant(vec![0.0; robot.nv()]);
    simulate(&mut dynamics, &input, q0, v0, &opts, &mut rec, &mut |_| {}).unwrap();
    rec
}

fn col(rec: &Recorder, name: &str) -> Vec<f64> {
    rec.series(name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// Largest |x - first|, over a series.
fn drift(x: &[f64]) -> f64 {
    x.iter().map(|v| (v - x[0]).abs()).fold(0.0, f64::max)
}

#[test]
fn free_fall_follows_the_laws_of_a_free_body() {
    let g = [0.0, 0.0, -9.81];
    for seed in 0..4u64 {
        let robot = floating_tree(40 + seed, 3 + seed as usize, g);
        let (q0, v0) = initial_state(&robot, seed);
        let duration = 1.5;
        let rec = run(&robot, &q0, &v0, duration);
        let t = col(&rec, "t");
        // M from the momentum's change (dP/dt = M g) against the sum of the links' and the
        // base's masses
        let m = col(&rec, "momentum_z");
        let mass = (m[m.len() - 1] - m[0]) / (g[2] * duration);
        let total: f64 = (1..=robot.nl())
            .map(|j| robot.numeric().link(j).mass)
            .sum::<f64>()
            + robot.floating_base().unwrap().body.mass;
        assert!(
            (mass - total).abs() < 1e-8 * total,
            "seed {seed}: {mass} vs {total}"
        );
        for (axis, gk) in ["x", "y", "z"].iter().zip(g) {
            let p = col(&rec, &format!("momentum_{axis}"));
            let c = col(&rec, &format!("com_{axis}"));
            let (c0, vc0) = (c[0], p[0] / total);
            for (k, tk) in t.iter().enumerate() {
                // linear momentum P0 + M g t; centre of mass on the parabola
                let pe = p[0] + total * gk * tk;
                assert!(
                    (p[k] - pe).abs() < 1e-7 * (1.0 + pe.abs()),
                    "seed {seed} P{axis}({tk}) {} vs {pe}",
                    p[k]
                );
                let ce = c0 + vc0 * tk + 0.5 * gk * tk * tk;
                assert!(
                    (c[k] - ce).abs() < 1e-7,
                    "seed {seed} c{axis}({tk}) {} vs {ce}",
                    c[k]
                );
            }
            let l = col(&rec, &format!("angular_momentum_{axis}"));
            assert!(
                drift(&l) < 1e-7 * (1.0 + l[0].abs()),
                "seed {seed} L{axis} drifts {}",
                drift(&l)
            );
        }
        let e = col(&rec, "energy");
        assert!(
            drift(&e) < 1e-7 * (1.0 + e[0].abs()),
            "seed {seed}: energy drifts {}",
            drift(&e)
        );
        // the quaternion is unit on every row, without renormalization
        let qn: Vec<f64> = (0..t.len())
            .map(|k| {
                ["x", "y", "z", "w"]
                    .iter()
                    .map(|a| col(&rec, &format!("base_q{a}"))[k].powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .collect();
        assert!(
            qn.iter().all(|n| (n - 1.0).abs() < 1e-14),
            "quaternion norms {qn:?}"
        );
    }
}

/// Gravity off, a fast spin (several turns, so the chart of the base orientation moves many
/// times): momentum and energy conserved, and the quaternion columns differentiate to the
/// base angular velocity columns.
#[test]
fn spinning_robot_conserves_momentum_and_its_quaternion_follows_the_angular_velocity() {
    let robot = floating_tree(77, 5, [0.0; 3]);
    let (q0, mut v0) = initial_state(&robot, 9);
    v0[3..6].copy_from_slice(&[6.0, -4.0, 5.0]);
    let rec = run(&robot, &q0, &v0, 2.0);
    for name in [
        "momentum_x",
        "momentum_y",
        "momentum_z",
        "angular_momentum_x",
        "angular_momentum_y",
        "angular_momentum_z",
        "energy",
    ] {
        let x = col(&rec, name);
        assert!(
            drift(&x) < 1e-7 * (1.0 + x[0].abs()),
            "{name} drifts {}",
            drift(&x)
        );
    }
    // turned by more than 2 pi in total (the chart moved)
    let w: Vec<f64> = (0..rec.rows.len())
        .map(|k| {
            ["x", "y", "z"]
                .iter()
                .map(|a| col(&rec, &format!("base_w{a}"))[k].powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let turned: f64 = w.iter().map(|w| w * 0.01).sum();
    assert!(turned > 2.0 * std::f64::consts::PI, "turned {turned} rad");
    // q_dot = 1/2 q (0, w): central differences of the quaternion columns at the output rate
    let quat = |k: usize| {
        let c = |a: &str| col(&rec, &format!("base_q{a}"))[k];
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            c("w"),
            c("x"),
            c("y"),
            c("z"),
        ))
    };
    let mut worst: f64 = 0.0;
    for k in 1..rec.rows.len() - 1 {
        let body = (quat(k).inverse() * quat(k + 1)).scaled_axis()
            - (quat(k).inverse() * quat(k - 1)).scaled_axis();
        let body = body / 0.02;
        let wk = nalgebra::Vector3::new(
            col(&rec, "base_wx")[k],
            col(&rec, "base_wy")[k],
            col(&rec, "base_wz")[k],
        );
        worst = worst.max((body - wk).norm() / wk.norm());
    }
    // central differences over 0.01 s: truncation error ~ (w h)^2 / 6 relative
    assert!(
        worst < 2e-2,
        "quaternion vs angular velocity: worst relative {worst}"
    );
}

/// A floating robot's trajectory names its base columns.
#[test]
fn trajectory_columns_name_the_base() {
    let robot = floating_tree(5, 2, [0.0, 0.0, -9.81]);
    let dynamics = TreeDynamics::new(&robot, Method::Composite);
    let h = robodyn::simulation::trajectory_headers(&dynamics);
    let joints: Vec<String> = robot
        .coordinates()
        .frames()
        .iter()
        .map(|j| j.to_string())
        .collect();
    let mut expected: Vec<String> = [
        "t", "base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw",
    ]
    .map(String::from)
    .to_vec();
    expected.extend(joints.iter().map(|j| format!("q{j}")));
    assert_eq!(&h[..expected.len()], &expected[..]);
    assert!(h.contains(&"base_wz".to_string()) && h.contains(&"base_dwz".to_string()));
    assert!(h.contains(&"base_mz".to_string()) && h.contains(&"angular_momentum_z".to_string()));
}

/// A [`robodyn::simulation::Wrapper`] that overrides nothing is the system it wraps: the same
/// trajectory, every column and row bit for bit, for a floating base whose pose is integrated
/// in a chart (the chart calls reach the inner system through the wrapper), and the same
/// columns; one that overrides `accel` to add a base wrench changes the motion.
#[test]
fn a_wrapper_is_the_system_it_wraps() {
    use robodyn::simulation::{Dynamics, Wrapper};
    struct Plain<'a>(TreeDynamics<'a>);
    impl Wrapper for Plain<'_> {
        fn inner(&self) -> &dyn Dynamics {
            &self.0
        }
        fn inner_mut(&mut self) -> &mut dyn Dynamics {
            &mut self.0
        }
    }
    struct Pushed<'a>(TreeDynamics<'a>);
    impl Wrapper for Pushed<'_> {
        fn inner(&self) -> &dyn Dynamics {
            &self.0
        }
        fn inner_mut(&mut self) -> &mut dyn Dynamics {
            &mut self.0
        }
        fn accel(
            &mut self,
            t: f64,
            q: &[f64],
            qd: &[f64],
            tau: &[f64],
            qdd: &mut [f64],
        ) -> robodyn::Result<()> {
            let mut pushed = tau.to_vec();
            pushed[0] += 500.0;
            self.0.accel(t, q, qd, &pushed, qdd)
        }
    }
    let robot = floating_tree(11, 4, [0.0, 0.0, -9.81]);
    let (q0, v0) = initial_state(&robot, 12);
    let opts = SimOptions {
        duration: 0.3,
        integrator: Integrator::Dopri5 {
            rtol: 1e-9,
            atol: 1e-10,
            h0: None,
            h_max: None,
        },
        output_dt: 0.01,
        max_steps: None,
    };
    let input = TorqueInput::Constant(vec![0.0; robot.nv()]);
    let go = |d: &mut dyn Dynamics| {
        let mut rec = Recorder::default();
        simulate(d, &input, &q0, &v0, &opts, &mut rec, &mut |_| {}).unwrap();
        rec
    };
    let plain = go(&mut TreeDynamics::new(&robot, Method::ArticulatedBody));
    let wrapped = go(&mut Plain(TreeDynamics::new(
        &robot,
        Method::ArticulatedBody,
    )));
    let pushed = go(&mut Pushed(TreeDynamics::new(
        &robot,
        Method::ArticulatedBody,
    )));
    assert_eq!(plain.headers, wrapped.headers);
    assert!(plain.rows.len() > 20, "{} rows", plain.rows.len());
    assert_eq!(
        plain.rows, wrapped.rows,
        "the wrapper changed the trajectory"
    );
    let x = |r: &Recorder| r.series("base_x").unwrap();
    let moved = x(&pushed).last().unwrap() - x(&plain).last().unwrap();
    assert!(moved.abs() > 1e-3, "the pushed base moved by {moved} more");
}
