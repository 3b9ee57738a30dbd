//! `robodyn identify` from several logs (`--data a --data b`) and from their statistics
//! (`--partial`, `--merge`): the real TX40 log cut into two logs gives the same numbers by both
//! routes; a simulated RX-90 log cut into three logs gives, from the merged statistics, the base
//! parameters `base-params --method numeric` computes from the robot file; statistics of another
//! robot or other options are refused.

mod common;
use common::{assert_identified_base_params, fails, robot, run, tmp};
use std::path::{Path, PathBuf};

/// The CSV `src` cut into `parts` files of consecutive rows (each with the header).
fn split(src: &Path, parts: usize, tag: &str) -> Vec<PathBuf> {
    let text = std::fs::read_to_string(src).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap();
    let rows: Vec<&str> = lines.filter(|l| !l.trim().is_empty()).collect();
    let per = rows.len().div_ceil(parts);
    rows.chunks(per)
        .enumerate()
        .map(|(k, chunk)| {
            let p = tmp(tag, &format!("part{k}.csv"));
            std::fs::write(&p, format!("{header}\n{}\n", chunk.join("\n"))).unwrap();
            p
        })
        .collect()
}

fn json(text: &str) -> serde_json::Value {
    serde_json::from_str(text).unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The TX40 log (README's command) as two logs: `--data a --data b` and `--merge` of the
/// statistics written by `--partial` for each give the same parameters, standard deviations,
/// weights and validation errors, every number; the report names both logs.
#[test]
fn tx40_halves_merged_equal_the_two_logs_together() {
    let Some(data) = crate::harness::shared("data/tx40/tx40_joint.csv", "the TX40 merge") else {
        return;
    };
    let tx40 = robot("tx40.toml");
    let halves = split(&data, 2, "many_tx40");
    let common = ["--offsets", "--validation", "0.6:0.8", "--format", "json"];
    let mut args = vec![
        "identify",
        &tx40,
        "--data",
        s(&halves[0]),
        "--data",
        s(&halves[1]),
    ];
    args.extend(common);
    let together = json(&run(&args));
    let mut partials = Vec::new();
    for (k, h) in halves.iter().enumerate() {
        let p = tmp("many_tx40", &format!("stats{k}.json"));
        let out = run(&[
            "identify",
            &tx40,
            "--data",
            s(h),
            "--offsets",
            "--validation",
            "0.6:0.8",
            "--partial",
            s(&p),
        ]);
        assert!(out.is_empty(), "--partial prints no report: {out}");
        partials.push(p);
    }
    let mut args = vec![
        "identify",
        &tx40,
        "--merge",
        s(&partials[0]),
        s(&partials[1]),
    ];
    args.extend(common);
    let merged = json(&run(&args));
    for key in [
        "parameters",
        "condition_number",
        "relative_error",
        "per_joint",
        "validation",
    ] {
        assert_eq!(merged[key], together[key], "{key}");
    }
    assert!(merged["processing"]["source"]
        .as_str()
        .unwrap()
        .starts_with("2 logs ("));
    assert_eq!(merged["processing"]["samples"], 45000);
    // each half alone differs (the merge is not one of them)
    let mut args = vec!["identify", &tx40, "--merge", s(&partials[0])];
    args.extend(common);
    let first = json(&run(&args));
    assert_ne!(first["parameters"], merged["parameters"]);
    // the TX40's statistics against the RX-90, or with another bandwidth
    let e = fails(&[
        "identify",
        &robot("rx90.toml"),
        "--merge",
        s(&partials[0]),
        "--offsets",
        "--validation",
        "0.6:0.8",
    ]);
    assert!(e.contains("another robot") && e.contains("TX40"), "{e}");
    let e = fails(&[
        "identify",
        &tx40,
        "--merge",
        s(&partials[0]),
        "--offsets",
        "--validation",
        "0.6:0.8",
        "--bandwidth",
        "10",
    ]);
    assert!(e.contains("bandwidth"), "{e}");
    let e = fails(&[
        "identify",
        &tx40,
        "--merge",
        s(&partials[0]),
        "--validation",
        "0.6:0.8",
    ]);
    assert!(e.contains("offsets"), "{e}");
    // the same log twice: its rows would count twice
    let e = fails(&[
        "identify",
        &tx40,
        "--data",
        s(&halves[0]),
        "--data",
        s(&halves[0]),
        "--offsets",
    ]);
    assert!(e.contains("the same log twice"), "{e}");
}

/// A noise-free simulated RX-90 log (excite, simulate) cut into three logs, each written as
/// statistics by `--partial` and merged (together with a statistics file of two of them):
/// the OLS estimate equals the base parameters of the robot file (`base-params --method
/// numeric`, an independent route) to 1e-8.
#[test]
fn rx90_statistics_of_three_logs_give_the_true_base_parameters() {
    let rx90 = robot("rx90.toml");
    let reference = tmp("many_rx90", "excite.csv");
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
        "30",
        "--rate",
        "200",
        "--periods",
        "2",
        "--output",
        s(&reference),
    ]);
    let traj = tmp("many_rx90", "traj.csv");
    run(&[
        "simulate",
        &rx90,
        "--duration",
        "8",
        "--dt",
        "0.001",
        "--output-step",
        "0.004",
        "--track",
        s(&reference),
        "--kp",
        "400",
        "--kd",
        "40",
        "--coulomb-smoothing",
        "0",
        "--output",
        s(&traj),
    ]);
    let parts = split(&traj, 3, "many_rx90");
    let (a, bc) = (tmp("many_rx90", "a.json"), tmp("many_rx90", "bc.json"));
    // every run with the same options: OLS, no validation segment
    let identify = |extra: &[&str]| {
        let mut args = vec!["identify", rx90.as_str()];
        args.extend(extra);
        args.extend(["--estimator", "ols", "--validation", "none"]);
        run(&args)
    };
    identify(&["--data", s(&parts[0]), "--partial", s(&a)]);
    identify(&[
        "--data",
        s(&parts[1]),
        "--data",
        s(&parts[2]),
        "--partial",
        s(&bc),
    ]);
    let v = json(&identify(&["--merge", s(&a), s(&bc), "--format", "json"]));
    assert_identified_base_params(&rx90, &v);
    assert!(v["processing"]["source"]
        .as_str()
        .unwrap()
        .starts_with("3 logs ("));
    // IDIM-IV needs the logs; a file that is not statistics; --partial with a report flag
    let e = fails(&[
        "identify",
        &rx90,
        "--merge",
        s(&a),
        "--estimator",
        "iv",
        "--validation",
        "none",
    ]);
    assert!(e.contains("IDIM-IV"), "{e}");
    let e = fails(&["identify", &rx90, "--merge", s(&parts[0])]);
    assert!(e.contains("part0.csv") && e.contains("not JSON"), "{e}");
    let e = fails(&[
        "identify",
        &rx90,
        "--data",
        s(&parts[0]),
        "--partial",
        s(&a),
        "--plot",
        "x.svg",
    ]);
    assert!(e.contains("--plot"), "{e}");
    let e = fails(&["identify", &rx90]);
    assert!(e.contains("--data"), "{e}");
}
