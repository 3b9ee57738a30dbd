//! Derivatives of the inverse and direct dynamic models (`robodyn::algorithms::derivatives`)
//! against two independent routes:
//! - forward-mode automatic differentiation: the generic Newton–Euler recursion (`rnea`) run on
//!   hyper-dual numbers, one joint coordinate seeded per run (exact to rounding: 1e-12
//!   relative to the largest entry of the compared matrix);
//! - central finite differences of `inverse_dynamics` and of `direct_dynamics` by the
//!   articulated-body method (a route that shares neither A nor its factorization), to their
//!   truncation error (step 1e-6: error ~ h^2 f''' + eps f / h, a few 1e-9 relative; checked
//!   at 1e-6 relative, while a wrong term is O(1)).
//!
//! On seeded random trees (revolute, prismatic, fixed frames, offsets, friction, rotor inertia,
//! external wrenches, a moving base every fourth case) and on every bundled robot.

use nalgebra::DMatrix;
use num_dual::HyperDual64;
use robodyn::algorithms::derivatives::regressor_derivatives;
use robodyn::algorithms::energy::convert_model;
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::{
    direct_dynamics, direct_dynamics_derivatives_into, inverse_dynamics,
    inverse_dynamics_derivatives, inverse_dynamics_derivatives_batch,
    inverse_dynamics_derivatives_into, Data, DdmDerivatives, DerivativesData, DynModel, Error,
    Expr, IdmDerivatives, Method, Robot,
};
use robodyn_testing::{random_state, random_tree_description, rng, TreeOptions};
use std::path::PathBuf;

fn random_robot(r: &mut rand_chacha::ChaCha8Rng, n: usize, moving_base: bool) -> Robot {
    let mut d = random_tree_description(r, n, &TreeOptions::default());
    if moving_base {
        d.w0 = [0.3, -0.2, 0.5].map(Expr::num);
        d.wp0 = [0.1, 0.4, -0.3].map(Expr::num);
        d.vp0 = [0.5, 0.0, -1.0].map(Expr::num);
    }
    Robot::new(d).unwrap()
}

/// The bundled robots (every file of robots/), each as a tree over its movable joints.
fn bundled() -> Vec<(String, Robot)> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let mut v: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    let all: Vec<(String, Robot)> = v
        .iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, robodyn::io::load(p).unwrap())
        })
        .collect();
    // derivatives of floating-base robots are not there yet: they are refused, never a
    // fixed-base number (issue 28 / 27)
    for (name, robot) in all.iter().filter(|(_, r)| r.is_floating()) {
        let n = robot.dof();
        let z = vec![0.0; n];
        let got = inverse_dynamics_derivatives(robot, &z, &z, &z);
        assert!(
            got.is_err(),
            "{name}: a floating robot's derivatives: {got:?}"
        );
    }
    all.into_iter().filter(|(_, r)| !r.is_floating()).collect()
}

