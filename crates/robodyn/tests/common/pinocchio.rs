//! Driving Pinocchio's Python bindings from the tests that compare against it
//! (`derivatives_pinocchio`, `floating_pinocchio`, `kinematics_pinocchio`): the states go to a
//! script of `tests/data/` as JSON (joint vectors keyed by joint name, one entry per robot with
//! its URDF), the script writes Pinocchio's results as JSON, read back here.

use robodyn::Robot;
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

/// A vector over the movable joints of `robot` as a JSON object keyed by joint name.
pub fn by_name(robot: &Robot, v: &[f64]) -> Value {
    let coords = robot.coordinates();
    (0..coords.len())
        .map(|k| (coords.name(k).to_string(), json!(v[k])))
        .collect::<serde_json::Map<_, _>>()
        .into()
}

/// One robot's entry of the script's input: the URDF `name` found under `dir`, its states.
pub fn robot_entry(dir: &Path, name: &str, states: Vec<Value>) -> Value {
    let path = super::find_file(dir, name).unwrap_or_else(|| panic!("{name} not found"));
    json!({"urdf": path, "states": states})
}

/// Run `tests/data/<script>` (with `crate::common::python`) on `{"robots": robots}` and return
/// its JSON output; panics when the script fails.
pub fn run_script(script: &str, robots: Vec<Value>) -> Value {
    // a directory of its own per call: the tests of one process run the same script at once
    let stem = script.trim_end_matches(".py");
    let tmp = tempfile::Builder::new()
        .prefix(&format!("robodyn_{stem}_"))
        .tempdir()
        .unwrap();
    let (inp, outp) = (tmp.path().join("in.json"), tmp.path().join("out.json"));
    std::fs::write(&inp, json!({ "robots": robots }).to_string()).unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(script);
    let st = Command::new(super::python())
        .arg(&path)
        .arg(&inp)
        .arg(&outp)
        .status()
        .unwrap();
    assert!(st.success(), "pinocchio script {script} failed");
    // the directory is removed when `tmp` drops
    serde_json::from_str(&std::fs::read_to_string(&outp).unwrap()).unwrap()
}

/// robodyn's index (in the movable-joint vectors) of each joint of the script's `joints` list
/// (Pinocchio's v order).
pub fn joint_indices(robot: &Robot, joints: &Value) -> Vec<usize> {
    joints
        .as_array()
        .unwrap()
        .iter()
        .map(|j| robot.coordinates().index_of(j.as_str().unwrap()).unwrap())
        .collect()
}

/// A JSON array of numbers.
pub fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}
