//! Identification from several logs and from their sufficient statistics
//! (`identification::statistics`): short noise-free logs that are too short alone give the true
//! parameters together; merged statistics (through JSON) give the numbers of the logs
//! identified together; Gautier's WLS over several noisy logs against the estimator written out
//! on the explicit rows of W (nalgebra SVD, an independent route); merges of another robot or
//! other options refused.

use nalgebra::{DMatrix, DVector};
use rand::Rng;
use robodyn::identification::data::{MemoryLog, RawSample};
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::parameters::ParameterModel;
use robodyn::identification::statistics::statistics;
use robodyn::identification::{
    identify, identify_from_statistics, identify_logs, Estimator, Options, Statistics,
};
use robodyn::io::load_description;
use robodyn_testing::rng;

fn access(name: &str) -> ModelAccess {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/").to_string() + name;
    ModelAccess::new(load_description(path).unwrap()).unwrap()
}

/// A simulated log (qd, qdd given) of a random Fourier trajectory, `duration` s at 250 Hz.
fn log(acc: &ModelAccess, seed: u64, duration: f64) -> MemoryLog {
    let start = acc.reference_actuated().unwrap();
    let mut r = rng(seed);
    let harmonics = 4;
    let free: Vec<f64> = (0..start.len() * FourierTrajectory::free_per_joint(harmonics))
        .map(|_| r.random_range(-0.5..0.5))
        .collect();
    let tr = FourierTrajectory::from_free(4.0, &start, harmonics, &free);
    let mut l = simulated_log(acc, &tr, duration, 0.004, 5.0).unwrap();
    l.name = format!("sim{seed}");
    l
}

/// Gaussian noise of standard deviation `sd[j]` on joint j's torque.
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

fn ols() -> Options {
    Options {
        estimator: Estimator::Ols,
        validation: None,
        ..Options::default()
    }
}

/// A noise-free SCARA log cut into logs of 4 samples, each too short for the 19 parameters
/// (refused alone): together they give the true base parameters (the robot file's, mapped by
/// the parameter model) to 1e-8.
#[test]
fn short_logs_together_give_the_true_parameters() {
    let mut acc = access("scara.toml");
    let whole = log(&acc, 40, 2.0);
    let logs: Vec<MemoryLog> = whole
        .samples
        .chunks_exact(4)
        .enumerate()
        .map(|(k, c)| MemoryLog {
            name: format!("chunk{k}"),
            samples: c.to_vec(),
        })
        .collect();
    let opt = Options {
        decimation: Some(1),
        ..ols()
    };
    let alone = identify(&mut acc, &logs[0], &opt).unwrap_err().to_string();
    assert!(alone.contains("too short"), "{alone}");
    let refs: Vec<&dyn robodyn::identification::data::LogSource> =
        logs.iter().map(|l| l as _).collect();
    let id = identify_logs(&mut acc, &refs, &opt).unwrap();
    let truth = id.model.values(&acc.standard_parameters());
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (k, p) in id.parameters.iter().enumerate() {
        let e = (id.x[k] - truth[k]).abs() / truth[k].abs().max(1e-3 * scale);
        assert!(e < 1e-8, "{}: {} vs {} ({e:e})", p.name, id.x[k], truth[k]);
    }
    assert_eq!(id.logs.len(), logs.len());
    assert_eq!(id.processing.samples, 4 * logs.len());
    assert!(id
        .processing
        .source
        .contains(" logs (chunk0, chunk1, chunk2, ..."));
}

