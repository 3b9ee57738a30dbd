//! `simulate --names joint`: the trajectory's joint columns follow the rule of idm, ddm and
//! regressor (`q_<joint name>`), in the CSV, in the `--track` input and in the plot's legend;
//! the numbers are those of the run named by frame number. A URDF with fixed frames (its joint
//! vectors hold the movable joints only) and a closed chain (passive columns named too).

mod common;

use common::{csv, run, tmp};
use std::process::Command;

fn fixed_frames_urdf() -> String {
    format!(
        "{}/../robodyn/tests/data/fixed_frames.urdf",
        env!("CARGO_MANIFEST_DIR")
    )
}

#[test]
fn joint_names_name_the_trajectory_columns() {
    let r = fixed_frames_urdf();
    let by_frame = tmp("simnames", "frame.csv");
    let by_name = tmp("simnames", "name.csv");
    let svg = tmp("simnames", "plot.svg");
    let common = ["--duration", "0.2", "--dt", "0.01", "--q0", "0.1,-0.2,0.05"];
    let mut args = vec!["simulate", &r, "--output", by_frame.to_str().unwrap()];
    args.extend(common);
    run(&args);
    let mut args = vec!["simulate", &r, "--output", by_name.to_str().unwrap()];
    args.extend(common);
    args.extend(["--names", "joint", "--plot", svg.to_str().unwrap()]);
    run(&args);
    let (hf, rf) = csv(&std::fs::read_to_string(&by_frame).unwrap());
    let (hn, rn) = csv(&std::fs::read_to_string(&by_name).unwrap());
    // movable joints 2, 4, 5 (shoulder, elbow, extend); the fixed frames carry no column
    let frames = ["2", "4", "5"];
    let names = ["shoulder", "elbow", "extend"];
    let mut want_f = vec!["t".to_string()];
    let mut want_n = vec!["t".to_string()];
    for p in ["q", "qd", "qdd", "tau"] {
        want_f.extend(frames.iter().map(|j| format!("{p}{j}")));
        want_n.extend(names.iter().map(|n| format!("{p}_{n}")));
    }
    want_f.push("energy".into());
    want_n.push("energy".into());
    assert_eq!(hf, want_f);
    assert_eq!(hn, want_n);
    assert_eq!(rf, rn, "the names change the header only");
    // one rule: idm --names joint writes the same tau columns
    let idm = run(&["idm", &r, "--q", "0.1,-0.2,0.05", "--names", "joint"]);
    let idm_header: Vec<&str> = idm.lines().next().unwrap().split(',').collect();
    assert_eq!(idm_header, &hn[10..13]);
    // the plot's legend and the prismatic panel use the same names
    let plot = std::fs::read_to_string(&svg).unwrap();
    for n in names {
        assert!(plot.contains(&format!("q_{n}")), "legend lacks q_{n}");
    }
    assert!(
        plot.contains("prismatic joints"),
        "q_extend is plotted in metres"
    );
}

#[test]
fn track_reads_joint_named_columns() {
    let r = fixed_frames_urdf();
    let reference = tmp("simnames", "ref.csv");
    std::fs::write(
        &reference,
        "t,q_shoulder,q_elbow,q_extend\n0,0,0,0.05\n1,0.3,-0.2,0.1\n",
    )
    .unwrap();
    let out = tmp("simnames", "track.csv");
    let args = |names: &'static str| {
        vec![
            "simulate".to_string(),
            r.clone(),
            "--duration".into(),
            "0.1".into(),
            "--track".into(),
            reference.to_str().unwrap().into(),
            "--kp".into(),
            "100".into(),
            "--kd".into(),
            "10".into(),
            "--output".into(),
            out.to_str().unwrap().into(),
            "--names".into(),
            names.into(),
        ]
    };
    run(&args("joint").iter().map(String::as_str).collect::<Vec<_>>());
    // named by frame number, the same file lacks q2, q4, q5
    let o = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args("frame"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("q2"), "{err}");
}

#[test]
fn closed_chain_passive_columns_follow_the_names() {
    let out = tmp("simnames", "fivebar.csv");
    run(&[
        "simulate",
        &common::robot("fivebar.toml"),
        "--duration",
        "0.05",
        "--output",
        out.to_str().unwrap(),
        "--names",
        "joint",
    ]);
    let (h, rows) = csv(&std::fs::read_to_string(&out).unwrap());
    assert!(!rows.is_empty());
    // actuated q, qd, qdd, tau and the passive q: every joint column by name, none by number
    let joint_cols: Vec<&String> = h
        .iter()
        .filter(|c| !matches!(c.as_str(), "t" | "energy" | "closure_residual"))
        .collect();
    assert_eq!(joint_cols.len(), 4 * 2 + 2, "{h:?}");
    for c in joint_cols {
        let label = c.trim_start_matches(['q', 'd', 't', 'a', 'u']);
        assert!(label.starts_with('_') && label.len() > 1, "{c} in {h:?}");
    }
}

#[test]
fn closure_names_its_variables_by_joint_name() {
    // `closure --names joint` names q_a, q_p, the cut joints and W's rows and columns by joint
    // name (the file's names, `j<frame>` when it gives none); the values are those of the run
    // named by frame number.
    let robot = common::robot("fivebar.toml");
    let json = |names: &str| -> serde_json::Value {
        let out = run(&[
            "closure",
            &robot,
            "--qa",
            "0.3,2.0",
            "--jacobian",
            "--format",
            "json",
            "--names",
            names,
        ]);
        serde_json::from_str(&out).unwrap()
    };
    let (by_frame, by_name) = (json("frame"), json("joint"));
    let desc = robodyn::io::load(std::path::Path::new(&robot))
        .unwrap()
        .into_description();
    for part in ["q_a", "q_p", "q_c"] {
        let f = by_frame[part].as_object().unwrap();
        let n = by_name[part].as_object().unwrap();
        assert_eq!(f.len(), n.len());
        assert!(!f.is_empty(), "{part}");
        for (key, v) in f {
            let j: usize = key[1..].parse().unwrap();
            let named = format!("q_{}", desc.frame(j).name);
            assert_eq!(n.get(&named), Some(v), "{part}: {key} -> {named} in {n:?}");
        }
    }
    let cols = by_name["W"]["columns"].as_array().unwrap();
    assert!(cols.iter().all(|c| c.as_str().unwrap().starts_with("q_")));
    assert_eq!(by_name["W"]["values"], by_frame["W"]["values"]);
}
