//! Independent cross-checks of the Newton–Euler inverse dynamic model (eqs 10.3–10.12).
//!
//! Route 1 (Lagrangian, §10.2.1): kinetic and potential energy of the tree from the link
//! velocities (10.1–10.2), torques by the Euler–Lagrange equations, derivatives by hyper-dual
//! automatic differentiation (`algorithms::energy`). Route 2 (power balance): for a fixed base,
//! `qd'Gamma_NE = dE/dt + friction power + power delivered to the environment`.
//! Route 3 (kinetic energy as a quadratic form): `T = 1/2 qd' A(q) qd` with the columns of the
//! inertia matrix A obtained from Newton–Euler.
//!
//! Relative error of a torque vector (norm-wise): `rel(x, ref) = ||x - ref||_2 / ||ref||_2`,
//! with `ref` the Newton–Euler torques; every comparison also checks `||ref||_2` is not tiny,
//! so the ratio is meaningful.

use nalgebra::DVector;
use rand::Rng;
use robodyn::algorithms::energy::{
    kinetic_energy, lagrangian_torques, potential_energy, total_energy, total_energy_rate,
    wrench_power,
};
use robodyn::model::JointType;
use robodyn::{inverse_dynamics, inverse_dynamics_into};
use robodyn::{Data, Error, Expr, Robot, RobotDescription};
use robodyn_testing::{self as testing, random_state, random_tree_description, TreeOptions};
use std::path::PathBuf;

/// Tolerance of the Lagrangian vs Newton–Euler comparison (issue 2).
const TOL: f64 = 1e-8;

fn rel(x: &DVector<f64>, reference: &DVector<f64>) -> f64 {
    (x - reference).norm() / reference.norm()
}

fn sr400() -> Robot {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml");
    robodyn::io::load(&path).expect("robots/sr400.toml loads")
}

fn random_vec3<R: Rng>(rng: &mut R, s: f64) -> [Expr; 3] {
    std::array::from_fn(|_| Expr::num(rng.random_range(-s..s)))
}

/// Random tree options: vary the joint mix and topology from robot to robot; random gravity
/// direction, nonzero gamma and b, friction, rotor inertia and external wrenches.
fn random_options<R: Rng>(rng: &mut R) -> TreeOptions {
    TreeOptions {
        p_prismatic: rng.random_range(0.0..0.5),
        p_fixed: rng.random_range(0.0..0.25),
        p_serial: rng.random_range(0.2..1.0),
        general_frames: true,
        friction: true,
        wrenches: true,
        gravity: None,
    }
}

/// Newton–Euler torques with a reused workspace.
fn ne(robot: &Robot, ws: &mut Data, s: &[Vec<f64>; 3]) -> DVector<f64> {
    let mut tau = DVector::zeros(robot.dof());
    inverse_dynamics_into(
        robot,
        ws,
        robot.environment(),
        &s[0],
        &s[1],
        &s[2],
        tau.as_mut_slice(),
    )
    .unwrap();
    tau
}

fn has_movable_joint(robot: &Robot) -> bool {
    !robot.movable_joints().is_empty()
}

