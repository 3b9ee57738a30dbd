//! Physically consistent parameters (the SDP, solved by robodyn's interior-point method in the
//! default build): the robot written from an identification is consistent and reproduces the
//! identified base parameters; deliberately inconsistent estimates are projected onto the
//! consistent set and reported; noisy problems give exactly consistent parameters; with the
//! `sdp` feature, Clarabel finds the same optimum.

use robodyn::identification::consistency::{min_pseudo_inertia_eigenvalue, pseudo_inertia};
use robodyn::identification::data::MemoryLog;
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::{identify, Estimator, Options};
use robodyn::io::{load_description, save_description};
use std::path::PathBuf;

/// The RX-90 with friction on every joint (the file has none: true values at the boundary
/// FS = FV = 0 of the consistent set would make rounding-level estimates "inconsistent").
fn rx90() -> robodyn::RobotDescription {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/rx90.toml");
    let mut d = load_description(&p).unwrap();
    for (j, l) in d.links.iter_mut().enumerate() {
        l.params[11] = robodyn::Expr::num(0.5 + 0.1 * j as f64);
        l.params[12] = robodyn::Expr::num(0.3 + 0.05 * j as f64);
    }
    d
}

/// A noise-free simulated log of `acc` along a fixed Fourier trajectory (qd, qdd given).
fn log(acc: &ModelAccess) -> MemoryLog {
    let n = acc.actuated_joints().len();
    let free: Vec<f64> = (0..n * 8)
        .map(|k| 0.9 * ((k * 37 % 17) as f64 / 8.0 - 1.0))
        .collect();
    let tr = FourierTrajectory::from_free(4.0, &vec![0.0; n], 5, &free);
    simulated_log(acc, &tr, 8.0, 0.004, 5.0).unwrap()
}

fn opts(consistent: bool) -> Options {
    Options {
        estimator: Estimator::Ols,
        validation: None,
        consistent,
        standard: true,
        ..Options::default()
    }
}

/// Noise-free data of a consistent robot: the consistent standard parameters reproduce the
/// identified base parameters (1e-6 relative: the SDP's tolerance), the written robot file
/// reloads with pseudo-inertias PSD, a positive definite inertia matrix, and can be simulated.
#[test]
fn written_robot_is_consistent_and_reproduces_the_base_parameters() {
    let mut acc = ModelAccess::new(rx90()).unwrap();
    let log = log(&acc);
    let id = identify(&mut acc, &log, &opts(false)).unwrap();
    assert!(
        id.warnings
            .iter()
            .all(|w| !w.message.contains("not physically consistent")),
        "{:?}",
        id.warnings
    );
    let c = id.consistent.as_ref().expect("consistent parameters");
    eprintln!(
        "{} ; distance^2 {:.3e}, max deviation {:.3e} std",
        c.solver, c.distance2, c.max_deviation
    );
    // write, reload and compare
    let path = std::env::temp_dir().join(format!("robodyn-identified-{}.toml", std::process::id()));
    let desc = acc.description_with(&id.standard_parameters()).unwrap();
    save_description(&desc, &path).unwrap();
    let reloaded = ModelAccess::new(load_description(&path).unwrap()).unwrap();
    std::fs::remove_file(&path).ok();
    let k = reloaded.standard_parameters();
    let x = id.model.values(&k);
    let scale = id.x.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (i, p) in id.parameters.iter().enumerate() {
        let e = (x[i] - id.x[i]).abs() / id.x[i].abs().max(1e-3 * scale);
        assert!(
            e < 1e-6,
            "{}: written robot {} vs identified {} ({e:e})",
            p.name,
            x[i],
            id.x[i]
        );
    }
    // consistent: every pseudo-inertia PSD (to the solver's tolerance), drives >= 0
    let lo = min_pseudo_inertia_eigenvalue(&k);
    assert!(lo > -1e-9, "pseudo-inertia eigenvalue {lo}");
    for j in 0..6 {
        let ev = pseudo_inertia(&k[13 * j..13 * j + 10]).symmetric_eigenvalues();
        assert!(
            ev.min() > -1e-9 * ev.max().abs().max(1.0),
            "link {}: {ev:?}",
            j + 1
        );
        for p in 10..13 {
            assert!(k[13 * j + p] >= 0.0);
        }
    }
    assert!(c.min_inertia_eigenvalue > 0.0);
    // the written robot simulates
    let n = reloaded.actuated_joints().len();
    let rows = reloaded
        .simulate_tracking(
            &|t| vec![0.3 * t.sin(); n],
            0.5,
            0.01,
            &vec![100.0; n],
            &vec![20.0; n],
        )
        .unwrap();
    assert_eq!(rows.len(), 51);
}

