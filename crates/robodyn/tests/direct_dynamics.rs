//! Direct dynamic model, both methods: round trip through Newton–Euler, agreement of the two
//! methods, a dense solve of A, and singular models reported with the joint.

use nalgebra::{DMatrix, DVector};
use robodyn::algorithms::direct_dynamics::{ddm, direct_dynamics, DirectWorkspace, Method};
use robodyn::algorithms::inertia_matrix::{h_vector, inertia_matrix};
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::model::{param, JointType};
use robodyn::testing::{random_state, random_tree_description, rng, TreeOptions};
use robodyn::{Error, Expr, Robot, Workspace};

const METHODS: [Method; 2] = [Method::Composite, Method::ArticulatedBody];

fn random_robot(r: &mut rand_chacha::ChaCha8Rng, n: usize, moving_base: bool) -> Robot {
    let mut d = random_tree_description(r, n, &TreeOptions::default());
    if moving_base {
        d.w0 = [0.3, -0.2, 0.5].map(Expr::num);
        d.wp0 = [0.1, 0.4, -0.3].map(Expr::num);
        d.vp0 = [0.5, 0.0, -1.0].map(Expr::num);
    }
    Robot::new(d).unwrap()
}

/// idm(q, qd, ddm(q, qd, tau)) = tau to 1e-9 relative and ddm(q, qd, idm(q, qd, qdd)) = qdd,
/// both methods, random trees of 2..30 joints (revolute, prismatic, fixed; gamma, b nonzero;
/// friction, rotor inertia, external wrenches; every fourth case with a moving base).
#[test]
fn round_trip_through_newton_euler() {
    let mut r = rng(21);
    let mut worst = [0.0f64; 2];
    for case in 0..60 {
        let n = 2 + case % 29;
        let robot = random_robot(&mut r, n, case % 4 == 3);
        let model = robot.numeric();
        let mut ws = DirectWorkspace::new(model);
        let mut ne = Workspace::new(model);
        let [q, qd, qdd0] = random_state(&mut r, n);
        let tau0: Vec<f64> = (0..n)
            .map(|j| {
                if robot.frame(j + 1).joint == JointType::Fixed {
                    0.0
                } else {
                    10.0 * (qdd0[j] - 0.3 * q[j])
                }
            })
            .collect();
        for (m, method) in METHODS.iter().enumerate() {
            // tau -> qdd -> tau
            let mut qdd = vec![0.0; n];
            ddm(model, &mut ws, *method, &q, &qd, &tau0, &mut qdd).unwrap();
            let mut tau = vec![0.0; n];
            rnea(model, &mut ne, &q, &qd, &qdd, &mut tau);
            let scale = tau0.iter().fold(1.0f64, |a, x| a.max(x.abs()));
            let err = tau
                .iter()
                .zip(&tau0)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            worst[m] = worst[m].max(err / scale);
            assert!(err <= 1e-9 * scale, "{method:?} case {case}: {err:e}");
            for j in 1..=n {
                if robot.frame(j).joint == JointType::Fixed {
                    assert_eq!(qdd[j - 1], 0.0);
                }
            }
            // qdd -> tau -> qdd
            rnea(model, &mut ne, &q, &qd, &qdd0, &mut tau);
            ddm(model, &mut ws, *method, &q, &qd, &tau, &mut qdd).unwrap();
            for j in 1..=n {
                if robot.frame(j).joint != JointType::Fixed {
                    let e = (qdd[j - 1] - qdd0[j - 1]).abs();
                    assert!(
                        e <= 1e-9 * qdd0[j - 1].abs().max(1.0),
                        "{method:?} case {case} joint {j}: {e:e}"
                    );
                }
            }
        }
    }
    eprintln!(
        "worst relative round-trip error: composite {:e}, aba {:e}",
        worst[0], worst[1]
    );
}

