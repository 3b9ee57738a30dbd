//! Do the reported standard deviations mean what they say with the default processing?
//!
//! A random 5-joint tree tracks a seeded Fourier trajectory (simulated log: q, qd, qdd given,
//! so only the torques are noisy); white Gaussian noise at the log's rate is added to the
//! torques, a different level per joint, and the log is identified with the default options
//! (WLS, the default parallel decimation). Over many noise draws the true base parameters must
//! lie within +-2 reported standard deviations in 95.45 % of the cases. The decimation
//! low-pass leaves the decimated residuals correlated; without accounting for it the coverage
//! was 92 % (the standard deviations about 11 % too small).

use rand::Rng;
use robodyn::identification::data::MemoryLog;
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::{identify, Options};
use robodyn_testing::{random_tree_description, rng, TreeOptions};

/// Standard normal variate (Box-Muller).
fn gauss(r: &mut impl Rng) -> f64 {
    let u: f64 = r.random_range(f64::EPSILON..1.0);
    let v: f64 = r.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// A random 5-joint tree (revolute and prismatic joints, friction, no fixed frames) and its
/// simulated log (500 Hz, 12 s).
fn case() -> (ModelAccess, MemoryLog) {
    let opt = TreeOptions {
        p_fixed: 0.0,
        wrenches: false,
        ..TreeOptions::default()
    };
    let desc = random_tree_description(&mut rng(7), 5, &opt);
    let acc = ModelAccess::new(desc).unwrap();
    let start = acc.reference_actuated().unwrap();
    let harmonics = 5;
    let w = 2.0 * std::f64::consts::PI / 4.0;
    let mut r = rng(8);
    let free: Vec<f64> = (0..start.len() * FourierTrajectory::free_per_joint(harmonics))
        .map(|k| {
            let l = (k % (harmonics - 1)) as f64 + 1.0;
            r.random_range(-1.0..1.0) * 0.6 * w / l.sqrt()
        })
        .collect();
    let tr = FourierTrajectory::from_free(4.0, &start, harmonics, &free);
    let log = simulated_log(&acc, &tr, 12.0, 0.002, 5.0).unwrap();
    (acc, log)
}

/// Pooled 2-sigma coverage over `runs` noise draws with `noise` (run, joint rms) -> torque
/// noise sequences; returns (inside, total).
fn coverage(
    noise: &dyn Fn(&mut rand_chacha::ChaCha8Rng, usize) -> Vec<f64>,
    runs: u64,
) -> (usize, usize) {
    let (mut acc, clean) = case();
    let n = acc.actuated_joints().len();
    let samples = clean.samples.len();
    let rms: Vec<f64> = (0..n)
        .map(|j| {
            (clean.samples.iter().map(|s| s.y[j] * s.y[j]).sum::<f64>() / samples as f64).sqrt()
        })
        .collect();
    let opt = Options {
        validation: None,
        ..Options::default()
    };
    let (mut inside, mut total) = (0, 0);
    let mut truth = Vec::new();
    for run in 0..runs {
        let mut r = rng(5000 + run);
        let mut log = clean.clone();
        for (j, rms) in rms.iter().enumerate() {
            let e = noise(&mut r, samples);
            for (s, e) in log.samples.iter_mut().zip(e) {
                s.y[j] += 0.01 * (1.0 + j as f64) * rms * e;
            }
        }
        let id = identify(&mut acc, &log, &opt).unwrap();
        if truth.is_empty() {
            truth = id.model.values(&acc.standard_parameters());
            assert!(id.x.len() > 20, "{} base parameters", id.x.len());
        }
        inside += (0..id.x.len())
            .filter(|&k| (id.x[k] - truth[k]).abs() <= 2.0 * id.std[k])
            .count();
        total += id.x.len();
    }
    (inside, total)
}

/// White torque noise: pooled coverage within one point of 95.45 %.
#[test]
fn white_noise_two_sigma_coverage_with_the_default_decimation() {
    let white = |r: &mut rand_chacha::ChaCha8Rng, m: usize| (0..m).map(|_| gauss(r)).collect();
    let (inside, total) = coverage(&white, 150);
    let pct = 100.0 * inside as f64 / total as f64;
    eprintln!("white noise: 2-sigma coverage {inside}/{total} = {pct:.2} %");
    assert!(
        (94.45..=96.45).contains(&pct),
        "2-sigma coverage {pct:.2} % ({inside}/{total}): 95.45 +- 1 expected"
    );
}

/// Coloured torque noise (AR(1) at the log's rate, correlation 0.95 from sample to sample, so
/// still correlated across decimated rows beyond what the filter explains): the inflation,
/// exact for white noise, is not enough and the standard deviations are optimistic. This is
/// the limitation docs/models/identification.md states; the test checks its direction and
/// size (coverage at least 3 points under nominal), so that the docs' claim stays true.
#[test]
fn coloured_noise_coverage_is_optimistic_as_documented() {
    let ar1 = |r: &mut rand_chacha::ChaCha8Rng, m: usize| {
        let a: f64 = 0.95;
        let s = (1.0 - a * a).sqrt();
        let mut e = gauss(r);
        (0..m)
            .map(|_| {
                e = a * e + s * gauss(r);
                e
            })
            .collect()
    };
    let (inside, total) = coverage(&ar1, 60);
    let pct = 100.0 * inside as f64 / total as f64;
    eprintln!("AR(1) noise (0.95): 2-sigma coverage {inside}/{total} = {pct:.2} %");
    assert!(
        pct < 92.45,
        "coverage {pct:.2} % under coloured noise: the docs say it is optimistic"
    );
}