/// Identification under the constraints of consistent noise-free data is the unconstrained
/// answer: the true base parameters.
#[test]
fn constrained_identification_of_consistent_data_finds_the_truth() {
    let mut acc = ModelAccess::new(rx90()).unwrap();
    let log = log(&acc);
    let id = identify(&mut acc, &log, &opts(true)).unwrap();
    let truth = id.model.values(&acc.standard_parameters());
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (i, p) in id.parameters.iter().enumerate() {
        let e = (id.x[i] - truth[i]).abs() / truth[i].abs().max(1e-3 * scale);
        assert!(
            e < 1e-6,
            "{}: {} vs true {} ({e:e})",
            p.name,
            id.x[i],
            truth[i]
        );
    }
    assert!(id.estimator.contains("consistency"));
}

/// A robot that is not physically consistent (ZZ6 < 0: no mass distribution has a negative
/// moment of inertia; ZZ6 is a base parameter of the RX-90 by itself) makes data whose exact
/// estimate is inconsistent: the report says so, the consistent set has ZZ6 >= 0 and PSD
/// pseudo-inertias, and identifying under the constraints fits worse than the unconstrained
/// (exact) estimate.
#[test]
fn deliberately_inconsistent_estimates_are_projected_and_reported() {
    let mut desc = rx90();
    // ZZ6 = -0.01 (the rotor inertia IA6 = 0.1 keeps the inertia matrix positive definite)
    desc.links[5].params[5] = robodyn::Expr::num(-0.01);
    let mut acc = ModelAccess::new(desc).unwrap();
    let log = log(&acc);
    let id = identify(&mut acc, &log, &opts(false)).unwrap();
    let zz6 = id.parameters.iter().position(|p| p.name == "ZZ6").unwrap();
    assert!(
        (id.x[zz6] + 0.01).abs() < 1e-9,
        "the unconstrained estimate is exact: {}",
        id.x[zz6]
    );
    let c = id.consistent.as_ref().unwrap();
    eprintln!(
        "{}: distance^2 {:.3e}, ZZ6 consistent {:.3e}",
        c.solver, c.distance2, c.x[zz6]
    );
    assert!(
        id.warnings
            .iter()
            .any(|w| w.message.contains("not physically consistent")),
        "{:?}",
        id.warnings
    );
    assert!(c.x[zz6] >= -1e-9, "ZZ6 of the consistent set {}", c.x[zz6]);
    assert!(c.min_pseudo_inertia_eigenvalue > -1e-9);
    assert!(c.distance2 > 1e3);
    let constrained = identify(&mut acc, &log, &opts(true)).unwrap();
    assert!(constrained.x[zz6] >= -1e-9);
    assert!(
        constrained.relative_error > 1e3 * id.relative_error.max(1e-15)
            && constrained.relative_error > 1e-6,
        "constrained {:e} vs unconstrained {:e}",
        constrained.relative_error,
        id.relative_error
    );
}

/// Standard normal variate (Box-Muller).
fn gauss(r: &mut impl rand::Rng) -> f64 {
    let u: f64 = r.random_range(f64::EPSILON..1.0);
    let v: f64 = r.random_range(0.0..1.0);
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

/// Identification problems for the cross-checks: random trees (fixed seeds; their random
/// inertias are not all consistent, so constraints are active) and the RX-90 with ZZ6 < 0,
/// each with torque noise of 2 % of the joint's RMS torque (WLS).
fn cross_check_problems() -> Vec<(String, ModelAccess, MemoryLog)> {
    use robodyn_testing::{random_tree_description, rng, TreeOptions};
    let mut out = Vec::new();
    let mut noisy = |name: String, acc: ModelAccess, seed: u64| {
        let mut log = log(&acc);
        let n = acc.actuated_joints().len();
        let rms: Vec<f64> = (0..n)
            .map(|j| {
                (log.samples.iter().map(|s| s.y[j] * s.y[j]).sum::<f64>()
                    / log.samples.len() as f64)
                    .sqrt()
            })
            .collect();
        let mut r = rng(seed);
        for s in &mut log.samples {
            for (y, rms) in s.y.iter_mut().zip(&rms) {
                *y += 0.02 * rms * gauss(&mut r);
            }
        }
        out.push((name, acc, log));
    };
    for seed in 0..6u64 {
        let mut r = rng(300 + seed);
        let desc = random_tree_description(&mut r, 3 + seed as usize % 4, &TreeOptions::default());
        let acc = ModelAccess::new(desc).unwrap();
        if !acc.actuated_joints().is_empty() {
            noisy(format!("random tree {seed}"), acc, 900 + seed);
        }
    }
    let mut desc = rx90();
    desc.links[5].params[5] = robodyn::Expr::num(-0.01);
    noisy(
        "RX-90 with ZZ6 < 0".into(),
        ModelAccess::new(desc).unwrap(),
        7,
    );
    out
}

/// The largest difference of two identified vectors, relative to each parameter's size (at
/// least 1e-3 of the largest).
#[cfg(feature = "sdp")]
fn max_relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs() / y.abs().max(1e-3 * scale))
        .fold(0.0, f64::max)
}