/// Two different logs of the robot standing still, velocities differentiated from the
/// positions: the default minimum speed leaves out all their rows. Their statistics are both
/// empty (the same digest) but not the same log twice: they merge, with a moving log, into the
/// moving log's estimate (to rounding).
#[test]
fn logs_at_rest_merge_without_being_taken_for_the_same_log() {
    let mut acc = access("scara.toml");
    let moving = log(&acc, 90, 3.0);
    let rest = |q0: f64, name: &str| MemoryLog {
        name: name.into(),
        samples: (0..500)
            .map(|k| RawSample {
                t: k as f64 * 0.004,
                q: vec![q0, 0.3, 0.1, -0.2],
                y: vec![1.0, 2.0, -3.0, 0.1],
                qd: None,
                qdd: None,
            })
            .collect(),
    };
    let opt = Options {
        use_log_derivatives: false,
        ..ols()
    };
    let parts: Vec<Statistics> = [&moving, &rest(0.2, "rest1"), &rest(-0.4, "rest2")]
        .into_iter()
        .map(|l| statistics(&mut acc, l, &opt).unwrap())
        .collect();
    assert_eq!(parts[1].rows() + parts[2].rows(), 0);
    assert_eq!(parts[1].digests, parts[2].digests);
    let merged = identify_from_statistics(&mut acc, &parts, &opt).unwrap();
    let alone = identify(&mut acc, &moving, &opt).unwrap();
    for (a, b) in merged.x.iter().zip(&alone.x) {
        assert!((a - b).abs() <= 1e-9 * b.abs().max(1e-3), "{a} vs {b}");
    }
    // the same moving log twice is still refused
    let e = identify_from_statistics(&mut acc, &[parts[0].clone(), parts[0].clone()], &opt)
        .unwrap_err()
        .to_string();
    assert!(e.contains("the same log twice"), "{e}");
}

/// Statistics computed per log, written as JSON and read back, merged: exactly the numbers of
/// the logs identified together (estimate, std, weights, validation), and the same to 1e-10
/// in the other merge order. One log's statistics give exactly `identify` of it.
#[test]
fn merged_statistics_equal_the_logs_identified_together() {
    let mut acc = access("rx90.toml");
    let sd = [0.5, 0.8, 0.3, 0.05, 0.04, 0.02];
    let logs: Vec<MemoryLog> = (0..3)
        .map(|k| noisy(log(&acc, 60 + k, 3.0), &sd, 7 + k))
        .collect();
    let opt = Options {
        validation: Some((0.7, 0.9)),
        ..Options::default()
    };
    let refs: Vec<&dyn robodyn::identification::data::LogSource> =
        logs.iter().map(|l| l as _).collect();
    let together = identify_logs(&mut acc, &refs, &opt).unwrap();
    let parts: Vec<Statistics> = logs
        .iter()
        .map(|l| {
            let text = statistics(&mut acc, l, &opt).unwrap().to_json();
            Statistics::from_json(&text, "part.json").unwrap()
        })
        .collect();
    let merged = identify_from_statistics(&mut acc, &parts, &opt).unwrap();
    assert_eq!(merged.x, together.x);
    assert_eq!(merged.std, together.std);
    let sig = |id: &robodyn::identification::Identification| -> Vec<Option<f64>> {
        id.per_joint.iter().map(|f| f.sigma).collect()
    };
    assert_eq!(sig(&merged), sig(&together));
    let v = |id: &robodyn::identification::Identification| {
        let v = id.validation.as_ref().unwrap();
        (v.relative_error, v.raw_relative_error)
    };
    assert_eq!(v(&merged), v(&together));
    assert_eq!(merged.processing, together.processing);
    // another order: the same problem, other rounding
    let reversed: Vec<Statistics> = parts.iter().rev().cloned().collect();
    let other = identify_from_statistics(&mut acc, &reversed, &opt).unwrap();
    for k in 0..other.x.len() {
        let e = (other.x[k] - together.x[k]).abs();
        assert!(e <= 1e-10 * together.x[k].abs().max(1e-3), "{k}: {e:e}");
        assert!((other.std[k] - together.std[k]).abs() <= 1e-8 * together.std[k]);
    }
    // one log: identify and its statistics agree exactly
    let one = identify(&mut acc, &logs[1], &opt).unwrap();
    let from = identify_from_statistics(&mut acc, &parts[1..2], &opt).unwrap();
    assert_eq!(one.x, from.x);
    assert_eq!(one.std, from.std);
    assert_eq!(one.relative_error, from.relative_error);
}