/// Lagrangian vs Newton–Euler on 290 random trees of 2..=30 links (10 per size), 3 states each;
/// half of the robots also have a moving base (w0, wp0, v0, vp0 random).
#[test]
fn lagrangian_matches_newton_euler_on_random_trees() {
    let mut rng = testing::rng(0x1a6_2a46e);
    let (mut worst, mut robots, mut states) = (0.0f64, 0, 0);
    let (mut n_prismatic, mut n_fixed, mut n_general) = (0, 0, 0);
    for n in 2..=30 {
        for r in 0..10 {
            let opt = random_options(&mut rng);
            let mut desc = random_tree_description(&mut rng, n, &opt);
            if r % 2 == 1 {
                desc.w0 = random_vec3(&mut rng, 1.0);
                desc.wp0 = random_vec3(&mut rng, 2.0);
                desc.v0 = random_vec3(&mut rng, 1.0);
                desc.vp0 = random_vec3(&mut rng, 2.0);
            }
            let robot = Robot::new(desc).unwrap();
            if !has_movable_joint(&robot) {
                continue;
            }
            for j in 1..=n {
                let f = robot.frame(j);
                n_prismatic += (f.joint == JointType::Prismatic) as usize;
                n_fixed += (f.joint == JointType::Fixed) as usize;
                n_general += (!f.gamma.is_zero() || !f.b.is_zero()) as usize;
            }
            robots += 1;
            let mut ws = Data::new(&robot);
            for _ in 0..3 {
                let s = random_state(&mut rng, robot.dof());
                let tau_ne = ne(&robot, &mut ws, &s);
                let tau_l = lagrangian_torques(&robot, &s[0], &s[1], &s[2]).unwrap();
                assert!(tau_ne.norm() > 1e-3, "degenerate reference torques");
                let e = rel(&tau_l, &tau_ne);
                assert!(
                    e < TOL,
                    "{} ({n} links, base moving: {}): relative error {e:e}\nNE  {tau_ne}\nLag {tau_l}",
                    robot.name(),
                    r % 2 == 1
                );
                worst = worst.max(e);
                states += 1;
            }
        }
    }
    assert!(robots >= 280, "only {robots} robots compared");
    // The sample must exercise every kind of frame.
    assert!(n_prismatic > 100 && n_fixed > 50 && n_general > 500);
    eprintln!(
        "Lagrangian vs NE: {robots} robots, {states} states, max relative error {worst:.2e} \
         ({n_prismatic} prismatic, {n_fixed} fixed, {n_general} frames with gamma/b)"
    );
}

/// The SR400's equivalent tree (links 1..8, cut joint 9 open), default and random states.
#[test]
fn lagrangian_matches_newton_euler_on_sr400_tree() {
    let robot = sr400();
    assert_eq!(robot.nl(), 8);
    let mut rng = testing::rng(400);
    let mut ws = Data::new(&robot);
    let mut worst = 0.0f64;
    for _ in 0..50 {
        let s = random_state(&mut rng, 8);
        let tau_ne = ne(&robot, &mut ws, &s);
        let tau_l = lagrangian_torques(&robot, &s[0], &s[1], &s[2]).unwrap();
        assert!(tau_ne.norm() > 1e-3);
        let e = rel(&tau_l, &tau_ne);
        assert!(e < TOL, "SR400: relative error {e:e}");
        worst = worst.max(e);
    }
    // At rest, only gravity: the convenience wrapper agrees with the reused-workspace path.
    let z = vec![0.0; 8];
    let q: Vec<f64> = (0..8).map(|k| 0.3 * k as f64 - 1.0).collect();
    let tau_ne = inverse_dynamics(&robot, &q, &z, &z).unwrap();
    let tau_l = lagrangian_torques(&robot, &q, &z, &z).unwrap();
    assert!(rel(&tau_l, &tau_ne) < TOL);
    eprintln!("SR400 tree: max relative error {worst:.2e}");
}

