//! Batches over the cores (`robodyn::batch`): the same numbers as the per-state `_into`
//! functions whatever the number of threads, the lowest failing row reported, and independent
//! cross-checks on whole batches (inverse then direct dynamics gives the accelerations back;
//! regressor times parameters plus wrench torques gives the Newton–Euler torques).

use rand::Rng;
use robodyn::testing::{random_tree, rng, TreeOptions};
use robodyn::{
    direct_dynamics_batch, inverse_dynamics_batch, inverse_dynamics_into, regressor_batch, Data,
    Error, Method, Robot,
};

fn states(robot: &Robot, rows: usize, seed: u64) -> [Vec<f64>; 3] {
    let mut r = rng(seed);
    let n = robot.dof();
    let mut v = |s: f64| {
        (0..rows * n)
            .map(|_| r.random_range(-s..s))
            .collect::<Vec<f64>>()
    };
    [v(3.0), v(2.0), v(5.0)]
}

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
}

fn tree(seed: u64) -> Robot {
    let opt = TreeOptions {
        p_fixed: 0.3,
        ..TreeOptions::default()
    };
    random_tree(&mut rng(seed), 9, &opt)
}

#[test]
fn batch_equals_per_state_calls_for_any_thread_count() {
    let robot = tree(3);
    let n = robot.dof();
    let rows = 1000; // several tasks
    let [q, qd, qdd] = states(&robot, rows, 4);
    let env = robot.environment();
    let mut seq = vec![0.0; rows * n];
    let mut data = Data::new(&robot);
    for s in 0..rows {
        let r = s * n..(s + 1) * n;
        inverse_dynamics_into(
            &robot,
            &mut data,
            env,
            &q[r.clone()],
            &qd[r.clone()],
            &qdd[r.clone()],
            &mut seq[r],
        )
        .unwrap();
    }
    for threads in [1, 2, 3] {
        let mut tau = vec![0.0; rows * n];
        pool(threads)
            .install(|| inverse_dynamics_batch(&robot, env, &q, &qd, &qdd, &mut tau))
            .unwrap();
        assert_eq!(tau, seq, "{threads} threads");
    }
}

#[test]
fn inverse_then_direct_batch_gives_the_accelerations_back() {
    for seed in 0..5 {
        let robot = tree(10 + seed);
        let n = robot.dof();
        let rows = 300;
        let [q, qd, qdd] = states(&robot, rows, seed);
        let env = robot.environment();
        let mut tau = vec![0.0; rows * n];
        inverse_dynamics_batch(&robot, env, &q, &qd, &qdd, &mut tau).unwrap();
        for method in [Method::Composite, Method::ArticulatedBody] {
            let mut back = vec![0.0; rows * n];
            direct_dynamics_batch(&robot, env, &q, &qd, &tau, method, &mut back).unwrap();
            for (k, (a, b)) in back.iter().zip(&qdd).enumerate() {
                assert!(
                    (a - b).abs() < 1e-8 * (1.0 + b.abs()),
                    "seed {seed} {method:?} entry {k}: {a} vs {b}"
                );
            }
        }
    }
}

#[test]
fn regressor_batch_times_parameters_is_the_newton_euler_torque() {
    let robot = tree(21);
    let (n, nl) = (robot.dof(), robot.nl());
    let rows = 200;
    let [q, qd, qdd] = states(&robot, rows, 22);
    let env = robot.environment();
    let mut tau = vec![0.0; rows * n];
    inverse_dynamics_batch(&robot, env, &q, &qd, &qdd, &mut tau).unwrap();
    let cols = 13 * nl;
    let (mut phi, mut tau_e) = (vec![0.0; rows * n * cols], vec![0.0; rows * n]);
    regressor_batch(&robot, env, &q, &qd, &qdd, &mut phi, &mut tau_e).unwrap();
    let k = robot.standard_parameters();
    for r in 0..rows * n {
        let pk: f64 = (0..cols).map(|c| phi[r * cols + c] * k[c]).sum();
        let want = tau[r];
        assert!(
            (pk + tau_e[r] - want).abs() < 1e-9 * (1.0 + want.abs()),
            "row {r}: {} vs {want}",
            pk + tau_e[r]
        );
    }
}

#[test]
fn the_lowest_failing_row_is_reported_and_lengths_are_checked() {
    let robot = tree(5);
    let n = robot.dof();
    let rows = 700;
    let [mut q, qd, qdd] = states(&robot, rows, 6);
    q[650 * n] = f64::NAN; // row 651
    q[333 * n + n - 1] = f64::INFINITY; // row 334
    let mut tau = vec![0.0; rows * n];
    let env = robot.environment();
    for threads in [1, 2] {
        let e = pool(threads)
            .install(|| inverse_dynamics_batch(&robot, env, &q, &qd, &qdd, &mut tau))
            .unwrap_err();
        match e {
            Error::Row { row, source } => {
                assert_eq!(row, 334);
                assert!(matches!(*source, Error::NotFinite { .. }), "{source}");
            }
            other => panic!("{other}"),
        }
    }
    let e = inverse_dynamics_batch(&robot, env, &q[..n * 10], &qd, &qdd, &mut tau).unwrap_err();
    assert!(matches!(e, Error::Dimension { .. }), "{e}");
    let e = inverse_dynamics_batch(&robot, env, &q, &qd, &qdd, &mut tau[1..]).unwrap_err();
    assert!(matches!(e, Error::Dimension { .. }), "{e}");
}
