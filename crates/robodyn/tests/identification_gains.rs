//! Drive gains identified jointly with the base parameters (`identification::gains`): logs of
//! motor currents i = tau / g made by the simulator (every row satisfies the direct dynamic
//! model with the robot file's parameters) and a reference fixing the scale — a log of joint
//! torques, or a log of currents with a known payload (a robot whose last link carries point
//! masses, simulated as such). Noise-free, the gains and the base parameters come back to 1e-8
//! (the gains of the simulation, the robot file's parameters mapped by the parameter model);
//! with noise on currents and torques, the errors stay within the reported standard
//! deviations as often as a Gaussian estimate's should.

use rand::Rng;
use robodyn::identification::data::MemoryLog;
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::gains::{identify_gains, Currents, GainReference};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::{Estimator, Options};
use robodyn::io::load_description;
use robodyn_testing::rng;

pub fn access(name: &str) -> ModelAccess {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/").to_string() + name;
    ModelAccess::new(load_description(path).unwrap()).unwrap()
}

fn trajectory(acc: &ModelAccess, seed: u64) -> FourierTrajectory {
    let start = acc.reference_actuated().unwrap();
    let mut r = rng(seed);
    let harmonics = 4;
    let free: Vec<f64> = (0..start.len() * FourierTrajectory::free_per_joint(harmonics))
        .map(|_| r.random_range(-0.5..0.5))
        .collect();
    FourierTrajectory::from_free(4.0, &start, harmonics, &free)
}

/// A simulated log (qd, qdd given) of a random Fourier trajectory, 4 s at 250 Hz.
pub fn log(acc: &ModelAccess, seed: u64) -> MemoryLog {
    let mut l = simulated_log(acc, &trajectory(acc, seed), 4.0, 0.004, 5.0).unwrap();
    l.name = format!("sim{seed}");
    l
}

/// The currents i = tau / g of a log of torques.
fn currents(mut l: MemoryLog, g: &[f64]) -> MemoryLog {
    for s in &mut l.samples {
        for (y, g) in s.y.iter_mut().zip(g) {
            *y /= g;
        }
    }
    l.name = format!("{} (currents)", l.name);
    l
}