/// A change of sign of any single parameter is detected by far more than the tolerance:
/// the comparison has teeth. Newton–Euler runs on the altered robot, the Lagrangian route on the
/// original one.
#[test]
fn a_wrong_parameter_is_caught() {
    let mut rng = testing::rng(7);
    let opt = TreeOptions {
        p_prismatic: 0.0,
        p_fixed: 0.0,
        p_serial: 1.0,
        gravity: None,
        ..TreeOptions::default()
    };
    let mut desc = random_tree_description(&mut rng, 6, &opt);
    // Every parameter of the last link nonzero, wrench included.
    for k in 10..13 {
        desc.links[5].params[k] = Expr::num(rng.random_range(0.2..1.0));
    }
    desc.links[5].wrench = std::array::from_fn(|_| Expr::num(rng.random_range(1.0..3.0)));
    // A moving base, so that its terms are tested too (v0 has no effect on the torques: NE does
    // not use it, the Lagrangian route must cancel it).
    let base = |rng: &mut rand_chacha::ChaCha8Rng| -> [Expr; 3] {
        std::array::from_fn(|_| Expr::num(rng.random_range(0.5..1.5)))
    };
    desc.w0 = base(&mut rng);
    desc.wp0 = base(&mut rng);
    desc.v0 = base(&mut rng);
    desc.vp0 = base(&mut rng);
    let good = Robot::new(desc.clone()).unwrap();
    let s = random_state(&mut rng, 6);
    let tau_l = lagrangian_torques(&good, &s[0], &s[1], &s[2]).unwrap();
    let tau_good = inverse_dynamics(&good, &s[0], &s[1], &s[2]).unwrap();
    assert!(rel(&tau_l, &tau_good) < TOL);
    let smallest = std::cell::Cell::new(f64::INFINITY);
    let alter = |name: &str, f: &dyn Fn(&mut RobotDescription)| {
        let mut d = desc.clone();
        f(&mut d);
        let bad = Robot::new(d).unwrap();
        let tau_bad = inverse_dynamics(&bad, &s[0], &s[1], &s[2]).unwrap();
        let e = rel(&tau_l, &tau_bad);
        assert!(
            e > 1e4 * TOL,
            "flipping {name} changes the comparison by only {e:e}"
        );
        smallest.set(smallest.get().min(e));
    };
    let value = |e: &Expr| e.eval(&|_| None).unwrap();
    let neg = |e: &Expr| Expr::num(-value(e));
    // M, IA, FS, FV must stay non-negative (Robot::new checks): a 10 % error instead of a flip.
    let off = |e: &Expr| Expr::num(0.9 * value(e));
    for (k, name) in robodyn::model::STANDARD_PARAMETERS.iter().enumerate() {
        let change: &dyn Fn(&Expr) -> Expr = if k >= 9 { &off } else { &neg };
        alter(name, &|d| {
            d.links[5].params[k] = change(&d.links[5].params[k])
        });
    }
    for (k, name) in robodyn::model::WRENCH_COMPONENTS.iter().enumerate() {
        alter(name, &|d| d.links[5].wrench[k] = neg(&d.links[5].wrench[k]));
    }
    alter("d4", &|d| d.frames[3].d = neg(&d.frames[3].d));
    alter("r5", &|d| d.frames[4].r = neg(&d.frames[4].r));
    alter("gravity", &|d| d.gravity[2] = neg(&d.gravity[2]));
    alter("W0", &|d| d.w0[0] = neg(&d.w0[0]));
    alter("WP0", &|d| d.wp0[1] = neg(&d.wp0[1]));
    alter("VP0", &|d| d.vp0[2] = neg(&d.vp0[2]));
    eprintln!("teeth: smallest relative change {:.2e}", smallest.get());
}

/// Power balance for a fixed base:
/// `qd'Gamma_NE - sum_j (Fs_j |qd_j| + Fv_j qd_j^2) - P_wrench = dE/dt`,
/// E = T + U (rotors included), dE/dt by forward AD. Relative to the sum of the absolute terms.
#[test]
fn power_balance() {
    let mut rng = testing::rng(0xe1e);
    let mut worst = 0.0f64;
    for n in 2..=30 {
        for _ in 0..3 {
            let opt = random_options(&mut rng);
            let robot = Robot::new(random_tree_description(&mut rng, n, &opt)).unwrap();
            if !has_movable_joint(&robot) {
                continue;
            }
            let s = random_state(&mut rng, robot.dof());
            let tau = inverse_dynamics(&robot, &s[0], &s[1], &s[2]).unwrap();
            let (mut input, mut scale, mut friction) = (0.0, 0.0, 0.0);
            for (k, &j) in robot.coordinates().frames().iter().enumerate() {
                let (qd, l) = (s[1][k], robot.numeric().link(j));
                input += qd * tau[k];
                scale += (qd * tau[k]).abs();
                friction += l.fs * qd.abs() + l.fv * qd * qd;
            }
            let p_env = wrench_power(&robot, &s[0], &s[1]).unwrap();
            let de_dt = total_energy_rate(&robot, &s[0], &s[1], &s[2]).unwrap();
            let e = (input - friction - p_env - de_dt).abs() / (scale + p_env.abs());
            assert!(scale > 1e-3);
            assert!(e < 1e-10, "{n} links: power balance off by {e:e}");
            worst = worst.max(e);
        }
    }
    eprintln!("power balance: max relative error {worst:.2e}");
}

