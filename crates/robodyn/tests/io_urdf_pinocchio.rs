//! Real URDFs (example-robot-data) load, and our inverse dynamics on them agrees with
//! `pinocchio.rnea` (an independent implementation) to 1e-9 relative on random states.
//!
//! Needs `python3` with `pin` and `example-robot-data` (`pip install pin example-robot-data`,
//! done by `.ci/run`, which sets ROBODYN_REQUIRE=all so that a missing install fails instead
//! of skipping). `ROBODYN_PYTHON` selects the interpreter.

use robodyn::algorithms::inverse_dynamics::inverse_dynamics;
use robodyn::model::param;
use robodyn::{Expr, Robot};
use robodyn_testing as testing;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

mod common;
pub(crate) use common::find_file as find;
use common::{example_robot_data, python};

/// The example-robot-data `robots` folder, or None (with the reason) when unavailable.
pub(crate) fn robots_dir() -> Option<PathBuf> {
    example_robot_data("real URDFs vs pinocchio.rnea not checked")
}

fn all_urdfs(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            all_urdfs(&p, out);
        } else if p.extension().is_some_and(|x| x == "urdf") {
            out.push(p);
        }
    }
}

/// Load a URDF without joint friction (Pinocchio's rnea has none).
fn load_frictionless(path: &Path) -> Robot {
    let mut d = robodyn::io::load_description(path).unwrap();
    for l in &mut d.links {
        l.params[param::FS] = Expr::zero();
        l.params[param::FV] = Expr::zero();
    }
    Robot::new(d).unwrap()
}

#[test]
fn every_example_robot_data_urdf_loads_or_says_why() {
    let Some(dir) = robots_dir() else { return };
    let mut files = Vec::new();
    all_urdfs(&dir, &mut files);
    assert!(
        files.len() > 20,
        "only {} URDFs found in {}",
        files.len(),
        dir.display()
    );
    let mut loaded = 0;
    for f in &files {
        match robodyn::io::load(f) {
            Ok(r) => {
                assert!(r.nl() > 0);
                loaded += 1;
            }
            Err(e) => {
                // the only acceptable failures: files that are not robots (no link / no joint)
                let m = e.to_string();
                assert!(
                    m.contains("has no <link>") || m.contains("has no joint"),
                    "{}: {m}",
                    f.display()
                );
                assert!(m.contains(&f.display().to_string()), "{m}");
            }
        }
    }
    assert!(
        loaded + 2 >= files.len(),
        "{loaded} of {} loaded",
        files.len()
    );
}

#[test]
fn inverse_dynamics_matches_pinocchio_rnea() {
    let Some(dir) = robots_dir() else { return };
    let names = [
        "ur5_robot.urdf",
        "panda.urdf",
        "hyq_no_sensors.urdf",
        "baxter.urdf",
        "talos_reduced.urdf",
        "double_pendulum_continuous.urdf",
        "romeo_small.urdf", // has nearly parallel axes: auxiliary fixed frames
    ];
    let mut rng = testing::rng(20261122);
    let mut robots = Vec::new();
    let mut spec = Vec::new();
    for n in names {
        let path = find(&dir, n).unwrap_or_else(|| panic!("{n} not in {}", dir.display()));
        let robot = load_frictionless(&path);
        // joint vectors over the movable joints, named by the coordinate map
        let c = robot.coordinates().clone();
        let mut states = Vec::new();
        let mut ours = Vec::new();
        for _ in 0..5 {
            let [q, qd, qdd] = testing::random_state(&mut rng, c.len());
            let tau = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
            let by_name = |v: &[f64]| -> Value {
                (0..c.len())
                    .map(|k| (c.name(k).to_string(), json!(v[k])))
                    .collect::<serde_json::Map<_, _>>()
                    .into()
            };
            states.push(json!({"q": by_name(&q), "qd": by_name(&qd), "qdd": by_name(&qdd)}));
            ours.push(tau);
        }
        spec.push(json!({"urdf": path, "states": states}));
        robots.push((n, robot, ours));
    }
    let tmp = std::env::temp_dir().join(format!("robodyn_pin_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let (inp, outp) = (tmp.join("in.json"), tmp.join("out.json"));
    std::fs::write(&inp, json!({ "robots": spec }).to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/pinocchio_rnea.py");
    let st = Command::new(python())
        .arg(&script)
        .arg(&inp)
        .arg(&outp)
        .status()
        .unwrap();
    assert!(st.success(), "pinocchio script failed");
    let res: Value = serde_json::from_str(&std::fs::read_to_string(&outp).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&tmp);
    let mut worst: f64 = 0.0;
    for (k, (n, robot, ours)) in robots.iter().enumerate() {
        let r = &res["robots"][k];
        let c = robot.coordinates();
        assert_eq!(r["nv"].as_u64().unwrap() as usize, c.len(), "{n}: nv");
        for (s, tau) in ours.iter().enumerate() {
            let pin_tau = &r["tau"][s];
            let scale = c
                .names()
                .iter()
                .map(|name| pin_tau[name].as_f64().unwrap().abs())
                .fold(0.0, f64::max);
            assert!(
                scale > 1e-3,
                "{n}: torques vanish, the test would be vacuous"
            );
            for (k, name) in c.names().iter().enumerate() {
                let p = pin_tau[name]
                    .as_f64()
                    .unwrap_or_else(|| panic!("{n}: {name}"));
                let rel = (tau[k] - p).abs() / scale;
                worst = worst.max(rel);
                assert!(
                    rel < 1e-9,
                    "{n}, state {s}, joint {name}: robodyn {} vs pinocchio {p} (rel {rel:e})",
                    tau[k]
                );
            }
        }
    }
    eprintln!("worst relative difference to pinocchio.rnea: {worst:e}");
}