/// Gaussian noise of standard deviation `sd[j]` on channel j.
fn noisy(mut l: MemoryLog, sd: &[f64], seed: u64) -> MemoryLog {
    let mut r = rng(seed);
    for s in &mut l.samples {
        for (y, sd) in s.y.iter_mut().zip(sd) {
            let (u, v): (f64, f64) = (r.random_range(f64::EPSILON..1.0), r.random_range(0.0..1.0));
            *y += sd * (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos();
        }
    }
    l
}

/// The standard parameters of link `link` (10) of point masses (m, position in R_link), from
/// the definitions: J = sum m (|r|^2 1 - r r^T), MS = sum m r, M = sum m.
pub fn point_masses(masses: &[(f64, [f64; 3])]) -> [f64; 10] {
    let mut k = [0.0; 10];
    for &(m, r) in masses {
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        k[0] += m * (r2 - r[0] * r[0]);
        k[1] -= m * r[0] * r[1];
        k[2] -= m * r[0] * r[2];
        k[3] += m * (r2 - r[1] * r[1]);
        k[4] -= m * r[1] * r[2];
        k[5] += m * (r2 - r[2] * r[2]);
        k[6] += m * r[0];
        k[7] += m * r[1];
        k[8] += m * r[2];
        k[9] += m;
    }
    k
}

/// The robot of `acc` with `payload` added to link `link`'s standard parameters.
pub fn with_payload(acc: &ModelAccess, link: usize, payload: &[f64; 10]) -> ModelAccess {
    let mut k = acc.standard_parameters();
    for (i, v) in payload.iter().enumerate() {
        k[13 * (link - 1) + i] += v;
    }
    ModelAccess::new(acc.description_with(&k).unwrap()).unwrap()
}

pub const PAYLOAD: [(f64, [f64; 3]); 4] = [
    (1.2, [0.03, 0.0, 0.12]),
    (0.8, [-0.05, 0.04, 0.10]),
    (0.5, [0.0, -0.06, 0.02]),
    (0.3, [0.07, 0.02, -0.03]),
];

const GAINS: [f64; 6] = [31.0, 47.0, 22.0, 7.5, 6.2, 3.9];

pub fn ols() -> Options {
    Options {
        estimator: Estimator::Ols,
        validation: None,
        ..Options::default()
    }
}

fn assert_close(what: &str, got: &[f64], truth: &[f64], tol: f64) {
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (k, (g, t)) in got.iter().zip(truth).enumerate() {
        let e = (g - t).abs() / t.abs().max(1e-3 * scale);
        assert!(e < tol, "{what} {k}: {g} vs {t} ({e:e})");
    }
}

fn truth(acc: &mut ModelAccess, opt: &Options) -> Vec<f64> {
    let model =
        robodyn::identification::parameters::ParameterModel::build(acc, &opt.parameters).unwrap();
    model.values(&acc.standard_parameters())
}

/// Currents of one log and the torques of another: the gains and the base parameters to 1e-8.
#[test]
fn noise_free_gains_from_a_torque_reference() {
    let mut acc = access("rx90.toml");
    let cur = currents(log(&acc, 1), &GAINS);
    let tau = log(&acc, 2);
    let reference = GainReference::Torques(vec![&tau]);
    let id = identify_gains(&mut acc, &[&Currents(&cur)], &reference, &ols()).unwrap();
    assert_close("gain", &id.gains, &GAINS, 1e-8);
    assert_close("parameter", &id.x, &truth(&mut acc, &ols()), 1e-8);
    assert_eq!(id.gains.len(), 6);
    assert!(id.rows > 0 && id.condition_number.is_finite());
}

/// Currents without and with a known payload (point masses on link 6, the robot simulated
/// with them): the payload's inertia fixes the scale; gains and parameters to 1e-8.
#[test]
fn noise_free_gains_from_a_known_payload() {
    let mut acc = access("rx90.toml");
    let phi = point_masses(&PAYLOAD);
    let loaded = with_payload(&acc, 6, &phi);
    let before = currents(log(&acc, 3), &GAINS);
    let after = currents(log(&loaded, 4), &GAINS);
    let after = Currents(&after);
    let reference = GainReference::Payload {
        link: 6,
        parameters: phi,
        logs: vec![&after],
    };
    let id = identify_gains(&mut acc, &[&Currents(&before)], &reference, &ols()).unwrap();
    assert_close("gain", &id.gains, &GAINS, 1e-8);
    assert_close("parameter", &id.x, &truth(&mut acc, &ols()), 1e-8);
}

/// Gaussian noise on the currents (1 % of each channel's RMS) and on the reference torques
/// (1 %), 30 noise draws, default processing (the logs give qd, qdd: the decimation low-pass
/// at 10 x the 5 Hz bandwidth, decimation by 2), WLS: the errors in units of the reported
/// standard deviations have an RMS of 1.14 over the 180 cases (accepted 0.8..1.3; 1 for a
/// calibrated std), 92.8 % lie within 2 (accepted >= 88 %; 95.45 % expected), all within 4.5
/// (measured largest 3.1). The current column is noisy (errors in variables): at 250 Hz
/// without decimation the attenuation bias reaches about one standard deviation (RMS 1.38 with
/// decimation by 1; docs/models/identification.md); the decimation low-pass removes most of that
/// noise.
#[test]
fn noisy_gains_lie_within_their_standard_deviations() {
    let mut acc = access("rx90.toml");
    let cur = currents(log(&acc, 5), &GAINS);
    let tau = log(&acc, 6);
    let rms = |l: &MemoryLog| -> Vec<f64> {
        (0..6)
            .map(|j| {
                let s: f64 = l.samples.iter().map(|s| s.y[j] * s.y[j]).sum();
                0.01 * (s / l.samples.len() as f64).sqrt()
            })
            .collect()
    };
    let (sd_i, sd_t) = (rms(&cur), rms(&tau));
    let opt = Options {
        validation: None,
        ..Options::default()
    };
    let mut z = Vec::new();
    for draw in 0..30 {
        let ci = noisy(cur.clone(), &sd_i, 100 + draw);
        let ct = noisy(tau.clone(), &sd_t, 200 + draw);
        let reference = GainReference::Torques(vec![&ct]);
        let id = identify_gains(&mut acc, &[&Currents(&ci)], &reference, &opt).unwrap();
        for (k, g) in id.gains.iter().enumerate() {
            assert!(
                id.gains_std[k] < 0.01 * GAINS[k],
                "std {} of gain {k}",
                id.gains_std[k]
            );
            z.push((g - GAINS[k]) / id.gains_std[k]);
        }
    }
    let rms_z = (z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64).sqrt();
    let inside2 = z.iter().filter(|v| v.abs() < 2.0).count();
    let largest = z.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    eprintln!(
        "gain errors / std over {} cases: RMS {rms_z:.3}, {inside2} within 2, largest {largest:.2}",
        z.len()
    );
    assert!(
        (0.8..1.3).contains(&rms_z),
        "RMS of the errors / std {rms_z}"
    );
    assert!(
        inside2 * 100 >= 88 * z.len(),
        "{inside2} of {} within 2 std",
        z.len()
    );
    assert!(largest < 4.5, "largest error {largest} std");
}

/// What cannot work is refused in words: no reference, gains given, a torque log given as
/// currents, a transmission coupling motors (the TX40's wrist), IDIM-IV.
#[test]
fn gain_identification_refusals() {
    let mut acc = access("scara.toml");
    let g = [10.0, 12.0, 3.0, 2.0];
    let cur = currents(log(&acc, 7), &g);
    let tau = log(&acc, 8);
    let none = GainReference::Torques(vec![]);
    let e = identify_gains(&mut acc, &[&Currents(&cur)], &none, &ols()).unwrap_err();
    assert!(e.to_string().contains("common scale"), "{e}");
    let given = Options {
        gains: Some(g.to_vec()),
        ..ols()
    };
    let reference = GainReference::Torques(vec![&tau]);
    let e = identify_gains(&mut acc, &[&Currents(&cur)], &reference, &given).unwrap_err();
    assert!(e.to_string().contains("unknowns"), "{e}");
    let e = identify_gains(&mut acc, &[&tau], &reference, &ols()).unwrap_err();
    assert!(e.to_string().contains("motor currents"), "{e}");
    let as_currents = Currents(&cur);
    let reference_i = GainReference::Torques(vec![&as_currents]);
    let e = identify_gains(&mut acc, &[&Currents(&cur)], &reference_i, &ols()).unwrap_err();
    assert!(e.to_string().contains("joint torques"), "{e}");
    let iv = Options {
        estimator: Estimator::Iv,
        ..ols()
    };
    let e = identify_gains(&mut acc, &[&Currents(&cur)], &reference, &iv).unwrap_err();
    assert!(e.to_string().contains("IDIM-IV"), "{e}");
    let mut tx40 = access("tx40.toml");
    let e = identify_gains(&mut tx40, &[&Currents(&cur)], &reference, &ols()).unwrap_err();
    assert!(e.to_string().contains("couples"), "{e}");
}
