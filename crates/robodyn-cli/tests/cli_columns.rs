//! What an input table's columns mean (issue 30 items 3 and 10): a misspelt input column is an
//! error naming it and the column it resembles (a table whose `qdd` columns were all misspelt was
//! computed with qdd = 0, exit 0); a column that is not an input is carried with a warning unless
//! declared with `--carry`; absent `qd`/`qdd` columns are said; small command-line slips get
//! clear messages.

mod common;

use common::process::{robodyn_within, Run};
use common::robot;
use std::path::PathBuf;

const LIMIT: f64 = 60.0;

fn table(name: &str, text: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("robodyn_columns_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn run(args: &[&str]) -> Run {
    let r = robodyn_within(args, LIMIT);
    r.assert_no_crash("robodyn");
    r
}

/// `qdd_1`..`qdd_6` instead of `qdd1`..`qdd6`: an error naming the columns and their inputs, in
/// every command that reads states (trees and closed chains).
#[test]
fn misspelt_input_columns_are_errors() {
    let rx90 = robot("rx90.toml");
    let sr400 = robot("sr400.toml");
    let six =
        |p: &str, sep: &str| -> Vec<String> { (1..=6).map(|j| format!("{p}{sep}{j}")).collect() };
    let rx90_table = |third: &str, sep: &str| {
        let h = [six("q", ""), six("qd", ""), six(third, sep)]
            .concat()
            .join(",");
        format!("{h}\n0.1,0.2,0.3,0.4,0.5,0.6,1,1,1,1,1,1,2,2,2,2,2,2\n")
    };
    let qdd_ = table("qdd_.csv", &rx90_table("qdd", "_"));
    let tau_ = table("tau_.csv", &rx90_table("tau", "_"));
    let sr400_cols: Vec<String> = [1, 2, 4, 5, 6, 7]
        .iter()
        .flat_map(|j| [format!("q{j}"), format!("qd{j}"), format!("QDD{j}")])
        .collect();
    let sr400_table = table(
        "sr400.csv",
        &format!(
            "{}\n0.1,0,0,0.2,0,0,0.3,0,0,0.4,0,0,0.5,0,0,1.6,0,0\n",
            sr400_cols.join(",")
        ),
    );
    for (cmd, r, t, bad, good) in [
        ("idm", &rx90, &qdd_, "qdd_1", "qdd1"),
        ("regressor", &rx90, &qdd_, "qdd_3", "qdd3"),
        ("ddm", &rx90, &tau_, "tau_6", "tau6"),
        ("idm", &sr400, &sr400_table, "QDD7", "qdd7"),
        ("regressor", &sr400, &sr400_table, "QDD1", "qdd1"),
    ] {
        let out = run(&[cmd, r, "--input", t.to_str().unwrap()]);
        assert_eq!(out.code, Some(1), "{cmd}: {}", out.stdout);
        assert!(out.stdout.is_empty(), "{cmd}: {}", out.stdout);
        let want = format!("`{bad}` (did you mean `{good}`?)");
        assert!(out.stderr.contains(&want), "{cmd}: {}", out.stderr);
    }
    // simulate's time series
    let track = table(
        "track.csv",
        "t,q_1,q2,q3,q4,q5,q6\n0,0,0,0,0,0,0\n1,0.1,0,0,0,0,0\n",
    );
    let torque = table(
        "torque.csv",
        "t,tau1,tau2,tau3,tau4,tau5,Tau6\n0,0,0,0,0,0,0\n",
    );
    let out_file = table("sim.csv", "");
    for (source, t, bad) in [
        ("--track", &track, "q_1"),
        ("--torque-csv", &torque, "Tau6"),
    ] {
        let mut args = vec![
            "simulate",
            &rx90,
            "--duration",
            "0.01",
            "--output",
            out_file.to_str().unwrap(),
            source,
            t.to_str().unwrap(),
        ];
        if source == "--track" {
            args.extend(["--kp", "100", "--kd", "10"]);
        }
        let out = run(&args);
        assert_eq!(out.code, Some(1), "{source}: {}", out.stderr);
        assert!(out.stderr.contains(&format!("`{bad}`")), "{}", out.stderr);
    }
}

/// A column that is neither an input nor a joint column of the robot is carried with a warning
/// that names it and the inputs; declared with --carry it is carried silently; `t` and a
/// measured `tau<j>` are carried silently, but not next to a computed column of the same name.
#[test]
fn unknown_columns_are_carried_with_a_warning() {
    let rx90 = robot("rx90.toml");
    let t = table(
        "extra.csv",
        "t,label,q1,q2,q3,q4,q5,q6,tau1\n0.5,7,0.1,0.2,0.3,0.4,0.5,0.6,99\n",
    );
    let t = t.to_str().unwrap();
    let out = run(&["regressor", &rx90, "--input", t]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(
        out.stdout.starts_with("t,label,tau1,state,joint,tau_e,"),
        "{}",
        out.stdout
    );
    assert!(
        out.stderr.contains("warning")
            && out.stderr.contains("`label`")
            && out
                .stderr
                .contains("q<j>, qd<j>, qdd<j> for j in [1, 2, 3, 4, 5, 6]"),
        "{}",
        out.stderr
    );
    assert!(
        !out.stderr.contains("`t`") && !out.stderr.contains("`tau1`"),
        "{}",
        out.stderr
    );
    let out = run(&["regressor", &rx90, "--input", t, "--carry", "label"]);
    assert_eq!(out.code, Some(0));
    assert!(!out.stderr.contains("warning"), "{}", out.stderr);
    let out = run(&["regressor", &rx90, "--input", t, "--carry", "lable"]);
    assert_eq!(out.code, Some(1));
    assert!(out.stderr.contains("--carry lable"), "{}", out.stderr);
    // idm computes tau1: a carried tau1 beside it would be a second column of that name
    let out = run(&["idm", &rx90, "--input", t, "--carry", "label"]);
    assert_eq!(out.code, Some(1), "{}", out.stdout);
    assert!(out.stderr.contains("`tau1`"), "{}", out.stderr);
}

/// Absent qd and qdd columns (all of them) are zeros, and a note says so.
#[test]
fn absent_velocities_and_accelerations_are_said() {
    let rx90 = robot("rx90.toml");
    let t = table("q_only.csv", "q1,q2,q3,q4,q5,q6\n0.1,0.2,0.3,0.4,0.5,0.6\n");
    let out = run(&["idm", &rx90, "--input", t.to_str().unwrap()]);
    assert_eq!(out.code, Some(0));
    assert!(
        out.stderr.contains("no qd columns") && out.stderr.contains("no qdd columns"),
        "{}",
        out.stderr
    );
    let track = table(
        "track_q.csv",
        "t,q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0,0\n1,0.1,0,0,0,0,0\n",
    );
    let o = table("track_out.csv", "");
    let out = run(&[
        "simulate",
        &rx90,
        "--duration",
        "0.01",
        "--output",
        o.to_str().unwrap(),
        "--track",
        track.to_str().unwrap(),
        "--kp",
        "100",
        "--kd",
        "10",
    ]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
    assert!(
        out.stderr.contains("no qd columns") && out.stderr.contains("slope"),
        "{}",
        out.stderr
    );
}

/// A table named after the joints, read without `--names joint`: the missing columns and the hint.
#[test]
fn the_other_naming_is_pointed_out() {
    let urdf = robot("rx90.urdf");
    let out = run(&["idm", &urdf, "--q=0,0,0,0,0,0", "--names", "joint"]);
    let header = out.stdout.lines().next().unwrap().replace("tau_", "q_");
    let t = table(
        "joint_named.csv",
        &format!("{header}\n0.1,0.2,0.3,0.4,0.5,0.6\n"),
    );
    let out = run(&["idm", &urdf, "--input", t.to_str().unwrap()]);
    assert_eq!(out.code, Some(1));
    assert!(
        out.stderr.contains("missing columns `q1`") && out.stderr.contains("give --names joint"),
        "{}",
        out.stderr
    );
    let out = run(&[
        "idm",
        &urdf,
        "--input",
        t.to_str().unwrap(),
        "--names",
        "joint",
    ]);
    assert_eq!(out.code, Some(0), "{}", out.stderr);
}

/// `--q 1,2,` names the trailing comma (it said "`` is not a number"); `--kp`/`--kd` without
/// `--track` are refused (they were ignored).
#[test]
fn command_line_slips_are_named() {
    let rx90 = robot("rx90.toml");
    for (q, what) in [
        ("--q=0.1,0.2,0.3,0.4,0.5,", "trailing comma"),
        ("--q=,0.2,0.3,0.4,0.5,0.6", "before the first value"),
        ("--q=0.1,0.2,,0.4,0.5,0.6", "between commas"),
    ] {
        let out = run(&["idm", &rx90, q]);
        assert_eq!(out.code, Some(1));
        assert!(
            out.stderr.contains(what) && !out.stderr.contains("``"),
            "{}",
            out.stderr
        );
    }
    let o = table("kp_out.csv", "");
    for gain in ["--kp", "--kd"] {
        let out = run(&[
            "simulate",
            &rx90,
            "--duration",
            "0.01",
            "--output",
            o.to_str().unwrap(),
            gain,
            "100",
        ]);
        assert_ne!(out.code, Some(0), "{gain} without --track was accepted");
        assert!(out.stderr.contains("--track"), "{}", out.stderr);
    }
}
