//! `robodyn idm --derivatives`: the three matrices at one state, in JSON and CSV, checked against
//! central differences of the library's inverse model (an independent route: the torques
//! only), the `inertia` command's A, and the CSV against the JSON; a table
//! input is refused with a message (closed chains: cli_closed_derivatives.rs).

use robodyn::nalgebra::DMatrix;
use std::process::Command;

mod common;
use common::{robot, run};

fn matrix(v: &serde_json::Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
    let n = rows.len();
    DMatrix::from_fn(n, rows[0].len(), |r, c| rows[r][c])
}

/// Central differences of the library's inverse model along argument `which` (0 q, 1 qd).
fn central(r: &robodyn::Robot, x: [&[f64]; 3], which: usize) -> DMatrix<f64> {
    let n = x[0].len();
    let h = 1e-6;
    DMatrix::from_fn(n, n, |j, k| {
        let at = |s: f64| {
            let mut v = [x[0].to_vec(), x[1].to_vec(), x[2].to_vec()];
            v[which][k] += s;
            robodyn::inverse_dynamics(r, &v[0], &v[1], &v[2]).unwrap()[j]
        };
        (at(h) - at(-h)) / (2.0 * h)
    })
}

#[test]
fn idm_derivatives_json_and_csv() {
    let file = robot("rx90.toml");
    let (q, qd, qdd) = (
        [0.1, -0.4, 1.2, 0.3, -0.7, 0.2],
        [0.5, 0.1, -0.3, 0.8, 0.2, -0.6],
        [1.0, -2.0, 0.5, 0.0, 3.0, -1.0],
    );
    let l = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(",")
    };
    let (sq, sqd, sqdd) = (l(&q), l(&qd), l(&qdd));
    let base = [
        "idm",
        &file,
        "--derivatives",
        "--q",
        &sq,
        "--qd",
        &sqd,
        "--qdd",
        &sqdd,
    ];
    let json: serde_json::Value =
        serde_json::from_str(&run(&[&base[..], &["--format", "json"]].concat())).unwrap();
    let r = robodyn::io::load(std::path::Path::new(&file)).unwrap();
    let (dq, dqd, a) = (
        matrix(&json["dtau_dq"]),
        matrix(&json["dtau_dqd"]),
        matrix(&json["A"]),
    );
    let rel = |m: &DMatrix<f64>, e: &DMatrix<f64>| (m - e).amax() / e.amax().max(1.0);
    assert!(
        rel(&dq, &central(&r, [&q, &qd, &qdd], 0)) < 1e-6,
        "dtau_dq {dq}"
    );
    assert!(
        rel(&dqd, &central(&r, [&q, &qd, &qdd], 1)) < 1e-6,
        "dtau_dqd {dqd}"
    );
    let inertia = run(&["inertia", &file, "--q", &sq, "--format", "json"]);
    let inertia: serde_json::Value = serde_json::from_str(&inertia).unwrap();
    assert!(rel(&a, &matrix(&inertia["A"])) < 1e-12, "A {a}");
    assert_eq!(json["joints"].as_array().unwrap().len(), 6);
    // CSV: header matrix, joint, 1..6; 18 rows, the same numbers as the JSON (to print
    // precision)
    let text = run(&base);
    let mut lines = text.lines();
    assert_eq!(lines.next().unwrap(), "matrix,joint,1,2,3,4,5,6");
    let rows: Vec<Vec<String>> = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    assert_eq!(rows.len(), 18);
    for (k, (name, m)) in [("dtau_dq", &dq), ("dtau_dqd", &dqd), ("A", &a)]
        .iter()
        .enumerate()
    {
        for i in 0..6 {
            let row = &rows[6 * k + i];
            assert_eq!(row[0], *name);
            assert_eq!(row[1], (i + 1).to_string());
            for c in 0..6 {
                let x: f64 = row[2 + c].parse().unwrap();
                assert!((x - m[(i, c)]).abs() <= 1e-9 * m[(i, c)].abs().max(1.0));
            }
        }
    }
}

#[test]
fn idm_derivatives_refuses_tables() {
    // (closed chains: tests/cli_closed_derivatives.rs)
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args([
            "idm",
            &robot("rx90.toml"),
            "--derivatives",
            "--input",
            "x.csv",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--input"), "{err}");
    // a state of the wrong length names the vector
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["idm", &robot("rx90.toml"), "--derivatives", "--q", "0,0"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains('q'), "{err}");
}