/// The two methods agree with each other and with a dense LU solve of A qdd = tau - H.
#[test]
fn methods_agree_with_dense_solve() {
    let mut r = rng(22);
    let mut worst: f64 = 0.0;
    for case in 0..40 {
        let n = 2 + case % 29;
        let robot = random_robot(&mut r, n, case % 3 == 0);
        let [q, qd, _] = random_state(&mut r, n);
        let tau: Vec<f64> = (0..n).map(|j| (j as f64 * 0.7).sin() * 5.0).collect();
        let c = direct_dynamics(&robot, &q, &qd, &tau, Method::Composite).unwrap();
        let b = direct_dynamics(&robot, &q, &qd, &tau, Method::ArticulatedBody).unwrap();
        let mov = robot.movable_joints();
        let a = inertia_matrix(&robot, &q).unwrap();
        let h = h_vector(&robot, &q, &qd).unwrap();
        let sub = DMatrix::from_fn(mov.len(), mov.len(), |i, j| a[(mov[i] - 1, mov[j] - 1)]);
        let rhs = DVector::from_fn(mov.len(), |i, _| tau[mov[i] - 1] - h[mov[i] - 1]);
        let x = sub.lu().solve(&rhs).unwrap();
        let scale = x.amax().max(1.0);
        for (k, &j) in mov.iter().enumerate() {
            worst = worst.max((c[j - 1] - x[k]).abs().max((b[j - 1] - x[k]).abs()) / scale);
            assert!(
                (c[j - 1] - x[k]).abs() <= 1e-9 * scale,
                "case {case} joint {j}"
            );
            assert!(
                (b[j - 1] - x[k]).abs() <= 1e-9 * scale,
                "case {case} joint {j}"
            );
        }
    }
    eprintln!("worst |qdd - qdd_LU| / max|qdd_LU|: {worst:e}");
}

/// A massless chain end (last link of a serial chain with zero inertial parameters and no rotor)
/// makes A singular: both methods report the joint, no NaN.
#[test]
fn massless_chain_end_names_the_joint() {
    let mut r = rng(23);
    let opt = TreeOptions {
        p_serial: 1.0,
        p_fixed: 0.0,
        ..TreeOptions::default()
    };
    for n in [2, 5, 9] {
        let mut d = random_tree_description(&mut r, n, &opt);
        for k in 0..=param::FV {
            d.links[n - 1].params[k] = Expr::zero();
        }
        let robot = Robot::new(d).unwrap();
        let [q, qd, _] = random_state(&mut r, n);
        let tau = vec![1.0; n];
        for method in METHODS {
            let e = direct_dynamics(&robot, &q, &qd, &tau, method).unwrap_err();
            match &e {
                Error::Numerical(msg) => {
                    assert!(msg.starts_with(&format!("joint {n}:")), "{method:?}: {msg}")
                }
                other => panic!("{method:?}: unexpected error {other}"),
            }
        }
    }
}

/// Non-physical (negative) inertia: an error, never a NaN.
#[test]
fn negative_inertia_is_an_error() {
    let mut r = rng(24);
    let mut d = random_tree_description(&mut r, 3, &TreeOptions::default());
    for j in 0..3 {
        d.frame_mut(j + 1).joint = JointType::Revolute;
        d.frame_mut(j + 1).actuated = true;
        d.links[j].params[param::ZZ] = Expr::num(-50.0);
        d.links[j].params[param::IA] = Expr::zero();
    }
    let robot = Robot::new(d).unwrap();
    for method in METHODS {
        let e = direct_dynamics(&robot, &[0.1, 0.2, 0.3], &[0.0; 3], &[0.0; 3], method);
        assert!(matches!(e, Err(Error::Numerical(_))), "{method:?}: {e:?}");
    }
}

#[test]
fn bad_state_is_an_input_error() {
    let mut r = rng(25);
    let robot = random_robot(&mut r, 4, false);
    for method in METHODS {
        let e = direct_dynamics(
            &robot,
            &[0.0; 4],
            &[0.0; 4],
            &[0.0, f64::INFINITY, 0.0, 0.0],
            method,
        );
        assert!(matches!(e, Err(Error::Input(_))));
        let e = direct_dynamics(&robot, &[0.0; 3], &[0.0; 4], &[0.0; 4], method);
        assert!(matches!(e, Err(Error::Input(_))));
    }
}
