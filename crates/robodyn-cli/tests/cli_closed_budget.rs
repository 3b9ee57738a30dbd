//! Closed chains at any finite joint value (issue 24 item 1): `idm`, `ddm`, `closure` and
//! `simulate` of a closed robot answer or refuse within seconds, where a value of 1e300 made the
//! branch tracker follow its path forever. The answers are checked against the same commands at
//! the angle less whole turns (computed here from the periodicity, never by the reduction the
//! tracker uses), and the closure of every answer against its residual.

mod common;

use common::process::{robodyn_within, Run};
use common::{robot, tmp};
use std::f64::consts::PI;

/// Generous bound on one run (the machine is shared); the runs themselves take milliseconds.
const LIMIT: f64 = 30.0;

fn ok(args: &[&str]) -> Run {
    let r = robodyn_within(args, LIMIT);
    r.assert_no_crash("robodyn");
    assert_eq!(r.code, Some(0), "{args:?}: {}", r.stderr);
    r
}

/// The numbers of a one-row CSV table.
fn row(csv: &str) -> Vec<f64> {
    let line = csv.lines().nth(1).expect("a row");
    line.split(',').map(|x| x.parse().unwrap()).collect()
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| (x - y).abs() <= tol * (1.0 + y.abs()))
}

/// `x - 2 pi k` for the whole k that brings it nearest to 0: exact enough for |x| <= 1e7
/// (k 2 pi rounds at ~1e-9), which is what the comparisons below need.
fn less_turns(x: f64) -> f64 {
    x - 2.0 * PI * (x / (2.0 * PI)).round()
}

/// The SR400's base and wrist joints are on no loop: any value, even 1e300, is set at once (the
/// tracker followed a path of 1e300 rad, 0.25 rad at a time, before). Torques equal those at
/// the angle less whole turns.
#[test]
fn sr400_joints_off_the_loop_take_any_value() {
    let sr400 = robot("sr400.toml");
    for (q1, q5) in [
        (1e300_f64, 0.5_f64),
        (1e5, 0.5),
        (1e6, -1.7e308),
        (-3.7e9, 1e17),
    ] {
        let q = format!("--q={q1:e},0.2,0.3,0.4,{q5:e},1.6");
        for cmd in ["idm", "ddm"] {
            let r = ok(&[cmd, &sr400, &q, "--qd=1,2,3,4,5,6"]);
            let got = row(&r.stdout);
            assert!(got.iter().all(|x| x.is_finite()), "{cmd} {q}: {got:?}");
            if q1.abs() <= 1e7 && q5.abs() <= 1e7 {
                let reduced = format!("--q={},0.2,0.3,0.4,{},1.6", less_turns(q1), less_turns(q5));
                let want = row(&ok(&[cmd, &sr400, &reduced, "--qd=1,2,3,4,5,6"]).stdout);
                assert!(close(&got, &want, 1e-7), "{cmd} {q}: {got:?} vs {want:?}");
            }
        }
        let r = ok(&[
            "closure",
            &sr400,
            &format!("--qa={q1:e},0.2,0.3,0.4,{q5:e},1.6"),
        ]);
        assert!(r.stdout.contains("closure residual"), "{}", r.stdout);
    }
}