/// The AD rate of the energy against a central finite difference along q(t) = q + qd t +
/// qdd t^2/2, qd(t) = qd + qdd t (checks the AD plumbing of `total_energy_rate` itself).
#[test]
fn energy_rate_matches_finite_difference() {
    let mut rng = testing::rng(31);
    for n in [2, 7, 15, 30] {
        let robot = Robot::new(random_tree_description(
            &mut rng,
            n,
            &TreeOptions {
                gravity: None,
                ..TreeOptions::default()
            },
        ))
        .unwrap();
        let s = random_state(&mut rng, robot.dof());
        let at = |t: f64| {
            let q: Vec<f64> = (0..s[0].len())
                .map(|k| s[0][k] + s[1][k] * t + 0.5 * s[2][k] * t * t)
                .collect();
            let qd: Vec<f64> = (0..s[0].len()).map(|k| s[1][k] + s[2][k] * t).collect();
            total_energy(&robot, &q, &qd).unwrap()
        };
        let h = 1e-4;
        let fd = (at(h) - at(-h)) / (2.0 * h);
        let ad = total_energy_rate(&robot, &s[0], &s[1], &s[2]).unwrap();
        // central difference: error O(h^2 E''') ~ 1e-8 relative here
        assert!(
            (fd - ad).abs() <= 1e-6 * ad.abs().max(1.0),
            "{n} links: AD {ad} vs FD {fd}"
        );
    }
}

/// Kinetic energy against `1/2 qd' A(q) qd`, column k of the inertia matrix being the
/// Newton–Euler torques for qdd = e_k, qd = 0, no gravity, friction or wrench. Potential
/// energy: its change along a random displacement equals the work of the NE gravity torques
/// (trapezoid-free check: dU/dq by central differences vs NE at qd = qdd = 0).
#[test]
fn energies_match_newton_euler_quadratic_form_and_gravity_torques() {
    let mut rng = testing::rng(99);
    for n in [2, 5, 11, 23, 30] {
        let opt = random_options(&mut rng);
        let desc = random_tree_description(&mut rng, n, &opt);
        let robot = Robot::new(desc.clone()).unwrap();
        let mut bare = desc;
        bare.gravity = std::array::from_fn(|_| Expr::zero());
        for l in bare.links.iter_mut() {
            l.params[11] = Expr::zero();
            l.params[12] = Expr::zero();
            l.wrench = std::array::from_fn(|_| Expr::zero());
        }
        let bare = Robot::new(bare).unwrap();
        let m = robot.dof();
        let s = random_state(&mut rng, m);
        let z = vec![0.0; m];
        let mut a = nalgebra::DMatrix::zeros(m, m);
        for k in 0..m {
            let mut e = z.clone();
            e[k] = 1.0;
            a.set_column(k, &inverse_dynamics(&bare, &s[0], &z, &e).unwrap());
        }
        let qd = DVector::from_column_slice(&s[1]);
        let t_ne = 0.5 * qd.dot(&(&a * &qd));
        let t = kinetic_energy(&robot, &s[0], &s[1]).unwrap();
        assert!(
            (t - t_ne).abs() <= 1e-12 * t_ne.abs().max(1.0),
            "{n} links: T = {t}, 1/2 qd'A qd = {t_ne}"
        );
        // Gravity torques (fixed base, qd = qdd = 0) are dU/dq.
        let g_ne = {
            let mut no_fric = robot.description().clone();
            for l in no_fric.links.iter_mut() {
                l.wrench = std::array::from_fn(|_| Expr::zero());
            }
            let r = Robot::new(no_fric).unwrap();
            inverse_dynamics(&r, &s[0], &z, &z).unwrap()
        };
        let h = 1e-5;
        for k in 1..=m {
            let mut qp = s[0].clone();
            let mut qm = s[0].clone();
            qp[k - 1] += h;
            qm[k - 1] -= h;
            let du = (potential_energy(&robot, &qp).unwrap()
                - potential_energy(&robot, &qm).unwrap())
                / (2.0 * h);
            assert!(
                (du - g_ne[k - 1]).abs() <= 1e-6 * g_ne.norm().max(1.0),
                "{n} links, joint {k}: dU/dq {du} vs NE {}",
                g_ne[k - 1]
            );
        }
    }
}

