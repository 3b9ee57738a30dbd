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

fn output(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap()
}

/// The five-bar at its parallel singularity (distal links aligned, q1 = -q3 = pi/6): `closure`
/// and `idm` refuse with the conditioning (exit 1) instead of printing W and torques of 1e5..1e9;
/// near it they print a warning on stderr and flag the JSON output.
#[test]
fn five_bar_singularity_is_refused_and_its_neighbourhood_flagged() {
    let r = robot("fivebar.toml");
    let a = std::f64::consts::PI / 6.0;
    let qa = format!("{a},{}", -a);
    for args in [
        vec!["closure", r.as_str(), "--qa", qa.as_str(), "--jacobian"],
        vec!["idm", r.as_str(), "--q", qa.as_str(), "--qd", "1,1"],
    ] {
        let out = output(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        assert!(
            err.contains("Wp") && err.contains("singular") && err.contains("reciprocal condition"),
            "{err}"
        );
    }
    let b = a - 1e-7;
    let qa = format!("{b},{}", -b);
    let out = output(&["idm", &r, "--q", &qa, "--qd", "1,1", "--format", "json"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning: near a singular configuration"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v[0]["singularity_warning"], serde_json::json!(true));
    assert!(v[0]["rcond_wp"].as_f64().unwrap() < 1e-3);
    // away from it: no warning
    let out = output(&["closure", &r, "--qa", "0.3,-0.3", "--format", "json"]);
    assert!(out.status.success() && out.stderr.is_empty());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["singularity_warning"], serde_json::json!(false));
}

/// SR400 rows: a row whose path flattens the parallelogram (q7 - q2 through 0) is an error naming
/// the row, never torques of the crossed mechanism.
#[test]
fn sr400_row_across_the_flat_parallelogram_is_an_error_naming_it() {
    let dir = std::env::temp_dir().join(format!("robodyn-cli-rows-sr-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rows.csv");
    let mut text =
        String::from("q1,q2,q4,q5,q6,q7,qd1,qd2,qd4,qd5,qd6,qd7,qdd1,qdd2,qdd4,qdd5,qdd6,qdd7\n");
    text.push_str("0.1,0.2,0,0,0,1.2,0,0,0,0,0,0,0,0,0,0,0,0\n");
    text.push_str("0,0.3,0.1,0,0,-0.3,0,0,0,0,0,0,0,0,0,0,0,0\n");
    std::fs::write(&path, text).unwrap();
    let out = output(&[
        "idm",
        &robot("sr400.toml"),
        "--input",
        path.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("row 2: ") && err.contains("assembly branch"),
        "{err}"
    );
}

/// `--names joint`: columns named after the joints (URDF joint names), in and out.
#[test]
fn joint_names_as_columns() {
    let r = robot("rx90.urdf");
    let out = output(&["idm", &r, "--q", "0,0.1,0.2,0,0,0", "--names", "joint"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let header = text.lines().next().unwrap();
    assert!(header.starts_with("tau_"), "{header}");
    let names: Vec<&str> = header.split(',').collect();
    assert_eq!(names.len(), 6);
    // the same columns read back as input
    let dir = std::env::temp_dir().join(format!("robodyn-cli-names-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("states.csv");
    let cols: Vec<String> = ["q", "qd", "qdd"]
        .iter()
        .flat_map(|p| names.iter().map(move |n| format!("{p}{}", &n[3..])))
        .collect();
    let mut body = cols.join(",");
    body.push('\n');
    body.push_str("0,0.1,0.2,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n");
    std::fs::write(&path, body).unwrap();
    let out2 = output(&[
        "idm",
        &r,
        "--input",
        path.to_str().unwrap(),
        "--names",
        "joint",
    ]);
    assert!(
        out2.status.success(),
        "{}",
        String::from_utf8_lossy(&out2.stderr)
    );
    assert_eq!(String::from_utf8(out2.stdout).unwrap(), text);
}