/// The interior-point solver (default build) and Clarabel (feature `sdp`) find the same
/// optimum: identified vectors to 1e-6 relative, objectives (squared Mahalanobis distances) to
/// 1e-6 relative, on random trees and a deliberately inconsistent robot, where Clarabel reports
/// "Solved"; where it stops with reduced accuracy ("AlmostSolved"), the interior point's fit is
/// at least as good and the vectors agree to 1e-2.
#[cfg(feature = "sdp")]
#[test]
fn interior_point_and_clarabel_agree() {
    use robodyn::identification::consistency::Solver;
    for (name, mut acc, log) in cross_check_problems() {
        let run = |acc: &mut ModelAccess, solver| {
            let opt = Options {
                validation: None,
                consistent: true,
                standard: true,
                consistency_solver: solver,
                ..Options::default()
            };
            identify(acc, &log, &opt).unwrap()
        };
        let ipm = run(&mut acc, Solver::InteriorPoint);
        let cl = run(&mut acc, Solver::Clarabel);
        let (a, b) = (ipm.consistent.unwrap(), cl.consistent.unwrap());
        let dx = max_relative_difference(&ipm.x, &cl.x);
        let dd = (a.distance2 - b.distance2).abs() / b.distance2.max(1.0);
        eprintln!(
            "{name}: {} parameters, distance^2 {:.4e} vs {:.4e}, max relative difference of x \
             {dx:.1e}; {} | {}",
            ipm.x.len(),
            a.distance2,
            b.distance2,
            a.solver,
            b.solver
        );
        if b.solver.contains("Solved in") && !b.solver.contains("AlmostSolved") {
            assert!(dx < 1e-6, "{name}: x differs by {dx:e}");
            assert!(dd < 1e-6, "{name}: objective differs by {dd:e}");
        } else {
            // Clarabel stopped with reduced accuracy: the interior point's fit is no worse
            assert!(
                a.distance2 <= b.distance2 * (1.0 + 1e-6) + 1e-9,
                "{name}: worse fit"
            );
            assert!(dx < 1e-2, "{name}: x differs by {dx:e}");
        }
        assert!(a.min_pseudo_inertia_eigenvalue >= 0.0, "{name}");
    }
}

/// Noisy identifications whose unconstrained estimates are not all consistent: the returned
/// standard parameters satisfy the constraints exactly (every pseudo-inertia's computed
/// smallest eigenvalue >= 0, drive parameters >= 0).
#[test]
fn noisy_problems_give_exactly_consistent_parameters() {
    for (name, mut acc, log) in cross_check_problems() {
        let opt = Options {
            validation: None,
            consistent: true,
            standard: true,
            ..Options::default()
        };
        let id = identify(&mut acc, &log, &opt).unwrap();
        let c = id.consistent.as_ref().unwrap();
        eprintln!("{name}: {}; distance^2 {:.3e}", c.solver, c.distance2);
        let k = &c.standard;
        for j in 0..k.len() / 13 {
            let ev = pseudo_inertia(&k[13 * j..13 * j + 10]).symmetric_eigenvalues();
            assert!(ev.min() >= 0.0, "{name}, link {}: {ev:?}", j + 1);
        }
        let drives = id
            .model
            .map
            .iter()
            .flatten()
            .map(|(i, _)| *i)
            .filter(|i| i % 13 >= 10);
        for i in drives {
            assert!(k[i] >= 0.0, "{name}: drive parameter {i} = {}", k[i]);
        }
    }
}
