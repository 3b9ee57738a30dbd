//! `idm`, `ddm`, `simulate`, `inertia` on a robot with a motor-joint transmission and motors'
//! drive parameters (the TX40's coupled wrist, motor 6 turning with q5 + q6): the torques are
//! joint-side and include R^T (IA m_dd + FV m_d + FS sign(m_d)), checked against that formula
//! computed here from the bundled TX40 (no drive parameters); ddm inverts idm; the side is
//! stated on stderr; the commands that do not apply transmissions refuse.

mod common;
use common::{csv, fails, robot, tmp};
use std::process::Command;

/// Motors' IA, FS, FV (motor units) given with --set.
const MOTORS: [(f64, f64, f64); 6] = [
    (3e-5, 0.2, 8e-3),
    (3e-5, 0.25, 5e-3),
    (5e-5, 0.12, 1e-3),
    (1.2e-5, 0.04, 5e-4),
    (1.8e-5, 0.06, 6e-4),
    (9e-6, 0.07, 6e-4),
];

/// R of robots/tx40.toml.
const R: [[f64; 6]; 6] = [
    [32.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 32.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 45.0, 0.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, -48.0, 0.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 45.0, 0.0],
    [0.0, 0.0, 0.0, 0.0, 32.0, 32.0],
];

/// `--set` of the motors' parameters, and inertia of link 6 about its axis.
fn sets() -> Vec<String> {
    let mut s = Vec::new();
    for (k, (ia, fs, fv)) in MOTORS.iter().enumerate() {
        let j = k + 1;
        s.extend([
            format!("IA{j}={ia}"),
            format!("FS{j}={fs}"),
            format!("FV{j}={fv}"),
        ]);
    }
    s.extend(["XX6=1e-3", "YY6=1e-3", "ZZ6=1e-3"].map(String::from));
    s.into_iter()
        .flat_map(|x| ["--set".to_string(), x])
        .collect()
}

/// Run robodyn, assert success, return (stdout, stderr).
fn run2(args: &[&str]) -> (String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert!(out.status.success(), "robodyn {args:?}: {err}");
    (String::from_utf8(out.stdout).unwrap(), err)
}

fn with_sets<'a>(head: &[&'a str], sets: &'a [String], tail: &[&'a str]) -> Vec<&'a str> {
    let mut v = head.to_vec();
    v.extend(sets.iter().map(String::as_str));
    v.extend_from_slice(tail);
    v
}

fn list(x: &[f64]) -> String {
    x.iter()
        .map(|v| format!("{v}"))
        .collect::<Vec<_>>()
        .join(",")
}

#[test]
fn idm_ddm_simulate_apply_the_transmission() {
    let tx40 = robot("tx40.toml");
    let sets = sets();
    let q = [0.1, -0.4, 1.2, 0.3, -0.7, 0.2];
    let qd = [0.5, 0.1, -0.3, 0.8, 0.2, -0.6];
    let qdd = [1.0, -2.0, 0.5, 3.0, -1.5, 2.5];
    let (lq, lqd, lqdd) = (list(&q), list(&qd), list(&qdd));
    let state = ["--q", &lq, "--qd", &lqd, "--qdd", &lqdd];
    let (out, err) = run2(&with_sets(&["idm", &tx40], &sets, &state));
    assert!(
        err.contains("joint-side") && err.contains("transmission"),
        "{err}"
    );
    let tau = csv(&out).1[0].clone();
    // the links alone: the bundled file (no drive parameters) with the same link 6
    let link6 = [
        "--set", "XX6=1e-3", "--set", "YY6=1e-3", "--set", "ZZ6=1e-3",
    ];
    let (out, err) = run2(&[&["idm", &tx40][..], &link6, &state].concat());
    assert!(
        !err.contains("joint-side"),
        "no drive parameters, no note: {err}"
    );
    let links = csv(&out).1[0].clone();
    // R^T (IA R qdd + FV R qd + FS sign(R qd)) by hand
    let mut drives = [0.0; 6];
    for (m, row) in R.iter().enumerate() {
        let dot = |v: &[f64]| row.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        let (ia, fs, fv) = MOTORS[m];
        let (md, mdd) = (dot(&qd), dot(&qdd));
        let f = ia * mdd + fv * md + fs * md.signum();
        for c in 0..6 {
            drives[c] += row[c] * f;
        }
    }
    for j in 0..6 {
        let want = links[j] + drives[j];
        assert!(
            (tau[j] - want).abs() < 1e-9 * want.abs().max(1.0),
            "joint {}: idm {} vs links + drives {want}",
            j + 1,
            tau[j]
        );
    }
    // the coupling: motor 6's torque (all of joint 6's drive torque) is in joint 5's too
    assert!(drives[5].abs() > 1.0, "{drives:?}");
    // ddm inverts idm (both methods)
    let ltau = list(&tau);
    for method in ["composite", "aba"] {
        let args = ["--q", &lq, "--qd", &lqd, "--tau", &ltau, "--method", method];
        let (out, err) = run2(&with_sets(&["ddm", &tx40], &sets, &args));
        assert!(err.contains("joint-side"), "{err}");
        let back = csv(&out).1[0].clone();
        for j in 0..6 {
            assert!(
                (back[j] - qdd[j]).abs() < 1e-7,
                "{method}: {back:?} vs {qdd:?}"
            );
        }
    }
    // simulate: a short free motion runs and states the side
    let traj = tmp("transmission", "sim.csv");
    let args = [
        "--duration",
        "0.2",
        "--q0",
        &lq,
        "--qd0",
        &lqd,
        "--output",
        traj.to_str().unwrap(),
    ];
    let (_, err) = run2(&with_sets(&["simulate", &tx40], &sets, &args));
    assert!(err.contains("joint-side"), "{err}");
    let (head, rows) = csv(&std::fs::read_to_string(&traj).unwrap());
    assert!(
        head.contains(&"tau6".to_string()) && rows.len() > 10,
        "{head:?}"
    );
    // inertia: A includes R^T IA R (joint 5-6 coupling 32^2 IA6 on top of the links')
    let q_only = ["--q", &lq];
    let a_with = run2(&with_sets(&["inertia", &tx40], &sets, &q_only)).0;
    let a_links = run2(&[&["inertia", &tx40][..], &link6, &q_only].concat()).0;
    let (a_with, a_links) = (csv(&a_with).1, csv(&a_links).1);
    let last = |rows: &[Vec<f64>], r: usize, c: usize| rows[r][rows[r].len() - 6 + c];
    let want = last(&a_links, 4, 5) + 32.0 * 32.0 * MOTORS[5].0;
    assert!((last(&a_with, 4, 5) - want).abs() < 1e-12, "A56");
}

#[test]
fn commands_without_transmissions_refuse_motor_parameters() {
    let tx40 = robot("tx40.toml");
    let sets = sets();
    let input = tmp("transmission", "states.csv");
    std::fs::write(
        &input,
        "q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6,qdd1,qdd2,qdd3,qdd4,qdd5,qdd6\n\
         0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n",
    )
    .unwrap();
    let e = fails(&with_sets(
        &["regressor", &tx40],
        &sets,
        &["--input", input.to_str().unwrap()],
    ));
    assert!(e.contains("transmission") && e.contains("regressor"), "{e}");
    let e = fails(&with_sets(
        &["idm", &tx40],
        &sets,
        &["--q", "0,0,0,0,0,0", "--derivatives"],
    ));
    assert!(
        e.contains("transmission") && e.contains("derivatives"),
        "{e}"
    );
}
