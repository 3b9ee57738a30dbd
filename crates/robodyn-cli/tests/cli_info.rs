//! `robodyn info --format json` lists every frame (j, name, ant, sigma, mu and its six
//! parameters) and every link (its 13 standard parameters); `robodyn convert` between formats
//! keeps the torques; mimic joints are flagged by `info`.

mod common;

use common::{robot, run};

fn tmp_(name: &str) -> std::path::PathBuf {
    common::tmp("info", name)
}
use serde_json::Value;
use std::process::Command;

fn info_json(path: &str) -> Value {
    serde_json::from_str(&run(&["info", path, "--format", "json"])).unwrap()
}

const GEOMETRIC: [&str; 6] = ["gamma", "b", "alpha", "d", "theta", "r"];
const STANDARD: [&str; 13] = [
    "XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FS", "FV",
];

#[test]
fn json_lists_every_frame_and_link_of_the_sr400() {
    let v = info_json(&robot("sr400.toml"));
    let frames = v["frames"].as_array().unwrap();
    assert_eq!(frames.len(), 10);
    let ant = [0, 1, 2, 3, 4, 5, 1, 7, 8, 3];
    let mu = [1, 1, 0, 1, 1, 1, 1, 0, 0, 0];
    let d = ["0", "d2", "d3", "d4", "0", "0", "d2", "d8", "d3", "-d8"];
    for (i, f) in frames.iter().enumerate() {
        let j = i + 1;
        assert_eq!(f["j"], j);
        assert_eq!(f["name"], format!("j{j}"), "unnamed TOML frames are j<j>");
        assert_eq!(f["ant"], ant[i]);
        assert_eq!(f["sigma"], if j == 10 { 2 } else { 0 });
        assert_eq!(f["mu"], mu[i]);
        for p in GEOMETRIC {
            assert!(f[p].is_string(), "frame {j} lacks {p}");
        }
        assert_eq!(f["d"], d[i], "frame {j}");
    }
    assert_eq!(frames[9]["gamma"], "pi/2");
    assert_eq!(frames[3]["r"], "RL4");
    let links = v["links"].as_array().unwrap();
    assert_eq!(links.len(), 8);
    for l in links {
        for p in STANDARD {
            assert!(l[p].is_string(), "link {} lacks {p}", l["j"]);
        }
    }
    assert_eq!(links[0]["M"], "30");
    let xz = robodyn::Expr::parse(links[1]["XZ"].as_str().unwrap()).unwrap();
    assert_eq!(xz.eval(&|_| None).unwrap(), -0.225);
}

#[test]
fn json_keeps_urdf_joint_names_and_toml_names() {
    let v = info_json(&robot("rx90.urdf"));
    let names: Vec<&str> = v["frames"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "shoulder",
            "arm",
            "elbow",
            "forearm",
            "wrist_pitch",
            "flange"
        ]
    );
    let v = info_json(&robot("torso2arms.toml"));
    assert_eq!(v["frames"][4]["name"], "r_shoulder_pitch");
    assert_eq!(v["frames"][4]["gamma"], "-pi/2");
    assert_eq!(v["frames"][4]["b"], "H");
}

#[test]
fn info_flags_mimic_joints() {
    let f = tmp_("mimic.urdf");
    std::fs::write(
        &f,
        r#"<robot name="gripper">
  <link name="palm"/>
  <link name="left"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"/></inertial></link>
  <link name="right"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4"/></inertial></link>
  <joint name="finger_left" type="prismatic"><parent link="palm"/><child link="left"/><axis xyz="0 1 0"/></joint>
  <joint name="finger_right" type="prismatic"><parent link="palm"/><child link="right"/><axis xyz="0 -1 0"/>
    <mimic joint="finger_left"/></joint>
</robot>
"#,
    )
    .unwrap();
    let text = run(&["info", f.to_str().unwrap()]);
    assert!(
        text.contains("note: joint finger_right mimics finger_left"),
        "{text}"
    );
}

#[test]
fn convert_between_formats_keeps_the_torques() {
    // the SR400 is a closed chain: idm takes the actuated joints 1, 2, 4, 5, 6, 7
    let args = [
        "--q",
        "0.1,0.2,0.4,0.5,0.6,0.7",
        "--qd",
        "1,-1,-2,1,1,0.5",
        "--qdd",
        "1,2,4,5,6,7",
    ];
    let idm = |p: &str| {
        let mut a = vec!["idm", p];
        a.extend(args);
        run(&a)
    };
    let reference = idm(&robot("sr400.toml"));
    let (toml, par) = (tmp_("sr400_conv.toml"), tmp_("sr400_conv.par"));
    run(&["convert", &robot("sr400.par"), toml.to_str().unwrap()]);
    run(&["convert", toml.to_str().unwrap(), par.to_str().unwrap()]);
    assert_eq!(idm(toml.to_str().unwrap()), reference);
    assert_eq!(idm(par.to_str().unwrap()), reference);
    // URDF -> .par keeps the joint names
    let p = tmp_("rx90_conv.par");
    run(&["convert", &robot("rx90.urdf"), p.to_str().unwrap()]);
    let v = info_json(p.to_str().unwrap());
    assert_eq!(v["frames"][2]["name"], "elbow");
    // writing URDF is refused with a message
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args([
            "convert",
            &robot("rx90.toml"),
            tmp_("x.urdf").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("writing URDF is not supported"));
}
