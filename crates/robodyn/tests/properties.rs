//! Property tests (proptest, fixed seed, no failure persistence): the generated robots are drawn
//! from strategies over size, joint mix and gravity, so a failure shrinks to a small robot.
//! Properties: Lagrangian route = Newton–Euler (issue 2), idm(ddm(tau)) = tau for both direct
//! methods (issue 3), regressor x parameters = Newton–Euler without wrenches (issue 5).

use nalgebra::DVector;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};
use robodyn::algorithms::energy::lagrangian_torques;
use robodyn::{direct_dynamics, inverse_dynamics, regressor, wrench_torques, Method, Robot};
use robodyn_testing::{random_state, random_tree, rng, TreeOptions};

fn config() -> Config {
    Config {
        cases: 48,
        rng_seed: RngSeed::Fixed(20261122),
        failure_persistence: None,
        ..Config::default()
    }
}

/// (robot, q, qd, qdd) from a seed, a size and a joint mix.
fn robot_and_state(
    seed: u64,
    n: usize,
    p_prismatic: f64,
    p_fixed: f64,
    gravity_z: bool,
) -> (Robot, [Vec<f64>; 3]) {
    let mut r = rng(seed);
    let opt = TreeOptions {
        p_prismatic,
        p_fixed,
        gravity: if gravity_z {
            Some([0.0, 0.0, -9.81])
        } else {
            None
        },
        ..TreeOptions::default()
    };
    let robot = random_tree(&mut r, n, &opt);
    let s = random_state(&mut r, robot.dof());
    (robot, s)
}

fn rel(x: &DVector<f64>, reference: &DVector<f64>) -> f64 {
    (x - reference).norm() / reference.norm().max(1e-3)
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn lagrangian_route_equals_newton_euler(
        seed in any::<u64>(), n in 2usize..=30, pp in 0.0..0.5f64, pf in 0.0..0.3f64, gz in any::<bool>()
    ) {
        let (robot, [q, qd, qdd]) = robot_and_state(seed, n, pp, pf, gz);
        let ne = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
        let lag = lagrangian_torques(&robot, &q, &qd, &qdd).unwrap();
        prop_assert!(rel(&lag, &ne) < 1e-8, "relative error {}", rel(&lag, &ne));
    }

    #[test]
    fn direct_then_inverse_gives_back_the_torques(
        seed in any::<u64>(), n in 2usize..=30, pp in 0.0..0.5f64, pf in 0.0..0.3f64
    ) {
        let (robot, [q, qd, tau]) = robot_and_state(seed, n, pp, pf, true);
        let tau = DVector::from_vec(tau);
        for method in [Method::Composite, Method::ArticulatedBody] {
            let qdd = direct_dynamics(&robot, &q, &qd, tau.as_slice(), method).unwrap();
            let back = inverse_dynamics(&robot, &q, &qd, qdd.as_slice()).unwrap();
            prop_assert!(rel(&back, &tau) < 1e-9, "{method:?}: relative error {}", rel(&back, &tau));
        }
    }

    #[test]
    fn regressor_times_parameters_is_newton_euler(
        seed in any::<u64>(), n in 2usize..=20, pp in 0.0..0.5f64, pf in 0.0..0.3f64
    ) {
        let (robot, [q, qd, qdd]) = robot_and_state(seed, n, pp, pf, false);
        let phi = regressor(&robot, &q, &qd, &qdd).unwrap();
        let k = DVector::from_vec(robot.standard_parameters());
        let we = wrench_torques(&robot, &q).unwrap();
        let model = phi * k + we;
        let ne = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
        prop_assert!(rel(&model, &ne) < 1e-10, "relative error {}", rel(&model, &ne));
    }
}
