//! The rule for results (`robodyn::error::check_finite_result`): finite inputs that overflow
//! (a velocity of 1e200 squared, gravity of 1e308 times a mass, masses of 1.5e308 summed) give
//! an error naming the entry, never a NaN or an infinity, in every checked tree function and
//! the batches; and a simulation that cannot end within its step limit is refused before it
//! starts (the default limit is the CLI's).

use robodyn::io::set_values;
use robodyn::simulation::{
    simulate, Integrator, Recorder, SimOptions, TorqueInput, TreeDynamics, DEFAULT_MAX_STEPS,
};
use robodyn::{
    direct_dynamics, h_vector, inertia_matrix, inverse_dynamics, inverse_dynamics_batch, regressor,
    Error, Method, Robot,
};
use std::collections::BTreeMap;

fn rx90(values: &[(&str, f64)]) -> Robot {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
    let mut d = robodyn::io::load_description(path).unwrap();
    let v: BTreeMap<String, f64> = values.iter().map(|(k, x)| (k.to_string(), *x)).collect();
    set_values(&mut d, &v).unwrap();
    Robot::new(d).unwrap()
}

fn overflow<T: std::fmt::Debug>(r: robodyn::Result<T>, entry: &str) {
    match r {
        Err(Error::Numerical(m)) => assert!(
            m.starts_with(entry) && m.contains("overflows the floating-point range"),
            "{m}"
        ),
        other => panic!("expected an overflow error on {entry}, got {other:?}"),
    }
}

#[test]
fn overflowing_results_are_errors() {
    let r = rx90(&[]);
    let (q, big, z) = ([0.0; 6], [1e200; 6], [0.0; 6]);
    overflow(inverse_dynamics(&r, &q, &big, &z), "tau[");
    overflow(h_vector(&r, &q, &big), "H[");
    overflow(regressor(&r, &q, &big, &z), "Phi[");
    assert!(matches!(
        direct_dynamics(&r, &q, &big, &z, Method::ArticulatedBody),
        Err(Error::Numerical(_))
    ));
    let g = rx90(&[("G3", 1e308)]);
    overflow(inverse_dynamics(&g, &q, &z, &z), "tau[");
    let heavy = rx90(&[("M2", 1.5e308), ("M3", 1.5e308)]);
    overflow(inertia_matrix(&heavy, &[0.3; 6]), "A[");
    // in a batch: the row is named
    let (qs, mut tau) = (vec![0.0; 18], vec![0.0; 18]);
    let mut qds = vec![0.0; 18];
    qds[12..].copy_from_slice(&big);
    match inverse_dynamics_batch(&r, r.environment(), &qs, &qds, &qs, &mut tau) {
        Err(Error::Row { row: 3, source }) => assert!(matches!(*source, Error::Numerical(_))),
        other => panic!("{other:?}"),
    }
    // large but finite results are results
    assert!(inverse_dynamics(&r, &q, &[1e10; 6], &z)
        .unwrap()
        .iter()
        .all(|x| x.is_finite()));
}

#[test]
fn a_run_beyond_the_step_limit_is_refused_before_it_starts() {
    let r = rx90(&[]);
    let mut dynamics = TreeDynamics::new(&r, Method::ArticulatedBody);
    let run = |duration: f64, integrator: Integrator, max_steps: usize, d: &mut TreeDynamics| {
        let opts = SimOptions {
            duration,
            integrator,
            output_dt: 0.01,
            max_steps: Some(max_steps),
        };
        let t = std::time::Instant::now();
        let r = simulate(
            d,
            &TorqueInput::Constant(vec![0.0; 6]),
            &[0.1; 6],
            &[0.0; 6],
            &opts,
            &mut Recorder::default(),
            &mut |_| {},
        );
        (r, t.elapsed())
    };
    let rk4 = Integrator::Rk4 { dt: 1e-3 };
    let (r1, took) = run(1e9, rk4, DEFAULT_MAX_STEPS, &mut dynamics);
    let m = r1.unwrap_err().to_string();
    assert!(
        m.contains("at least 1e12 integration steps") && m.contains("max_steps = 5000000"),
        "{m}"
    );
    assert!(
        took.as_secs_f64() < 1.0,
        "refused after {took:?}: not before the run"
    );
    let adaptive = Integrator::fixed_or_adaptive(None, 1e-8, 1e-10);
    let m = run(10.0, adaptive, 50, &mut dynamics)
        .0
        .unwrap_err()
        .to_string();
    assert!(
        m.contains("at least 1e3 integration steps") && m.contains("output step"),
        "{m}"
    );
    let ok = run(0.1, rk4, 100, &mut dynamics).0.unwrap();
    assert_eq!(ok.rows, 11);
}