/// Gautier's WLS over two noisy logs of different noise levels, against the estimator written
/// out on the explicit rows of W (qd, qdd from the logs, no decimation, no border): sigma_j
/// from each joint's own least squares over both logs (rank from the SVD), the weighted
/// solution and its standard deviations from the SVD of the stacked weighted rows.
#[test]
fn wls_of_several_logs_equals_the_estimator_on_the_stacked_rows() {
    let mut acc = access("scara.toml");
    let logs = [
        noisy(log(&acc, 80, 2.0), &[0.2, 0.1, 2.0, 0.01], 1),
        noisy(log(&acc, 81, 3.0), &[0.2, 0.1, 2.0, 0.01], 2),
    ];
    let opt = Options {
        decimation: Some(1),
        validation: None,
        ..Options::default()
    };
    let refs: Vec<&dyn robodyn::identification::data::LogSource> =
        logs.iter().map(|l| l as _).collect();
    let id = identify_logs(&mut acc, &refs, &opt).unwrap();
    // the rows by hand
    let mut model = ParameterModel::build(&mut acc, &opt.parameters).unwrap();
    let (n, p) = (model.joints_count(), model.count());
    let mut rows: Vec<Vec<(Vec<f64>, f64)>> = vec![Vec::new(); n];
    let mut w = vec![0.0; n * p];
    let mut tau_e = vec![0.0; n];
    for l in &logs {
        acc.restart();
        for s in &l.samples {
            let RawSample { q, y, qd, qdd, .. } = s;
            let (qd, qdd) = (qd.as_ref().unwrap(), qdd.as_ref().unwrap());
            model
                .rows(&mut acc, q, qd, qdd, &mut w, &mut tau_e)
                .unwrap();
            for j in 0..n {
                rows[j].push((w[j * p..(j + 1) * p].to_vec(), y[j] - tau_e[j]));
            }
        }
    }
    let stack = |rows: &[(Vec<f64>, f64)], scale: f64| {
        let a = DMatrix::from_fn(rows.len(), p, |r, c| rows[r].0[c] * scale);
        let b = DVector::from_fn(rows.len(), |r, _| rows[r].1 * scale);
        (a, b)
    };
    let sigma: Vec<f64> = rows
        .iter()
        .map(|rj| {
            let (a, b) = stack(rj, 1.0);
            let svd = a.clone().svd(true, true);
            let smax = svd.singular_values.max();
            let rank = svd
                .singular_values
                .iter()
                .filter(|&&s| s > 1e-10 * smax)
                .count();
            let x = svd.solve(&b, 1e-10 * smax).unwrap();
            ((&b - &a * x).norm_squared() / (rj.len() - rank) as f64).sqrt()
        })
        .collect();
    for (j, f) in id.per_joint.iter().enumerate() {
        let s = f.sigma.unwrap();
        assert!(
            (s - sigma[j]).abs() < 1e-6 * sigma[j],
            "joint {j}: {s} vs {}",
            sigma[j]
        );
    }
    let parts: Vec<(DMatrix<f64>, DVector<f64>)> = rows
        .iter()
        .zip(&sigma)
        .map(|(rj, s)| stack(rj, 1.0 / s))
        .collect();
    let m: usize = parts.iter().map(|(a, _)| a.nrows()).sum();
    let mut a = DMatrix::zeros(m, p);
    let mut b = DVector::zeros(m);
    let mut r0 = 0;
    for (aj, bj) in &parts {
        a.rows_mut(r0, aj.nrows()).copy_from(aj);
        b.rows_mut(r0, aj.nrows()).copy_from(bj);
        r0 += aj.nrows();
    }
    assert_eq!(m, id.per_joint.iter().map(|f| f.rows).sum::<usize>());
    let x = a.clone().svd(true, true).solve(&b, 1e-14).unwrap();
    let s2 = (&b - &a * &x).norm_squared() / (m - p) as f64;
    let cov = (a.transpose() * &a).try_inverse().unwrap() * s2;
    for k in 0..p {
        assert!(
            (id.x[k] - x[k]).abs() < 1e-7 * x[k].abs().max(1e-3),
            "{}: {} vs {}",
            id.parameters[k].name,
            id.x[k],
            x[k]
        );
        let sd = cov[(k, k)].sqrt();
        assert!(
            (id.std[k] - sd).abs() < 1e-6 * sd,
            "std {k}: {} vs {sd}",
            id.std[k]
        );
    }
}

