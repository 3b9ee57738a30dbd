//! CLI smoke tests of `simulate` and `ddm` on a closed-chain robot (the bundled four-bar):
//! actuated-joint columns in and out, the extra columns of the closed-chain simulation, finite
//! values, a closed loop along the trajectory, and `ddm` / `idm` agreeing with the simulation.

use std::path::PathBuf;
mod common;

use common::{csv as parse_csv, run};
use std::process::Command;

fn tmp_(name: &str) -> PathBuf {
    common::tmp("closed", name)
}

fn fourbar() -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots/fourbar.toml")
        .to_str()
        .unwrap()
        .to_string()
}

#[test]
fn simulate_and_ddm_on_the_fourbar() {
    let robot = fourbar();
    let traj = tmp_("fourbar.csv");
    run(&[
        "simulate",
        &robot,
        "--duration",
        "0.5",
        "--output-step",
        "0.01",
        "--q0",
        "0.3",
        "--qd0",
        "3",
        "--torque",
        "0.5",
        "--rtol",
        "1e-9",
        "--output",
        traj.to_str().unwrap(),
    ]);
    let (h, rows) = parse_csv(&std::fs::read_to_string(&traj).unwrap());
    // actuated joint 1; passive joints 2, 3 as extra columns
    let expected = [
        "t",
        "q1",
        "qd1",
        "qdd1",
        "tau1",
        "energy",
        "closure_residual",
        "q2",
        "q3",
    ];
    assert_eq!(h, expected);
    assert_eq!(rows.len(), 51);
    let mut residual: f64 = 0.0;
    for r in &rows {
        assert!(r.iter().all(|x| x.is_finite()));
        assert_eq!(r[4], 0.5);
        residual = residual.max(r[6]);
    }
    assert!(residual < 1e-9, "closure residual {residual}");
    assert!((rows[50][1] - 0.3).abs() > 0.1, "the crank should turn");
    // ddm on the simulated states: the same qdd1 where the Coulomb smoothing tanh(qd/0.01) is
    // exactly sign(qd) (|qd| > 0.5)
    let states = tmp_("states.csv");
    let mut csv = String::from("q1,qd1,tau1\n");
    let picked: Vec<&Vec<f64>> = rows.iter().filter(|r| r[2].abs() > 0.5).collect();
    assert!(picked.len() > 10);
    for r in &picked {
        csv.push_str(&format!("{},{},{}\n", r[1], r[2], r[4]));
    }
    std::fs::write(&states, csv).unwrap();
    let (hd, qdd) = parse_csv(&run(&["ddm", &robot, "--input", states.to_str().unwrap()]));
    assert_eq!(hd, ["qdd1"]);
    assert_eq!(qdd.len(), picked.len());
    for (r, a) in picked.iter().zip(&qdd) {
        assert!(
            (r[3] - a[0]).abs() <= 1e-9 * r[3].abs().max(1.0),
            "ddm {} vs simulated {}",
            a[0],
            r[3]
        );
    }
    // idm of that acceleration gives back the torque
    let r = picked[picked.len() / 2];
    let (ht, tau) = parse_csv(&run(&[
        "idm",
        &robot,
        "--q",
        &r[1].to_string(),
        "--qd",
        &r[2].to_string(),
        "--qdd",
        &r[3].to_string(),
    ]));
    assert_eq!(ht, ["tau1"]);
    assert!((tau[0][0] - 0.5).abs() < 1e-8, "idm gave {}", tau[0][0]);
}

#[test]
fn closed_robot_wrong_number_of_values() {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["ddm", &fourbar(), "--q", "0.1,0.2"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("actuated joints"), "{err}");
}
