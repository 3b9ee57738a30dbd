//! `robodyn identify --predictions FILE`: the identified model's torques at every sample of the
//! log. On a noise-free simulated log (`excite`, then `simulate --track`, which integrates the
//! direct dynamics: another route than identification's regressor), the OLS predictions equal
//! the simulated torques sample by sample; a mismatched count of files, a log on standard input
//! and a predictions file that is a log are refused before anything is written.

mod common;
use common::{csv, fails, robot, run, tmp};

/// A simulated log of the RX-90 tracking an excitation (t, q, qd, qdd, tau at 250 Hz).
fn simulated_log(tag: &str) -> (String, std::path::PathBuf) {
    let rx90 = robot("rx90.toml");
    let reference = tmp(tag, "excite.csv");
    run(&[
        "excite",
        &rx90,
        "--period",
        "4",
        "--harmonics",
        "3",
        "--qd-max",
        "1.5",
        "--qdd-max",
        "6",
        "--iterations",
        "20",
        "--rate",
        "200",
        "--output",
        reference.to_str().unwrap(),
    ]);
    let traj = tmp(tag, "traj.csv");
    run(&[
        "simulate",
        &rx90,
        "--duration",
        "6",
        "--dt",
        "0.001",
        "--output-step",
        "0.004",
        "--track",
        reference.to_str().unwrap(),
        "--kp",
        "400",
        "--kd",
        "40",
        "--coulomb-smoothing",
        "0",
        "--output",
        traj.to_str().unwrap(),
    ]);
    (rx90, traj)
}

#[test]
fn predictions_equal_the_simulated_torques() {
    let (rx90, traj) = simulated_log("predictions");
    let pred = tmp("predictions", "pred.csv");
    run(&[
        "identify",
        &rx90,
        "--data",
        traj.to_str().unwrap(),
        "--estimator",
        "ols",
        "--validation",
        "0.7:1",
        "--predictions",
        pred.to_str().unwrap(),
    ]);
    let (lh, log) = csv(&std::fs::read_to_string(&traj).unwrap());
    let (ph, p) = csv(&std::fs::read_to_string(&pred).unwrap());
    assert_eq!(ph, ["t", "tau1", "tau2", "tau3", "tau4", "tau5", "tau6"]);
    // the log gives qd, qdd: nothing filtered, no border, every sample predicted
    assert_eq!(p.len(), log.len());
    let tcol = lh.iter().position(|h| h == "t").unwrap();
    let taucols: Vec<usize> = (1..=6)
        .map(|j| lh.iter().position(|h| *h == format!("tau{j}")).unwrap())
        .collect();
    let scale = log
        .iter()
        .flat_map(|r| taucols.iter().map(move |&c| r[c].abs()))
        .fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for (r, q) in log.iter().zip(&p) {
        assert_eq!(r[tcol], q[0]);
        for (k, &c) in taucols.iter().enumerate() {
            assert!(q[1 + k].is_finite());
            worst = worst.max((r[c] - q[1 + k]).abs());
        }
    }
    eprintln!("largest |tau_simulated - tau_predicted| {worst:.2e} N m (scale {scale:.1})");
    assert!(worst < 1e-6 * scale, "{worst} (scale {scale})");
}

#[test]
fn predictions_refused_with_a_reason() {
    let (rx90, traj) = simulated_log("predictions_refused");
    let t = traj.to_str().unwrap();
    let before = std::fs::read(&traj).unwrap();
    let a = tmp("predictions_refused", "a.csv");
    let a = a.to_str().unwrap();
    let e = fails(&[
        "identify",
        &rx90,
        "--data",
        t,
        "--data",
        t,
        "--predictions",
        a,
    ]);
    assert!(e.contains("one predictions file per log"), "{e}");
    assert!(!std::path::Path::new(a).exists());
    let e = fails(&["identify", &rx90, "--data", "-", "--predictions", a]);
    assert!(e.contains("standard input"), "{e}");
    let e = fails(&["identify", &rx90, "--data", t, "--predictions", t]);
    assert!(e.contains("same file"), "{e}");
    assert_eq!(
        std::fs::read(&traj).unwrap(),
        before,
        "the log is untouched"
    );
    let e = fails(&["identify", &rx90, "--data", t, "--predictions", "-"]);
    assert!(e.contains("a file name expected"), "{e}");
}