/// Statistics of another robot, of other row options, or read from a file that is not
/// statistics are refused with the difference named; IDIM-IV needs the logs.
#[test]
fn merges_of_other_robots_or_options_are_refused() {
    let mut scara = access("scara.toml");
    let mut rx90 = access("rx90.toml");
    let opt = Options::default();
    let (la, lb) = (log(&scara, 1, 2.0), log(&rx90, 2, 2.0));
    let a = statistics(&mut scara, &la, &opt).unwrap();
    let b = statistics(&mut rx90, &lb, &opt).unwrap();
    let e = Statistics::merged(&[a.clone(), b.clone()])
        .unwrap_err()
        .to_string();
    assert!(e.contains("another robot") && e.contains("sim2"), "{e}");
    let e = identify_from_statistics(&mut scara, &[b], &opt)
        .unwrap_err()
        .to_string();
    assert!(e.contains("another robot"), "{e}");
    // the same robot with another link length
    let mut desc = load_description(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/scara.toml"
    ))
    .unwrap();
    desc.frames[1].d = robodyn_symbolic::Expr::from(0.123456);
    let mut longer = ModelAccess::new(desc).unwrap();
    let e = identify_from_statistics(&mut longer, std::slice::from_ref(&a), &opt)
        .unwrap_err()
        .to_string();
    assert!(e.contains("geometry"), "{e}");
    // other row options
    let other = Options {
        bandwidth: 10.0,
        ..Options::default()
    };
    let lc = log(&scara, 3, 2.0);
    let c = statistics(&mut scara, &lc, &other).unwrap();
    let e = Statistics::merged(&[a.clone(), a.clone()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the same log twice") && e.contains("sim1"),
        "{e}"
    );
    let e = Statistics::merged(&[a.clone(), c]).unwrap_err().to_string();
    assert!(
        e.contains("bandwidth = 5") && e.contains("bandwidth = 10"),
        "{e}"
    );
    let e = identify_from_statistics(&mut scara, std::slice::from_ref(&a), &other)
        .unwrap_err()
        .to_string();
    assert!(e.contains("bandwidth"), "{e}");
    let iv = Options {
        estimator: Estimator::Iv,
        ..Options::default()
    };
    let e = identify_from_statistics(&mut scara, std::slice::from_ref(&a), &iv)
        .unwrap_err()
        .to_string();
    assert!(e.contains("IDIM-IV"), "{e}");
    for (text, want) in [
        ("{", "not JSON"),
        ("{\"format\": \"x\"}", "not identification statistics"),
        (
            "{\"format\": \"robodyn-identification-statistics\", \"version\": 99}",
            "version",
        ),
    ] {
        let e = Statistics::from_json(text, "f.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("f.json") && e.contains(want), "{e}");
    }
    // a factor cut short
    let mut v: serde_json::Value = serde_json::from_str(&a.to_json()).unwrap();
    v["fit"][0]["upper"][0].as_array_mut().unwrap().pop();
    let e = Statistics::from_json(&v.to_string(), "f.json")
        .unwrap_err()
        .to_string();
    assert!(e.contains("upper triangle"), "{e}");
}
