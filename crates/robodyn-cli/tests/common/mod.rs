//! Helpers shared by the CLI tests: run the binary, locate bundled robots, temporary files, CSV.
#![allow(dead_code)]

pub mod process;

use std::path::PathBuf;
use std::process::Command;

/// Run `robodyn ARGS`, assert success, return standard output.
pub fn run(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "robodyn {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Path of a bundled robot file.
pub fn robot(name: &str) -> String {
    format!("{}/../../robots/{name}", env!("CARGO_MANIFEST_DIR"))
}

/// A path in a temporary directory of this test binary (`tag` keeps test files apart).
pub fn tmp(tag: &str, name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("robodyn_cli_{tag}_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// CSV text -> header and rows of numbers.
pub fn csv(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|x| x.trim().parse().unwrap()).collect())
        .collect();
    (head, rows)
}

/// Whether GNU Octave (`octave-cli`) runs here; without it the optional check `octave` is skipped
/// visibly, or fails where `ROBODYN_REQUIRE` requires it (CI): `crate::harness`.
pub fn octave_available() -> bool {
    crate::harness::tool(
        "octave",
        "octave-cli",
        &["--norc", "--quiet", "--eval", "exit(0)"],
        "generated MATLAB (Debian package `octave`)",
    )
}

/// Run `octave-cli --eval CODE` in `dir`, assert success, return standard output.
pub fn octave_eval(dir: &std::path::Path, code: &str) -> String {
    let out = Command::new("octave-cli")
        .args(["--norc", "--quiet", "--eval", code])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "octave {code}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Run `robodyn ARGS`, assert failure, return standard error.
pub fn fails(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap();
    assert!(!out.status.success(), "robodyn {args:?} should fail");
    String::from_utf8_lossy(&out.stderr).to_string()
}

/// The parameters of an `identify --format json` report equal the numeric base parameters of
/// the robot file `robot` (`base-params --method numeric`), by name and to 1e-8 relative (1e-3
/// of the largest for the small ones): the arbiter of a noise-free identification.
pub fn assert_identified_base_params(robot: &str, report: &serde_json::Value) {
    let bp: serde_json::Value = serde_json::from_str(&run(&[
        "base-params",
        robot,
        "--method",
        "numeric",
        "--format",
        "json",
    ]))
    .unwrap();
    let base = bp["base"].as_array().unwrap();
    let params = report["parameters"].as_array().unwrap();
    assert_eq!(base.len(), params.len());
    let scale = base
        .iter()
        .map(|b| b["value"].as_f64().unwrap().abs())
        .fold(0.0, f64::max);
    for (b, p) in base.iter().zip(params) {
        assert_eq!(b["name"], p["name"]);
        let (x, t) = (p["value"].as_f64().unwrap(), b["value"].as_f64().unwrap());
        assert!(
            (x - t).abs() <= 1e-8 * t.abs().max(1e-3 * scale),
            "{}: {x} vs {t}",
            b["name"]
        );
    }
}
