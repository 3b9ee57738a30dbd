//! The fixed-frame fold cross-check: the checked tree functions (run on `Robot::dynamic`, fixed
//! frames folded into their movable ancestor) against the kernels on the full frame list
//! (`Robot::numeric`, tree arrays with fixed frames), at one state and environment.

use nalgebra::{DMatrix, Vector3};
use rand::Rng;
use robodyn::algorithms::direct_dynamics::ddm;
use robodyn::algorithms::inertia_matrix::composite_inertia_matrix;
use robodyn::algorithms::inverse_dynamics::rnea_with_environment;
use robodyn::algorithms::regressor::tree_wrench_torques;
use robodyn::{Data, Environment, Method, Robot};

/// Relative tolerance of the comparison: folding only reorders floating-point sums.
pub const TOL: f64 = 1e-12;

fn close(what: &str, a: &[f64], b: &[f64]) {
    let scale = a.iter().chain(b).fold(0.0f64, |m, x| m.max(x.abs()));
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(
            (x - y).abs() <= TOL * scale,
            "{what}[{k}]: folded {x} vs full {y} (scale {scale})"
        );
    }
}

fn v3<R: Rng>(rng: &mut R, s: f64) -> Vector3<f64> {
    Vector3::new(
        rng.random_range(-s..s),
        rng.random_range(-s..s),
        rng.random_range(-s..s),
    )
}

/// A random environment: base motion, gravity and a wrench on every link (fixed ones included).
pub fn random_environment<R: Rng>(robot: &Robot, rng: &mut R) -> Environment {
    let mut env = robot.environment().clone();
    env.gravity = v3(rng, 10.0);
    env.base.w0 = v3(rng, 1.0);
    env.base.wp0 = v3(rng, 1.0);
    env.base.vp0 = v3(rng, 1.0);
    for j in 1..=robot.nl() {
        let (f, m) = (v3(rng, 5.0), v3(rng, 5.0));
        env.set_wrench_by_link(j, f, m).unwrap();
    }
    env
}

/// Compare every checked tree function with its full-frame kernel at a random state under `env`.
/// Returns the number of comparisons made.
pub fn check_fold<R: Rng>(label: &str, robot: &Robot, env: &Environment, rng: &mut R) {
    let c = robot.coordinates();
    let (n, nl) = (c.len(), robot.nl());
    let mut x = |s: f64| {
        (0..n)
            .map(|_| rng.random_range(-s..s))
            .collect::<Vec<f64>>()
    };
    let (q, qd, qdd) = (x(3.0), x(2.0), x(5.0));
    let scatter = |v: &[f64]| {
        let mut t = vec![0.0; nl];
        for (k, &j) in c.frames().iter().enumerate() {
            t[j - 1] = v[k];
        }
        t
    };
    let gather = |t: &[f64]| c.frames().iter().map(|&j| t[j - 1]).collect::<Vec<f64>>();
    let (tq, tqd, tqdd) = (scatter(&q), scatter(&qd), scatter(&qdd));
    let full = robot.numeric();
    let mut data = Data::new(robot);
    let mut t = vec![0.0; nl];

    // Newton–Euler
    let mut tau = vec![0.0; n];
    robodyn::inverse_dynamics_into(robot, &mut data, env, &q, &qd, &qdd, &mut tau).unwrap();
    rnea_with_environment(full, &mut data, env, &tq, &tqd, &tqdd, &mut t);
    close(&format!("{label}: tau"), &tau, &gather(&t));

    // composite links
    let mut a = DMatrix::zeros(n, n);
    robodyn::inertia_matrix_into(robot, &mut data, &q, &mut a).unwrap();
    let mut af = DMatrix::zeros(nl, nl);
    composite_inertia_matrix(full, &mut data, &tq, &mut af);
    let ag = DMatrix::from_fn(n, n, |r, k| af[(c.frame(r) - 1, c.frame(k) - 1)]);
    close(&format!("{label}: A"), a.as_slice(), ag.as_slice());

    // direct dynamics, both methods, at the torque of the state (a well-posed acceleration)
    for method in [Method::Composite, Method::ArticulatedBody] {
        let mut out = vec![0.0; n];
        robodyn::direct_dynamics_into(robot, &mut data, env, &q, &qd, &tau, method, &mut out)
            .unwrap();
        let mut o = vec![0.0; nl];
        ddm(
            full,
            &mut data,
            env,
            method,
            &tq,
            &tqd,
            &scatter(&tau),
            &mut o,
        )
        .unwrap();
        close(&format!("{label}: qdd {method:?}"), &out, &gather(&o));
    }

    // torques of the external wrenches alone
    let mut te = vec![0.0; n];
    robodyn::wrench_torques_into(robot, &mut data, env, &q, &mut te).unwrap();
    tree_wrench_torques(full, &mut data, env, &tq, &mut t);
    close(&format!("{label}: tau_e"), &te, &gather(&t));
}