/// Bad input is an error value, never a panic or a NaN.
#[test]
fn bad_input_is_an_error() {
    let robot = sr400();
    let z = vec![0.0; 8];
    let short = vec![0.0; 7];
    let mut nan = z.clone();
    nan[2] = f64::NAN;
    assert!(matches!(
        lagrangian_torques(&robot, &short, &z, &z),
        Err(Error::Dimension {
            expected: 8,
            got: 7,
            ..
        })
    ));
    assert!(matches!(
        lagrangian_torques(&robot, &z, &nan, &z),
        Err(Error::NotFinite { index: 2, .. })
    ));
    let err = kinetic_energy(&robot, &nan, &z).unwrap_err().to_string();
    assert!(err.contains("q[2]"), "{err}");
    assert!(matches!(
        potential_energy(&robot, &short),
        Err(Error::Dimension { .. })
    ));
    assert!(matches!(
        total_energy(&robot, &z, &[f64::INFINITY; 8]),
        Err(Error::NotFinite { .. })
    ));
}

/// A wrench that is not finite is refused at the call, naming its link, by every tree function
/// that takes the environment; setting it back to a finite value (or clearing) makes the same
/// environment usable again: the count of non-finite wrenches the setters keep follows them.
#[test]
fn non_finite_wrench_is_refused_until_replaced() {
    let robot = sr400();
    let n = robot.dof();
    let mut data = Data::new(&robot);
    let (q, mut tau) = (vec![0.3; n], vec![0.0; n]);
    let mut env = robot.environment().clone();
    let call = |env: &robodyn::Environment, data: &mut Data, tau: &mut [f64]| {
        inverse_dynamics_into(&robot, data, env, &q, &q, &q, tau)
    };
    assert!(call(&env, &mut data, &mut tau).is_ok());
    env.set_wrench_by_link(3, [f64::NAN, 0.0, 0.0].into(), [0.0; 3].into())
        .unwrap();
    env.set_wrench_by_link(4, [0.0; 3].into(), [0.0, f64::INFINITY, 0.0].into())
        .unwrap();
    let err = call(&env, &mut data, &mut tau).unwrap_err().to_string();
    assert!(
        err.contains("link 3") && err.contains("not finite"),
        "{err}"
    );
    env.set_wrench_by_link(3, [1.0, 0.0, 0.0].into(), [0.0; 3].into())
        .unwrap();
    let err = call(&env, &mut data, &mut tau).unwrap_err().to_string();
    assert!(err.contains("link 4"), "{err}");
    env.set_wrench_on_link(4, [0.0; 3].into(), [0.0, 2.0, 0.0].into())
        .unwrap();
    assert!(call(&env, &mut data, &mut tau).is_ok());
    env.set_wrench_by_link(2, [f64::NAN; 3].into(), [0.0; 3].into())
        .unwrap();
    assert!(call(&env, &mut data, &mut tau).is_err());
    env.clear_wrenches();
    assert!(call(&env, &mut data, &mut tau).is_ok());
    env.gravity.z = f64::NAN;
    let err = call(&env, &mut data, &mut tau).unwrap_err().to_string();
    assert!(err.contains("gravity"), "{err}");
}
