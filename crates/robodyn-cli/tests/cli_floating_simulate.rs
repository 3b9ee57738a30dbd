//! `robodyn simulate` of a floating-base robot: the RX-90 on a free base body (TOML
//! `base = "floating"`), released spinning. Checked against what a free body must do: its
//! linear momentum grows by M g t, its angular momentum about the centre of mass and its energy
//! stay constant (no friction, no torque), and its quaternion stays unit; the options of a
//! floating base are refused for a fixed robot and a non-unit quaternion is refused.

mod common;

use common::process::robodyn_within;
use common::{csv, robot, run, tmp};

/// The bundled RX-90 on a floating base body of 20 kg.
fn floating_rx90() -> String {
    let text = std::fs::read_to_string(robot("rx90.toml")).unwrap();
    let path = tmp("floating_sim", "rx90float.toml");
    std::fs::write(
        &path,
        format!(
            "base = \"floating\"\n{text}\n[base_link]\nXX = 2.0\nYY = 2.0\nZZ = 1.5\nMZ = 5.0\nM = 20.0\n"
        ),
    )
    .unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn a_floating_robot_falls_and_spins_as_a_free_body() {
    let r = floating_rx90();
    let out = run(&[
        "simulate",
        &r,
        "--duration",
        "1",
        "--base-pose",
        "0,0,1,0,0,0,1",
        "--base-twist",
        "0.2,0,0,0.5,0,2",
        "--rtol",
        "1e-10",
        "--atol",
        "1e-12",
        "--output",
        "-",
    ]);
    let (head, rows) = csv(&out);
    let c = |name: &str| -> Vec<f64> {
        let k = head
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no {name}"));
        rows.iter().map(|r| r[k]).collect()
    };
    assert_eq!(
        &head[..9],
        ["t", "base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw", "q1"]
    );
    let t = c("t");
    let drift = |x: &[f64]| x.iter().map(|v| (v - x[0]).abs()).fold(0.0, f64::max);
    for name in [
        "energy",
        "momentum_x",
        "momentum_y",
        "angular_momentum_x",
        "angular_momentum_y",
        "angular_momentum_z",
    ] {
        let x = c(name);
        assert!(
            drift(&x) < 1e-7 * (1.0 + x[0].abs()),
            "{name} drifts {}",
            drift(&x)
        );
    }
    // P_z(t) = P_z(0) - M g t, M = 20 kg base + the RX-90's link masses (from the file)
    let pz = c("momentum_z");
    let mass = (pz[0] - pz[pz.len() - 1]) / (9.81 * t[t.len() - 1]);
    let links: f64 = {
        let text = std::fs::read_to_string(robot("rx90.toml")).unwrap();
        text.lines()
            .filter_map(|l| l.trim().strip_prefix("M = "))
            .map(|v| v.trim().parse::<f64>().unwrap())
            .sum()
    };
    assert!(
        (mass - (20.0 + links)).abs() < 1e-6,
        "mass {mass} vs {}",
        20.0 + links
    );
    for k in 0..t.len() {
        let n: f64 = ["base_qx", "base_qy", "base_qz", "base_qw"]
            .iter()
            .map(|a| c(a)[k].powi(2))
            .sum::<f64>()
            .sqrt();
        assert!((n - 1.0).abs() < 1e-14, "row {k}: quaternion norm {n}");
    }
}

#[test]
fn floating_base_options_are_checked() {
    let r = floating_rx90();
    let bad = robodyn_within(
        &[
            "simulate",
            &r,
            "--duration",
            "0.1",
            "--base-pose",
            "0,0,0,0,0,0,2",
            "--output",
            "-",
        ],
        60.0,
    );
    assert_eq!(bad.code, Some(1), "{}", bad.stderr);
    assert!(
        bad.stderr.contains("--base-pose") && bad.stderr.contains("norm"),
        "{}",
        bad.stderr
    );
    let fixed = robodyn_within(
        &[
            "simulate",
            &robot("rx90.toml"),
            "--duration",
            "0.1",
            "--base-twist",
            "0,0,0,0,0,1",
            "--output",
            "-",
        ],
        60.0,
    );
    assert_eq!(fixed.code, Some(1), "{}", fixed.stderr);
    assert!(
        fixed.stderr.contains("--base-twist") && fixed.stderr.contains("fixed"),
        "{}",
        fixed.stderr
    );
}