/// dGamma/dq and dGamma/dqd by the hyper-dual route: `rnea` of the model of the dynamic
/// recursions on hyper-dual numbers, eps1 seeded on q_k (then on qd_k), column k = eps1 of
/// the torques.
fn hyper_dual(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> [DMatrix<f64>; 2] {
    let m: DynModel<HyperDual64> = convert_model(robot.dynamic());
    let mut ws = Data::from_model(&m);
    let n = robot.dof();
    let lift = |x: &[f64], k: Option<usize>| -> Vec<HyperDual64> {
        (0..n)
            .map(|i| HyperDual64::new(x[i], if Some(i) == k { 1.0 } else { 0.0 }, 0.0, 0.0))
            .collect()
    };
    let mut out = [DMatrix::zeros(n, n), DMatrix::zeros(n, n)];
    let mut tau = vec![HyperDual64::from_re(0.0); n];
    for k in 0..n {
        for (d, o) in out.iter_mut().enumerate() {
            let (qh, qdh) = if d == 0 {
                (lift(q, Some(k)), lift(qd, None))
            } else {
                (lift(q, None), lift(qd, Some(k)))
            };
            rnea(&m, &mut ws, &qh, &qdh, &lift(qdd, None), &mut tau);
            for j in 0..n {
                o[(j, k)] = tau[j].eps1;
            }
        }
    }
    out
}

/// Central differences of `f` (N -> N) at `x`, step h: column k = (f(x + h e_k) - f(x - h
/// e_k)) / 2h.
fn central(x: &[f64], h: f64, f: impl Fn(&[f64]) -> Vec<f64>) -> DMatrix<f64> {
    let n = x.len();
    let mut m = DMatrix::zeros(n, n);
    let mut y = x.to_vec();
    for k in 0..n {
        y[k] = x[k] + h;
        let p = f(&y);
        y[k] = x[k] - h;
        let q = f(&y);
        y[k] = x[k];
        for j in 0..n {
            m[(j, k)] = (p[j] - q[j]) / (2.0 * h);
        }
    }
    m
}

/// max |a - b| / max(1, max |b|).
fn rel(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    assert_eq!(a.shape(), b.shape());
    (a - b).amax() / b.amax().max(1.0)
}

const H: f64 = 1e-6;

/// Checks one state against the hyper-dual route (1e-12) and central differences (1e-6);
/// returns the two largest relative gaps.
fn check_idm(robot: &Robot, label: &str, q: &[f64], qd: &[f64], qdd: &[f64]) -> [f64; 2] {
    let d = inverse_dynamics_derivatives(robot, q, qd, qdd).unwrap();
    // the torques the derivatives carry are the inverse model's (friction, rotors included)
    let tau = inverse_dynamics(robot, q, qd, qdd).unwrap();
    let e_tau = (&d.tau - &tau).amax() / tau.amax().max(1.0);
    assert!(e_tau <= 1e-13, "{label}: tau vs inverse_dynamics {e_tau:e}");
    let [hq, hv] = hyper_dual(robot, q, qd, qdd);
    // the model's viscous friction, which rnea on any scalar applies as Fv qd
    let e_ad = rel(&d.dtau_dq, &hq).max(rel(&d.dtau_dqd, &hv));
    assert!(e_ad <= 1e-12, "{label}: analytical vs hyper-dual {e_ad:e}");
    let fq = central(q, H, |x| {
        inverse_dynamics(robot, x, qd, qdd)
            .unwrap()
            .as_slice()
            .to_vec()
    });
    let fv = central(qd, H, |x| {
        inverse_dynamics(robot, q, x, qdd)
            .unwrap()
            .as_slice()
            .to_vec()
    });
    let fa = central(qdd, H, |x| {
        inverse_dynamics(robot, q, qd, x)
            .unwrap()
            .as_slice()
            .to_vec()
    });
    let e_fd = rel(&d.dtau_dq, &fq)
        .max(rel(&d.dtau_dqd, &fv))
        .max(rel(&d.a, &fa));
    assert!(
        e_fd <= 1e-6,
        "{label}: analytical vs central differences {e_fd:e}"
    );
    [e_ad, e_fd]
}

/// Velocities away from zero so that Coulomb friction Fs sign(qd) is smooth within the
/// differences' step.
fn away_from_zero(qd: &mut [f64]) {
    for x in qd.iter_mut() {
        if x.abs() < 0.05 {
            *x += 0.1_f64.copysign(*x + 1e-300);
        }
    }
}

#[test]
fn inverse_derivatives_match_hyper_dual_and_finite_differences_on_random_trees() {
    let mut r = rng(2818);
    let mut worst = [0.0f64; 2];
    for case in 0..48 {
        let n = 1 + case % 24;
        let robot = random_robot(&mut r, n, case % 4 == 3);
        let [q, mut qd, qdd] = random_state(&mut r, robot.dof());
        away_from_zero(&mut qd);
        let e = check_idm(&robot, &format!("case {case} ({n} links)"), &q, &qd, &qdd);
        worst = [worst[0].max(e[0]), worst[1].max(e[1])];
    }
    eprintln!(
        "random trees: worst relative gap to hyper-dual {:e}, to FD {:e}",
        worst[0], worst[1]
    );
}

#[test]
fn inverse_derivatives_match_on_every_bundled_robot() {
    let mut r = rng(28);
    for (name, robot) in bundled() {
        for s in 0..3 {
            let [q, mut qd, qdd] = random_state(&mut r, robot.dof());
            away_from_zero(&mut qd);
            check_idm(&robot, &format!("{name} state {s}"), &q, &qd, &qdd);
        }
    }
}

/// Viscous friction is the diagonal Fv of dGamma/dqd, and at rest with qd = 0 the Coriolis
/// terms vanish: dGamma/dqd = diag(Fv) exactly (a hand-derived value, not our own output).
#[test]
fn at_rest_dtau_dqd_is_the_viscous_friction() {
    let mut r = rng(7);
    let robot = random_robot(&mut r, 8, false);
    let n = robot.dof();
    let [q, _, qdd] = random_state(&mut r, n);
    let d = inverse_dynamics_derivatives(&robot, &q, &vec![0.0; n], &qdd).unwrap();
    let fv = robot
        .coordinates()
        .frames()
        .iter()
        .map(|&j| robot.numeric().link(j).fv);
    let expected = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(n, fv));
    assert!(expected.amax() > 0.0);
    assert!((&d.dtau_dqd - &expected).amax() < 1e-12, "{}", d.dtau_dqd);
}

