//! Identification on synthetic logs made by the project's own simulation of bundled robots and
//! random trees with known parameters: the identified base parameters against the true ones
//! (the numerical base-parameter method applied to the robot's standard parameters, an
//! independent route: the regressor of the log's states versus the simulator's direct dynamics).

use rand::Rng;
use robodyn::identification::data::{MemoryLog, RawSample};
use robodyn::identification::excitation::FourierTrajectory;
use robodyn::identification::model_access::{load_description, ModelAccess};
use robodyn::identification::{identify, Estimator, Identification, Options};
use robodyn::testing::{random_tree_description, rng, TreeOptions};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn robot_path(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name)
}

fn access(name: &str) -> ModelAccess {
    ModelAccess::new(load_description(&robot_path(name), &BTreeMap::new()).unwrap()).unwrap()
}

/// A random Fourier trajectory (seeded) around `start`, velocity amplitude ~ `amp` w.
fn trajectory(start: &[f64], harmonics: usize, period: f64, amp: f64, seed: u64) -> FourierTrajectory {
    let mut rng = rng(seed);
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

/// Simulated log: PD tracking (loop at `loop_hz`) of the trajectory from rest; every row
/// (t, q, qd, qdd, tau) satisfies the direct dynamic model exactly.
fn simulate(acc: &ModelAccess, tr: &FourierTrajectory, duration: f64, dt: f64) -> MemoryLog {
    let k = acc.standard_parameters();
    let q0 = tr.eval(0.0)[0].clone();
    let a = acc
        .tracking_model(&k, 1e-3)
        .unwrap()
        .inertia_diagonal(&q0)
        .unwrap();
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

/// Largest |x - truth| / max(|truth|, 1e-3 max|truth|) over the parameters.
fn max_relative_error(id: &Identification, truth: &[f64]) -> (f64, String) {
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    id.parameters
        .iter()
        .enumerate()
        .map(|(k, p)| {
            (
                (id.x[k] - truth[k]).abs() / truth[k].abs().max(1e-3 * scale),
                p.name.clone(),
            )
        })
        .fold((0.0, String::new()), |a, b| if b.0 > a.0 { b } else { a })
}

fn noise_free(acc: &mut ModelAccess, seed: u64, decimation: Option<usize>) -> (f64, String, usize) {
    let n = acc.actuated_joints().len();
    let tr = trajectory(&acc.reference_actuated(), 5, 4.0, 0.6, seed);
    let log = simulate(acc, &tr, 8.0, 0.004);
    assert_eq!(log.samples.len(), 2001);
    let opt = Options {
        estimator: Estimator::Ols,
        validation: None,
        decimation,
        ..Options::default()
    };
    let id = identify(acc, &log, &opt).unwrap();
    let truth = id.model.values(&acc.standard_parameters());
    let (e, name) = max_relative_error(&id, &truth);
    assert!(
        id.relative_error < 1e-10,
        "{}: residual {}",
        acc.name(),
        id.relative_error
    );
    let _ = n;
    (e, name, id.x.len())
}

/// Noise-free logs (qd, qdd from the simulation): the identified base parameters equal the
/// true ones to 1e-8 relative (floor 1e-3 of the largest for parameters near zero), with the
/// default parallel decimation and without.
#[test]
fn noise_free_bundled_robots_give_the_true_base_parameters() {
    for name in ["rx90.toml", "scara.toml", "torso2arms.toml"] {
        let mut acc = access(name);
        for decimation in [None, Some(1)] {
            let (e, p, count) = noise_free(&mut acc, 11, decimation);
            eprintln!("{name} decimation {decimation:?}: {count} parameters, max relative error {e:.2e} ({p})");
            assert!(e < 1e-8, "{name}: {p} off by {e:e}");
        }
    }
}

/// Random trees (revolute, prismatic and fixed joints, general frames, friction, rotor
/// inertias and external wrenches): noise-free identification is exact.
#[test]
fn noise_free_random_trees_give_the_true_base_parameters() {
    let mut worst = 0.0f64;
    for seed in 0..12u64 {
        let mut r = rng(100 + seed);
        let n = 2 + (seed as usize % 5);
        let desc = random_tree_description(&mut r, n, &TreeOptions::default());
        let mut acc = ModelAccess::new(desc).unwrap();
        if acc.actuated_joints().is_empty() {
            continue;
        }
        let (e, p, count) = noise_free(&mut acc, seed, None);
        eprintln!("random tree seed {seed} ({n} links): {count} parameters, max relative error {e:.2e} ({p})");
        assert!(e < 1e-8, "seed {seed}: {p} off by {e:e}");
        worst = worst.max(e);
    }
    eprintln!("worst over the random trees: {worst:.2e}");
}

/// Standard normal variate (Box-Muller).
fn gauss(r: &mut impl Rng) -> f64 {
    let u: f64 = r.random_range(f64::EPSILON..1.0);
    let v: f64 = r.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// With torque noise (white, a different standard deviation per joint), over many seeded
/// runs the true value lies within the reported 2 sigma in about 95.45 % of the cases.
///
/// Each run draws fresh noise on the same simulated motion and checks ONE parameter (cycling
/// through them), so the runs are independent Bernoulli trials with p = 0.9545 if the reported
/// standard deviations are right: with 400 runs the count has mean 381.8 and standard deviation
/// 4.17; we accept 368..=394 (about +-3.3 sigma: a false alarm once in 1000). Weighted least
/// squares (Gautier's weights estimated from the data), no decimation (white residuals).
#[test]
fn two_sigma_coverage_of_the_reported_standard_deviations() {
    let mut acc = access("rx90.toml");
    let tr = trajectory(&acc.reference_actuated(), 5, 4.0, 0.6, 5);
    let clean = simulate(&acc, &tr, 4.0, 0.004);
    let n = acc.actuated_joints().len();
    let rms: Vec<f64> = (0..n)
        .map(|j| {
            (clean.samples.iter().map(|s| s.y[j] * s.y[j]).sum::<f64>() / clean.samples.len() as f64)
                .sqrt()
        })
        .collect();
    let opt = Options {
        validation: None,
        decimation: Some(1),
        ..Options::default()
    };
    let runs = 400;
    let mut inside = 0;
    let (mut pooled_in, mut pooled) = (0usize, 0usize);
    let mut truth = Vec::new();
    for run in 0..runs {
        let mut r = rng(1000 + run as u64);
        let mut log = clean.clone();
        for s in &mut log.samples {
            for j in 0..n {
                // 1 % .. 6 % of the joint's RMS torque, different per joint
                s.y[j] += 0.01 * (1.0 + j as f64) * rms[j] * gauss(&mut r);
            }
        }
        let id = identify(&mut acc, &log, &opt).unwrap();
        if truth.is_empty() {
            truth = id.model.values(&acc.standard_parameters());
        }
        let covered: Vec<bool> = (0..id.x.len())
            .map(|k| (id.x[k] - truth[k]).abs() <= 2.0 * id.std[k])
            .collect();
        inside += usize::from(covered[run % covered.len()]);
        pooled_in += covered.iter().filter(|c| **c).count();
        pooled += covered.len();
    }
    eprintln!(
        "2-sigma coverage: {inside}/{runs} single-parameter trials ({:.2} %); pooled over all \
         parameters {pooled_in}/{pooled} ({:.2} %)",
        100.0 * inside as f64 / runs as f64,
        100.0 * pooled_in as f64 / pooled as f64
    );
    assert!(
        (368..=394).contains(&inside),
        "{inside} of {runs} runs inside 2 sigma: outside the binomial bound 368..=394"
    );
}
