//! Closed chains, several rows: each row's loop closure is continued from the previous row, so a
//! row far from its predecessor stays on the assembly branch and gets the same torques as when
//! it is evaluated alone (from the robot's assembly configuration).

mod common;

use common::robot;
use std::process::Command;

fn idm_csv(robot: &str, rows: &[f64]) -> Vec<f64> {
    let dir = std::env::temp_dir().join(format!("robodyn-cli-rows-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("states{}.csv", rows.len()));
    let mut text = String::from("q1,qd1,qdd1\n");
    for q in rows {
        text.push_str(&format!("{q},0.3,-0.2\n"));
    }
    std::fs::write(&path, text).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["idm", robot, "--input", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.trim().parse().unwrap())
        .collect()
}

#[test]
fn distant_rows_keep_the_assembly_branch() {
    let r = robot("spatial_loop.toml");
    let both = idm_csv(&r, &[0.3, -0.5]);
    let alone = idm_csv(&r, &[-0.5]);
    assert_eq!(both.len(), 2);
    let rel = (both[1] - alone[0]).abs() / alone[0].abs().max(1e-12);
    assert!(
        rel < 1e-9,
        "row 2: {} in a table, {} alone",
        both[1],
        alone[0]
    );
}
