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

/// Global and per-joint ||tau_log - tau_predicted|| / ||tau_log|| over the predicted samples
/// in [from, to) of the log's duration (to = 1: to the end), matched by their time stamps.
fn segment_errors(log: &[Vec<f64>], pred: &[Vec<f64>], (from, to): (f64, f64)) -> (f64, Vec<f64>) {
    let (t0, t1) = (log[0][0], log[log.len() - 1][0]);
    let (lo, hi) = (t0 + from * (t1 - t0), t0 + to * (t1 - t0));
    let (mut err, mut norm) = ([0.0f64; 6], [0.0f64; 6]);
    let mut i = 0;
    for p in pred {
        while log[i][0] < p[0] {
            i += 1;
        }
        assert_eq!(log[i][0], p[0], "a predicted sample at a time of the log");
        if p[0] < lo || (to < 1.0 && p[0] >= hi) {
            continue;
        }
        for k in 0..6 {
            // the TX40 log's columns: t, q1..q6, tau1..tau6
            err[k] += (log[i][7 + k] - p[1 + k]).powi(2);
            norm[k] += log[i][7 + k].powi(2);
        }
    }
    let global = (err.iter().sum::<f64>() / norm.iter().sum::<f64>()).sqrt();
    (global, (0..6).map(|k| (err[k] / norm[k]).sqrt()).collect())
}

/// Issue 31's done-means: the TX40's default run (the README's command: WLS, `--offsets`) with
/// 0.6:0.8, then 0.8:1, held out; the raw 5 kHz torques of the log against `--predictions`
/// (both files read here) have a global relative error of at most 0.173 and 0.233 (a reference
/// implementation's), and on 0.6:0.8 no joint worse than 1.05 x the reference's (0.187 0.154
/// 0.175 0.107 0.394 0.221).
#[test]
fn tx40_default_run_meets_the_reference_on_held_out_segments() {
    let Some(data) = crate::harness::shared("data/tx40/tx40_joint.csv", "the TX40 predictions")
    else {
        return;
    };
    let (head, log) = csv(&std::fs::read_to_string(&data).unwrap());
    assert_eq!(head[0], "t");
    assert_eq!(
        head[7..13],
        ["tau1", "tau2", "tau3", "tau4", "tau5", "tau6"]
    );
    let reference_joints = [0.187, 0.154, 0.175, 0.107, 0.394, 0.221];
    for (segment, (from, to), target) in
        [("0.6:0.8", (0.6, 0.8), 0.173), ("0.8:1", (0.8, 1.0), 0.233)]
    {
        let pred = tmp("predictions_tx40", &format!("pred_{segment}.csv"));
        run(&[
            "identify",
            &robot("tx40.toml"),
            "--data",
            data.to_str().unwrap(),
            "--offsets",
            "--validation",
            segment,
            "--predictions",
            pred.to_str().unwrap(),
        ]);
        let (_, p) = csv(&std::fs::read_to_string(&pred).unwrap());
        let (global, joints) = segment_errors(&log, &p, (from, to));
        eprintln!("TX40 held out {segment}: raw-torque error {global:.4}, joints {joints:.3?}");
        assert!(global <= target, "{segment}: {global} > {target}");
        if segment == "0.6:0.8" {
            for (j, (e, r)) in joints.iter().zip(reference_joints).enumerate() {
                assert!(*e <= 1.05 * r, "joint {}: {e} > 1.05 x {r}", j + 1);
            }
        }
    }
}
