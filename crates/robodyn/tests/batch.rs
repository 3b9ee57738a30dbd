//! Batches over the cores (`robodyn::batch`): the same numbers as the per-state `_into`
//! functions whatever the number of threads, the lowest failing row reported, and independent
//! cross-checks on whole batches (inverse then direct dynamics gives the accelerations back;
//! regressor times parameters plus wrench torques gives the Newton–Euler torques).

use rand::Rng;
use robodyn::{
    direct_dynamics_batch, inverse_dynamics_batch, inverse_dynamics_into, regressor_batch, Data,
    Error, Method, Robot,
};
use robodyn_testing::{random_tree, rng, TreeOptions};

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

/// The public row runner on a model the library does not batch itself (the inertia matrix, n x n
/// per row), and with two outputs of different widths (A and H): 1, 2 and 3 threads give
/// exactly the per-state results.
#[test]
fn row_runner_on_any_model_equals_per_state_calls_for_any_thread_count() {
    use nalgebra::DMatrix;
    use robodyn::batch::{count_rows, for_each_row, for_each_row2, ROWS_PER_TASK};
    use robodyn::{h_vector_into, inertia_matrix_into};
    let robot = tree(31);
    let n = robot.dof();
    let rows = 3 * ROWS_PER_TASK + 17; // several tasks, a short last one
    let [q, qd, _] = states(&robot, rows, 32);
    let env = robot.environment();
    assert_eq!(count_rows(n, &[("q", &q), ("qd", &qd)]).unwrap(), rows);
    let r = |s: usize| s * n..(s + 1) * n;
    let (mut seq_a, mut seq_h) = (vec![0.0; rows * n * n], vec![0.0; rows * n]);
    let mut data = Data::new(&robot);
    let mut m = DMatrix::zeros(n, n);
    for s in 0..rows {
        inertia_matrix_into(&robot, &mut data, &q[r(s)], &mut m).unwrap();
        seq_a[s * n * n..(s + 1) * n * n].copy_from_slice(m.transpose().as_slice());
        h_vector_into(
            &robot,
            &mut data,
            env,
            &q[r(s)],
            &qd[r(s)],
            &mut seq_h[r(s)],
        )
        .unwrap();
    }
    let scratch = || (Data::new(&robot), DMatrix::zeros(n, n));
    for threads in [1, 2, 3] {
        let mut a = vec![0.0; rows * n * n];
        pool(threads)
            .install(|| {
                for_each_row(rows, &mut a, n * n, scratch, |(data, m), s, a_s| {
                    inertia_matrix_into(&robot, data, &q[r(s)], m)?;
                    a_s.copy_from_slice(m.transpose().as_slice()); // row-major
                    Ok(())
                })
            })
            .unwrap();
        assert_eq!(a, seq_a, "A, {threads} threads");
        let (mut a, mut h) = (vec![0.0; rows * n * n], vec![0.0; rows * n]);
        pool(threads)
            .install(|| {
                for_each_row2(
                    rows,
                    (&mut a, n * n),
                    (&mut h, n),
                    scratch,
                    |(data, m), s, a_s, h_s| {
                        inertia_matrix_into(&robot, data, &q[r(s)], m)?;
                        a_s.copy_from_slice(m.transpose().as_slice());
                        h_vector_into(&robot, data, env, &q[r(s)], &qd[r(s)], h_s)
                    },
                )
            })
            .unwrap();
        assert_eq!((&a, &h), (&seq_a, &seq_h), "A and H, {threads} threads");
    }
}

/// The runner's contract on its own: every row visited once with its own output row, one
/// scratch per task at most, the lowest failing row whatever the threads (and every row before
/// it evaluated), and lengths checked.
#[test]
fn row_runner_visits_every_row_once_and_reports_the_lowest_failure() {
    use robodyn::batch::{count_rows, for_each_row, for_each_row2, ROWS_PER_TASK};
    use std::sync::atomic::{AtomicUsize, Ordering};
    let rows = 10 * ROWS_PER_TASK + 5;
    for threads in [1, 2, 3] {
        let made = AtomicUsize::new(0);
        let (mut out, mut second) = (vec![0.0; rows * 3], vec![0.0; rows]);
        pool(threads)
            .install(|| {
                for_each_row2(
                    rows,
                    (&mut out, 3),
                    (&mut second, 1),
                    || {
                        made.fetch_add(1, Ordering::Relaxed);
                        0usize // rows seen by this scratch
                    },
                    |seen, s, o, t| {
                        *seen += 1;
                        o.copy_from_slice(&[s as f64, 2.0 * s as f64, o[2] + 1.0]);
                        t[0] = -(s as f64);
                        Ok(())
                    },
                )
            })
            .unwrap();
        for s in 0..rows {
            let want = [s as f64, 2.0 * s as f64, 1.0];
            assert_eq!(out[3 * s..3 * s + 3], want, "row {s}, {threads} threads");
            assert_eq!(second[s], -(s as f64));
        }
        let made = made.into_inner();
        assert!(
            (1..=rows.div_ceil(ROWS_PER_TASK)).contains(&made),
            "{made} scratches for {rows} rows"
        );

        // failures in rows 1000 and 300 (0-based) of 1285: row 301 reported, rows before done
        let mut out = vec![0.0; rows];
        let e = pool(threads)
            .install(|| {
                for_each_row(
                    rows,
                    &mut out,
                    1,
                    || (),
                    |_, s, o| {
                        if s == 1000 || s == 300 {
                            return Err(Error::Input(format!("bad row {s}")));
                        }
                        o[0] = 1.0;
                        Ok(())
                    },
                )
            })
            .unwrap_err();
        match e {
            Error::Row { row, source } => {
                assert_eq!(row, 301, "{threads} threads");
                assert!(matches!(*source, Error::Input(ref m) if m == "bad row 300"));
            }
            other => panic!("{other}"),
        }
        assert!(
            out[..300].iter().all(|&x| x == 1.0),
            "rows before the failure"
        );
    }
    // lengths: an output of the wrong length, inputs of different lengths; empty batches
    let mut out = vec![0.0; 11];
    let e = for_each_row(4, &mut out, 3, || (), |_, _, _| Ok(())).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Dimension {
                expected: 12,
                got: 11,
                ..
            }
        ),
        "{e}"
    );
    let e = count_rows(3, &[("q", &[0.0; 6]), ("qd", &[0.0; 9])]).unwrap_err();
    assert!(
        matches!(e, Error::Dimension { ref what, .. } if what == "qd"),
        "{e}"
    );
    let e = count_rows(4, &[("q", &[0.0; 6])]).unwrap_err();
    assert!(matches!(e, Error::Dimension { .. }), "{e}");
    assert_eq!(count_rows(3, &[("q", &[]), ("qd", &[])]).unwrap(), 0);
    for_each_row(
        0,
        &mut [],
        3,
        || (),
        |_, _, _| -> robodyn::Result<()> { panic!("no row") },
    )
    .unwrap();
    // width 0: the rows are still visited (e.g. a check with no output)
    let seen = AtomicUsize::new(0);
    for_each_row(
        300,
        &mut [],
        0,
        || (),
        |_, _, o| {
            assert!(o.is_empty());
            seen.fetch_add(1, Ordering::Relaxed);
            Ok(())
        },
    )
    .unwrap();
    assert_eq!(seen.into_inner(), 300);
}
