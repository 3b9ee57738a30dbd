//! Identification on synthetic logs made by the project's own simulation of bundled robots and
//! random trees with known parameters.

use robodyn::identification::data::{MemoryLog, RawSample};
use robodyn::identification::excitation::FourierTrajectory;
use robodyn::identification::model_access::{load_description, ModelAccess};
use robodyn::identification::{identify, Estimator, Options};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn robot_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots").join(name)
}

fn access(name: &str) -> ModelAccess {
    ModelAccess::new(load_description(&robot_path(name), &BTreeMap::new()).unwrap()).unwrap()
}

/// A random Fourier trajectory (seeded) around `start`, amplitude ~ `amp` rad.
fn trajectory(start: &[f64], harmonics: usize, period: f64, amp: f64, seed: u64) -> FourierTrajectory {
    use rand::Rng;
    let mut rng = robodyn::testing::rng(seed);
    let m = FourierTrajectory::free_per_joint(harmonics);
    let w = 2.0 * std::f64::consts::PI / period;
    let free: Vec<f64> = (0..start.len() * m)
        .map(|k| {
            let l = (k % (harmonics - 1)) as f64 + 1.0;
            rng.random_range(-1.0..1.0) * amp * w / l.sqrt()
        })
        .collect();
    FourierTrajectory::from_free(period, start, harmonics, &free)
}

/// Simulated log: PD tracking (5 Hz loop) of the trajectory; rows t, q, qd, qdd, tau exact.
fn simulate(acc: &ModelAccess, tr: &FourierTrajectory, duration: f64, dt: f64) -> MemoryLog {
    let k = acc.standard_parameters();
    let q0 = tr.eval(0.0)[0].clone();
    let a = acc.tracking_model(&k, 1e-3).unwrap().inertia_diagonal(&q0).unwrap();
    let w = 2.0 * std::f64::consts::PI * 5.0;
    let kp: Vec<f64> = a.iter().map(|a| a * w * w).collect();
    let kd: Vec<f64> = a.iter().map(|a| 2.0 * 0.7 * a * w).collect();
    let rows = acc
        .simulate_tracking(&|t| tr.eval(t)[0].clone(), duration, dt, &kp, &kd)
        .unwrap();
    MemoryLog {
        name: format!("simulated {}", acc.name()),
        samples: rows
            .into_iter()
            .map(|(t, [q, qd, qdd, tau])| RawSample {
                t,
                q,
                y: tau,
                qd: Some(qd),
                qdd: Some(qdd),
            })
            .collect(),
    }
}

#[test]
fn noise_free_rx90_equals_true_base_parameters() {
    let mut acc = access("rx90.toml");
    let n = acc.actuated_joints().len();
    let tr = trajectory(&vec![0.0; n], 5, 5.0, 0.8, 11);
    let log = simulate(&acc, &tr, 10.0, 0.005);
    let opt = Options {
        estimator: Estimator::Ols,
        validation: None,
        ..Options::default()
    };
    let id = identify(&mut acc, &log, &opt).unwrap();
    let truth = id.model.values(&acc.standard_parameters());
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (k, p) in id.parameters.iter().enumerate() {
        eprintln!("{:8} {:>16.10e} {:>16.10e} {:e}", p.name, id.x[k], truth[k], (id.x[k]-truth[k]).abs()/truth[k].abs().max(1e-3*scale));
    }
    eprintln!("cond {:e} relerr {:e}", id.condition_number, id.relative_error);
    for (k, p) in id.parameters.iter().enumerate() {
        let err = (id.x[k] - truth[k]).abs() / truth[k].abs().max(1e-3 * scale);
        assert!(err < 1e-8, "{}: {} vs true {} ({err:e})", p.name, id.x[k], truth[k]);
    }
}

#[test]
fn debug_tx40_params() {
    let mut acc = access("tx40.toml");
    let m = robodyn::identification::parameters::ParameterModel::build(&mut acc, &Default::default()).unwrap();
    for p in &m.params { eprintln!("{} = {}", p.name, p.equation); }
}
