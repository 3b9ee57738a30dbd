//! The regressor (computed recursively) against the Newton–Euler torques: Phi K + Gamma_e = Gamma.

use nalgebra::DVector;
use robodyn::algorithms::regressor::PARAMS_PER_LINK;
use robodyn::{inverse_dynamics, regressor, wrench_torques};
use robodyn_testing::{random_state, random_tree, rng, TreeOptions};

#[test]
fn regressor_times_standard_parameters_is_newton_euler() {
    let mut worst: f64 = 0.0;
    for seed in 0..40u64 {
        let mut r = rng(seed);
        let n = 1 + (seed as usize % 12);
        let opt = TreeOptions {
            gravity: if seed % 2 == 0 {
                Some([0.0, 0.0, -9.81])
            } else {
                None
            },
            ..TreeOptions::default()
        };
        let robot = random_tree(&mut r, n, &opt);
        let k = DVector::from_vec(robot.standard_parameters());
        let m = robot.dof();
        for _ in 0..5 {
            let [q, qd, qdd] = random_state(&mut r, m);
            let tau = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
            let phi = regressor(&robot, &q, &qd, &qdd).unwrap();
            let tau_e = wrench_torques(&robot, &q).unwrap();
            let pred = &phi * &k;
            let scale = tau.iter().fold(1.0f64, |a, t| a.max(t.abs()));
            for j in 0..m {
                let err = (pred[j] + tau_e[j] - tau[j]).abs() / scale;
                worst = worst.max(err);
                assert!(
                    err < 1e-12,
                    "seed {seed}, joint {}: Phi K + Gamma_e = {} but NE gives {}",
                    j + 1,
                    pred[j] + tau_e[j],
                    tau[j]
                );
            }
        }
    }
    eprintln!("worst relative error of Phi K + Gamma_e vs NE: {worst:e}");
}

/// Gamma_e by a different route: Newton–Euler on the same robot with every inertial and drive
/// parameter zero leaves only the external wrenches.
#[test]
fn wrench_term_is_newton_euler_of_massless_robot() {
    for seed in 100..120u64 {
        let mut r = rng(seed);
        let n = 2 + (seed as usize % 9);
        let opt = TreeOptions {
            wrenches: true,
            ..TreeOptions::default()
        };
        let robot = random_tree(&mut r, n, &opt);
        let massless = robot
            .with_standard_parameters(&vec![0.0; PARAMS_PER_LINK * n])
            .unwrap();
        let m = robot.dof();
        let [q, qd, qdd] = random_state(&mut r, m);
        let tau = inverse_dynamics(&massless, &q, &qd, &qdd).unwrap();
        let tau_e = wrench_torques(&robot, &q).unwrap();
        for j in 0..m {
            assert!(
                (tau[j] - tau_e[j]).abs() <= 1e-12 * (1.0 + tau[j].abs()),
                "seed {seed}, joint {}: {} vs {}",
                j + 1,
                tau_e[j],
                tau[j]
            );
        }
    }
}

/// Each column of Phi is the torque of a robot whose only nonzero parameter is that one
/// (linearity, checked column by column against Newton–Euler; no wrench, no gravity offset lost).
#[test]
fn each_column_is_newton_euler_of_a_unit_parameter() {
    let mut r = rng(7);
    let n = 5;
    let opt = TreeOptions {
        wrenches: false,
        gravity: None,
        ..TreeOptions::default()
    };
    let robot = random_tree(&mut r, n, &opt);
    let m = robot.dof();
    let [q, qd, qdd] = random_state(&mut r, m);
    let phi = regressor(&robot, &q, &qd, &qdd).unwrap();
    for c in 0..PARAMS_PER_LINK * n {
        let mut k = vec![0.0; PARAMS_PER_LINK * n];
        k[c] = 1.0;
        // masses must be >= 0 for Robot::new: unit values are fine.
        let unit = robot.with_standard_parameters(&k).unwrap();
        let tau = inverse_dynamics(&unit, &q, &qd, &qdd).unwrap();
        for j in 0..m {
            assert!(
                (tau[j] - phi[(j, c)]).abs() <= 1e-12 * (1.0 + tau[j].abs()),
                "column {} row {}: {} vs NE {}",
                robodyn::algorithms::regressor::parameter_name(c),
                j + 1,
                phi[(j, c)],
                tau[j]
            );
        }
    }
}