#[test]
fn direct_derivatives_match_finite_differences_of_the_articulated_body_method() {
    let mut r = rng(2819);
    let mut worst = 0.0f64;
    let mut singular = 0;
    let mut cases: Vec<(String, Robot)> = (0..24)
        .map(|c| {
            let n = 1 + c % 16;
            (format!("random {c}"), random_robot(&mut r, n, c % 4 == 3))
        })
        .collect();
    cases.extend(bundled());
    for (label, robot) in &cases {
        let n = robot.dof();
        let [q, mut qd, _] = random_state(&mut r, n);
        away_from_zero(&mut qd);
        let tau: Vec<f64> = (0..n).map(|j| 3.0 * (q[j] - qd[j])).collect();
        let mut data = DerivativesData::new(robot);
        let mut d = DdmDerivatives::new(robot);
        let env = robot.environment();
        let got = direct_dynamics_derivatives_into(robot, &mut data, env, &q, &qd, &tau, &mut d);
        // a tree whose A is singular (a closed robot's massless cut links): both say so
        if direct_dynamics(robot, &q, &qd, &tau, Method::Composite).is_err() {
            assert!(
                matches!(got, Err(Error::Singular { .. })),
                "{label}: {got:?}"
            );
            singular += 1;
            continue;
        }
        got.unwrap();
        let aba = |q: &[f64], qd: &[f64], t: &[f64]| {
            direct_dynamics(robot, q, qd, t, Method::ArticulatedBody)
                .unwrap()
                .as_slice()
                .to_vec()
        };
        let qdd = aba(&q, &qd, &tau);
        let e_qdd = d
            .qdd
            .iter()
            .zip(&qdd)
            .map(|(a, b)| (a - b).abs() / b.abs().max(1.0))
            .fold(0.0, f64::max);
        assert!(e_qdd < 1e-9, "{label}: qdd {e_qdd:e}");
        let fq = central(&q, H, |x| aba(x, &qd, &tau));
        let fv = central(&qd, H, |x| aba(&q, x, &tau));
        let ft = central(&tau, H, |x| aba(&q, &qd, x));
        let e = rel(&d.dqdd_dq, &fq)
            .max(rel(&d.dqdd_dqd, &fv))
            .max(rel(&d.ainv, &ft));
        worst = worst.max(e);
        assert!(e <= 1e-6, "{label}: direct derivatives vs FD {e:e}");
    }
    assert!(singular < 4, "{singular} singular cases: too few checked");
    eprintln!(
        "direct derivatives: worst relative gap to FD of ABA {worst:e} ({singular} singular)"
    );
}

/// Bad inputs are errors naming the input, never a panic or a NaN.
#[test]
fn bad_inputs_are_errors() {
    let mut r = rng(3);
    let robot = random_robot(&mut r, 5, false);
    let other = random_robot(&mut r, 7, false);
    let n = robot.dof();
    let z = vec![0.0; n];
    let env = robot.environment();
    let mut data = DerivativesData::new(&robot);
    let mut d = IdmDerivatives::new(&robot);
    let short = vec![0.0; n - 1];
    let e = inverse_dynamics_derivatives_into(&robot, &mut data, env, &short, &z, &z, &mut d);
    assert!(
        matches!(e, Err(Error::Dimension { ref what, .. }) if what == "q"),
        "{e:?}"
    );
    let mut nan = z.clone();
    nan[0] = f64::NAN;
    let e = inverse_dynamics_derivatives_into(&robot, &mut data, env, &z, &nan, &z, &mut d);
    assert!(matches!(e, Err(Error::NotFinite { .. })), "{e:?}");
    let mut wrong = IdmDerivatives::new(&other);
    let e = inverse_dynamics_derivatives_into(&robot, &mut data, env, &z, &z, &z, &mut wrong);
    assert!(e.is_err(), "matrices of another robot accepted");
    let mut short_tau = IdmDerivatives::new(&robot);
    short_tau.tau = short_tau.tau.rows(0, 1).into_owned();
    let e = inverse_dynamics_derivatives_into(&robot, &mut data, env, &z, &z, &z, &mut short_tau);
    assert!(
        matches!(e, Err(Error::Dimension { ref what, .. }) if what == "tau"),
        "{e:?}"
    );
    let mut other_data = DerivativesData::new(&other);
    let e = inverse_dynamics_derivatives_into(&robot, &mut other_data, env, &z, &z, &z, &mut d);
    assert!(e.is_err(), "data of another robot accepted");
    let mut dd = DdmDerivatives::new(&robot);
    let e = direct_dynamics_derivatives_into(&robot, &mut data, env, &z, &z, &short, &mut dd);
    assert!(
        matches!(e, Err(Error::Dimension { ref what, .. }) if what == "tau"),
        "{e:?}"
    );
}

