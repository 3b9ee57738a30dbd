//! `robodyn identify --payload LINK` and `--estimate-gains` end to end on the RX-90: `excite`
//! designs a motion, `simulate --track` logs the robot and the robot carrying a payload (the
//! file's link-6 parameters plus point masses, given with `--set`), and the identification
//! finds the payload (robot known, and before/after) and the drive gains of a log of currents
//! (the torques divided by known gains, written as i<j> columns) with a torque reference and with
//! the known payload.

mod common;
use common::{robot, run, tmp};
use robodyn::identification::model_access::ModelAccess;
use std::path::{Path, PathBuf};
use std::process::Command;

const NAMES: [&str; 10] = ["XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"];
const GAINS: [f64; 6] = [31.0, 47.0, 22.0, 7.5, 6.2, 3.9];

/// Point masses (m, r in R_6) as the 10 standard parameters, from their definitions.
fn payload() -> [f64; 10] {
    let masses = [(1.5, [0.02, 0.01, 0.1]), (0.7, [-0.04, 0.03, 0.05])];
    let mut k = [0.0; 10];
    for (m, r) in masses {
        let r2: f64 = r.iter().map(|v| v * v).sum();
        let j = |a: usize, b: usize| m * (if a == b { r2 } else { 0.0 } - r[a] * r[b]);
        let v = [
            j(0, 0),
            j(0, 1),
            j(0, 2),
            j(1, 1),
            j(1, 2),
            j(2, 2),
            m * r[0],
            m * r[1],
            m * r[2],
            m,
        ];
        for i in 0..10 {
            k[i] += v[i];
        }
    }
    k
}

/// `simulate --track` of the reference, with `--set` values.
fn simulate(reference: &Path, out: &Path, set: &[String]) {
    let rx90 = robot("rx90.toml");
    let mut args: Vec<String> = [
        "simulate",
        &rx90,
        "--duration",
        "8",
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
        out.to_str().unwrap(),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for s in set {
        args.extend(["--set".to_string(), s.clone()]);
    }
    let refs: Vec<&str> = args.iter().map(|s| s.as_str()).collect();
    run(&refs);
}

/// A log of torques rewritten as currents i<j> = tau<j> / g_j.
fn as_currents(log: &Path, out: &Path) {
    let text = std::fs::read_to_string(log).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut s = head
        .iter()
        .map(|h| h.replacen("tau", "i", 1))
        .collect::<Vec<_>>()
        .join(",");
    s.push('\n');
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let row: Vec<String> = line
            .split(',')
            .zip(&head)
            .map(|(v, h)| match h.strip_prefix("tau") {
                Some(j) => {
                    let g = GAINS[j.parse::<usize>().unwrap() - 1];
                    format!("{:?}", v.parse::<f64>().unwrap() / g)
                }
                None => v.to_string(),
            })
            .collect();
        s.push_str(&row.join(","));
        s.push('\n');
    }
    std::fs::write(out, s).unwrap();
}

/// The logs: empty and loaded robot tracking one excitation.
fn logs() -> (PathBuf, PathBuf, [f64; 10]) {
    let rx90 = robot("rx90.toml");
    let reference = tmp("gains_payload", "excite.csv");
    run(&[
        "excite",
        &rx90,
        "--period",
        "4",
        "--harmonics",
        "4",
        "--qd-max",
        "1.5",
        "--qdd-max",
        "6",
        "--iterations",
        "60",
        "--periods",
        "2",
        "--output",
        reference.to_str().unwrap(),
    ]);
    let empty = tmp("gains_payload", "empty.csv");
    simulate(&reference, &empty, &[]);
    let phi = payload();
    let acc = ModelAccess::new(robodyn::io::load_description(&rx90).unwrap()).unwrap();
    let k = acc.standard_parameters();
    let set: Vec<String> = (0..10)
        .map(|i| format!("{}6={:?}", NAMES[i], k[13 * 5 + i] + phi[i]))
        .collect();
    let loaded = tmp("gains_payload", "loaded.csv");
    simulate(&reference, &loaded, &set);
    (empty, loaded, phi)
}

fn close(got: f64, truth: f64, scale: f64, tol: f64, what: &str) {
    assert!(
        (got - truth).abs() <= tol * truth.abs().max(1e-3 * scale),
        "{what}: {got} vs {truth}"
    );
}

#[test]
fn payload_and_gains_from_the_command_line() {
    let (empty, loaded, phi) = logs();
    let rx90 = robot("rx90.toml");
    let scale = phi.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let common = ["--estimator", "ols", "--validation", "none"];
    for before in [None, Some(&empty)] {
        let mut args = vec!["identify", &rx90, "--payload", "6", "--data"];
        args.push(loaded.to_str().unwrap());
        if let Some(b) = before {
            args.extend(["--before", b.to_str().unwrap()]);
        }
        args.extend(common);
        let mut json = args.clone();
        json.extend(["--format", "json"]);
        let v: serde_json::Value = serde_json::from_str(&run(&json)).unwrap();
        assert_eq!(v["structural_rank"], 10);
        assert_eq!(v["rank"], 10);
        for (i, p) in v["payload"].as_array().unwrap().iter().enumerate() {
            assert_eq!(p["name"], NAMES[i]);
            close(p["value"].as_f64().unwrap(), phi[i], scale, 1e-7, NAMES[i]);
        }
        let text = run(&args);
        assert!(
            text.contains("Payload on link 6") && text.contains("10 of 10"),
            "{text}"
        );
    }
    // drive gains: currents of the empty robot, with a torque reference and with the payload
    let currents = tmp("gains_payload", "currents.csv");
    as_currents(&empty, &currents);
    let loaded_currents = tmp("gains_payload", "loaded_currents.csv");
    as_currents(&loaded, &loaded_currents);
    let known = format!(
        "6:{}",
        phi.iter()
            .map(|v| format!("{v:?}"))
            .collect::<Vec<_>>()
            .join(",")
    );
    let torque_ref = ["--reference", empty.to_str().unwrap()];
    let payload_ref = [
        "--reference",
        loaded_currents.to_str().unwrap(),
        "--known-payload",
        &known,
    ];
    for reference in [&torque_ref[..], &payload_ref[..]] {
        let mut args = vec!["identify", &rx90, "--estimate-gains", "--data"];
        args.push(currents.to_str().unwrap());
        args.extend(reference);
        args.extend(common);
        let mut json = args.clone();
        json.extend(["--format", "json"]);
        let v: serde_json::Value = serde_json::from_str(&run(&json)).unwrap();
        for (k, g) in v["gains"].as_array().unwrap().iter().enumerate() {
            close(g["value"].as_f64().unwrap(), GAINS[k], 50.0, 1e-7, "gain");
        }
        let text = run(&args);
        assert!(
            text.contains("Drive gains of") && text.contains("g6"),
            "{text}"
        );
    }
    // a log of torques as --data of --estimate-gains, and --known-payload over torque logs
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["identify", &rx90, "--estimate-gains", "--data"])
        .arg(&empty)
        .args(["--reference"])
        .arg(&empty)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("motor currents"));
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["identify", &rx90, "--estimate-gains", "--data"])
        .arg(&currents)
        .args(["--reference"])
        .arg(&empty)
        .args(["--known-payload", &known])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--known-payload"));
}
