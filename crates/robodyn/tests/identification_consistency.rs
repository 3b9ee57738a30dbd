//! Physically consistent parameters (SDP with Clarabel's PSD cone): the robot written from an
//! identification is consistent and reproduces the identified base parameters; deliberately
//! inconsistent estimates are projected onto the consistent set and reported.

use robodyn::identification::consistency::{min_pseudo_inertia_eigenvalue, pseudo_inertia};
use robodyn::identification::data::MemoryLog;
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::model_access::{load_description, save_description, ModelAccess};
use robodyn::identification::{identify, Estimator, Options};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// The RX-90 with friction on every joint (the file has none: true values at the boundary
/// FS = FV = 0 of the consistent set would make rounding-level estimates "inconsistent").
fn rx90() -> robodyn::RobotDescription {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/rx90.toml");
    let mut d = load_description(&p, &BTreeMap::new()).unwrap();
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
    let reloaded = ModelAccess::new(load_description(&path, &BTreeMap::new()).unwrap()).unwrap();
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