/// The batch form gives, state by state, the matrices of the single-state form, and reports
/// the failing row.
#[test]
fn batch_matches_single_states() {
    let mut r = rng(11);
    let robot = random_robot(&mut r, 9, true);
    let n = robot.dof();
    let rows = 300;
    let (mut q, mut qd, mut qdd) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..rows {
        let [a, b, c] = random_state(&mut r, n);
        q.extend(a);
        qd.extend(b);
        qdd.extend(c);
    }
    let mut out = vec![0.0; rows * 3 * n * n];
    let env = robot.environment();
    let got = inverse_dynamics_derivatives_batch(&robot, env, &q, &qd, &qdd, &mut out).unwrap();
    assert_eq!(got, rows);
    for s in [0, 1, 137, rows - 1] {
        let x = |v: &[f64]| v[s * n..(s + 1) * n].to_vec();
        let d = inverse_dynamics_derivatives(&robot, &x(&q), &x(&qd), &x(&qdd)).unwrap();
        let o = &out[s * 3 * n * n..(s + 1) * 3 * n * n];
        assert_eq!(&o[..n * n], d.dtau_dq.as_slice());
        assert_eq!(&o[n * n..2 * n * n], d.dtau_dqd.as_slice());
        assert_eq!(&o[2 * n * n..], d.a.as_slice());
    }
    qd[200 * n] = f64::INFINITY;
    let e = inverse_dynamics_derivatives_batch(&robot, env, &q, &qd, &qdd, &mut out);
    assert!(matches!(e, Err(Error::Row { row: 201, .. })), "{e:?}");
}

/// dPhi/dq_k and dPhi/dqd_k against central differences of the recursive regressor
/// (`regressor`, its own recursion: an independent route), on random trees (fixed frames, a
/// moving base) and two bundled robots.
#[test]
fn regressor_derivatives_match_finite_differences_of_the_regressor() {
    let mut r = rng(2820);
    let mut cases: Vec<(String, Robot)> = (0..6)
        .map(|c| {
            (
                format!("random {c}"),
                random_robot(&mut r, 2 + c, c % 3 == 2),
            )
        })
        .collect();
    for (name, robot) in bundled() {
        if ["rx90.toml", "scara.toml"].contains(&name.as_str()) {
            cases.push((name, robot));
        }
    }
    let mut worst = 0.0f64;
    for (label, robot) in &cases {
        let n = robot.dof();
        let [q, mut qd, qdd] = random_state(&mut r, n);
        away_from_zero(&mut qd);
        let d = regressor_derivatives(robot, &q, &qd, &qdd).unwrap();
        let phi = |q: &[f64], qd: &[f64]| robodyn::regressor(robot, q, qd, &qdd).unwrap();
        let scale = phi(&q, &qd).amax().max(1.0);
        for k in 0..n {
            let (mut a, mut b) = (q.clone(), q.clone());
            a[k] += H;
            b[k] -= H;
            let fq = (phi(&a, &qd) - phi(&b, &qd)) / (2.0 * H);
            let (mut a, mut b) = (qd.clone(), qd.clone());
            a[k] += H;
            b[k] -= H;
            let fv = (phi(&q, &a) - phi(&q, &b)) / (2.0 * H);
            let e = (&d.dphi_dq[k] - &fq)
                .amax()
                .max((&d.dphi_dqd[k] - &fv).amax())
                / scale;
            worst = worst.max(e);
            assert!(
                e <= 1e-6,
                "{label}: dPhi/dq_{k} or dPhi/dqd_{k} vs FD {e:e}"
            );
        }
    }
    eprintln!("regressor derivatives: worst relative gap to FD {worst:e}");
}
