//! Direct dynamic model, both methods: round trip through Newton–Euler, agreement of the two
//! methods, a dense solve of A, and singular models reported with the joint.

use nalgebra::{DMatrix, DVector};
use robodyn::model::{param, JointType};
use robodyn::{
    direct_dynamics, direct_dynamics_into, h_vector, inertia_matrix, inverse_dynamics_into, Data,
    Error, Expr, Method, Robot,
};
use robodyn_testing::{random_state, random_tree_description, rng, TreeOptions};

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
        let env = robot.environment();
        // one Data for both directions: a call depends on nothing an earlier call left
        let mut data = Data::new(&robot);
        let nm = robot.dof();
        let [q, qd, qdd0] = random_state(&mut r, nm);
        let tau0: Vec<f64> = (0..nm).map(|j| 10.0 * (qdd0[j] - 0.3 * q[j])).collect();
        for (m, method) in METHODS.iter().enumerate() {
            // tau -> qdd -> tau
            let mut qdd = vec![0.0; nm];
            direct_dynamics_into(&robot, &mut data, env, &q, &qd, &tau0, *method, &mut qdd)
                .unwrap();
            let mut tau = vec![0.0; nm];
            inverse_dynamics_into(&robot, &mut data, env, &q, &qd, &qdd, &mut tau).unwrap();
            let scale = tau0.iter().fold(1.0f64, |a, x| a.max(x.abs()));
            let err = tau
                .iter()
                .zip(&tau0)
                .fold(0.0f64, |a, (x, y)| a.max((x - y).abs()));
            worst[m] = worst[m].max(err / scale);
            assert!(err <= 1e-9 * scale, "{method:?} case {case}: {err:e}");
            // qdd -> tau -> qdd
            inverse_dynamics_into(&robot, &mut data, env, &q, &qd, &qdd0, &mut tau).unwrap();
            direct_dynamics_into(&robot, &mut data, env, &q, &qd, &tau, *method, &mut qdd).unwrap();
            for j in 0..nm {
                let e = (qdd[j] - qdd0[j]).abs();
                assert!(
                    e <= 1e-9 * qdd0[j].abs().max(1.0),
                    "{method:?} case {case} joint {j}: {e:e}"
                );
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
        let nm = robot.dof();
        let [q, qd, _] = random_state(&mut r, nm);
        let tau: Vec<f64> = (0..nm).map(|j| (j as f64 * 0.7).sin() * 5.0).collect();
        let c = direct_dynamics(&robot, &q, &qd, &tau, Method::Composite).unwrap();
        let b = direct_dynamics(&robot, &q, &qd, &tau, Method::ArticulatedBody).unwrap();
        let a: DMatrix<f64> = inertia_matrix(&robot, &q).unwrap();
        let h = h_vector(&robot, &q, &qd).unwrap();
        let rhs = DVector::from_column_slice(&tau) - h;
        let x = a.lu().solve(&rhs).unwrap();
        let scale = x.amax().max(1.0);
        for k in 0..nm {
            worst = worst.max((c[k] - x[k]).abs().max((b[k] - x[k]).abs()) / scale);
            assert!((c[k] - x[k]).abs() <= 1e-9 * scale, "case {case} joint {k}");
            assert!((b[k] - x[k]).abs() <= 1e-9 * scale, "case {case} joint {k}");
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
                Error::Singular { what, .. } => {
                    assert!(what.ends_with(&format!("of joint {n}")), "{method:?}: {e}")
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
        assert!(
            matches!(e, Err(Error::Singular { .. })),
            "{method:?}: {e:?}"
        );
    }
}

#[test]
fn bad_state_is_an_input_error() {
    let mut r = rng(25);
    let robot = random_robot(&mut r, 4, false);
    for method in METHODS {
        let m = robot.dof();
        let mut inf = vec![0.0; m];
        inf[1] = f64::INFINITY;
        let e = direct_dynamics(&robot, &vec![0.0; m], &vec![0.0; m], &inf, method);
        assert!(matches!(e, Err(Error::NotFinite { index: 1, .. })));
        let e = direct_dynamics(
            &robot,
            &vec![0.0; m - 1],
            &vec![0.0; m],
            &vec![0.0; m],
            method,
        );
        assert!(matches!(e, Err(Error::Dimension { .. })));
    }
}