/// The four-bar's crank turns fully on its branch: whole turns are dropped after one turn is
/// checked, and the passive joints equal those at the angle less whole turns (the coupler's
/// modulo 2 pi); the loop is closed (residual of every closure equation).
#[test]
fn fourbar_crank_at_huge_angles_equals_the_reduced_angle() {
    let fourbar = robot("fourbar.toml");
    let closure = |qa: String| -> serde_json::Value {
        let r = ok(&["closure", &fourbar, &qa, "--format", "json"]);
        serde_json::from_str(&r.stdout).unwrap()
    };
    for q1 in [1e6, -3.3e6, 5e4, 2000.0] {
        let far = closure(format!("--qa={q1:e}"));
        let near = closure(format!("--qa={}", less_turns(q1)));
        assert!(far["residual"].as_f64().unwrap() < 1e-9, "{far}");
        for j in ["q2", "q3"] {
            let (a, b) = (
                far["q_p"][j].as_f64().unwrap(),
                near["q_p"][j].as_f64().unwrap(),
            );
            assert!(less_turns(a - b).abs() < 1e-7, "q1 = {q1}: {j} {a} vs {b}");
        }
    }
    // far beyond: answered (the residual says the loop is closed)
    for q1 in ["1e300", "-1.7976931348623157e308", "3e17"] {
        let far = closure(format!("--qa={q1}"));
        assert!(far["residual"].as_f64().unwrap() < 1e-9, "{far}");
    }
    // the torques too
    let idm = |q: String| row(&ok(&["idm", &fourbar, &q, "--qd=2", "--qdd=-1"]).stdout);
    let (a, b) = (
        idm("--q=1e6".into()),
        idm(format!("--q={}", less_turns(1e6))),
    );
    assert!(close(&a, &b, 1e-7), "{a:?} vs {b:?}");
}

/// A loop joint that cannot turn fully on its branch (the SR400's parallelogram flattens) keeps
/// its turns: 1e300 is refused at once, naming the joint and the budget.
#[test]
fn a_loop_joint_that_cannot_turn_is_refused_at_once() {
    let sr400 = robot("sr400.toml");
    for (cmd, q) in [
        ("idm", "--q=0.1,1e300,0.3,0.4,0.5,1.6"),
        ("ddm", "--q=0.1,0.2,0.3,0.4,0.5,-1e300"),
        ("closure", "--qa=0.1,2e5,0.3,0.4,0.5,1.6"),
    ] {
        let r = robodyn_within(&[cmd, &sr400, q], LIMIT);
        r.assert_no_crash(cmd);
        assert_eq!(r.code, Some(1), "{cmd} {q}: {}", r.stdout);
        assert!(
            r.stderr.contains("within the continuation's budget")
                && r.stderr.contains("revolute joint"),
            "{cmd} {q}: {}",
            r.stderr
        );
        assert!(
            !r.stderr.contains("0000000000000000"),
            "300 digits: {}",
            r.stderr
        );
    }
}

/// `simulate` of a closed robot from a huge initial angle of a joint off the loop ends (the
/// first evaluation moved the tracker along 1e300 rad before).
#[test]
fn simulate_closed_from_a_huge_angle_ends() {
    let out = tmp("budget", "run.csv");
    let r = robodyn_within(
        &[
            "simulate",
            &robot("sr400.toml"),
            "--duration",
            "0.01",
            "--dt",
            "0.001",
            "--q0=1e300,0.2,0.3,0.4,0.5,1.6",
            "--output",
            out.to_str().unwrap(),
        ],
        LIMIT,
    );
    r.assert_no_crash("simulate");
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().count(), 12, "{text}");
}

/// Non-finite values are refused before any continuation.
#[test]
fn non_finite_joint_values_are_refused() {
    let sr400 = robot("sr400.toml");
    for (q, why) in [
        (
            "--qa=nan,0.2,0.3,0.4,0.5,1.6",
            "`nan` is not a constant number",
        ),
        (
            "--qa=1e309,0.2,0.3,0.4,0.5,1.6",
            "`1e309` is not a finite number",
        ),
        ("--qa=0.1,0.2,0.3,0.4,0.5,1/0", "division by zero"),
        ("--qa=0.1,0.2,0.3,0.4,0.5,1e300*1e300", "infinite"),
    ] {
        let r = robodyn_within(&["closure", &sr400, q], LIMIT);
        r.assert_no_crash("closure");
        assert_eq!(r.code, Some(1));
        assert!(r.stderr.contains(why), "{}", r.stderr);
    }
}
