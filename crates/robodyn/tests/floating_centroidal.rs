//! The centroidal momentum matrix A_G(q) of floating robots (h_G = A_G v; Orin's CMM):
//! - against Pinocchio's `ccrba` (an independent implementation) on example-robot-data's
//!   Talos (full), HyQ and Solo12 with a free-flyer root, 200 random states each, to 1e-10
//!   relative to the largest entry (also its h_G = A_G v against ours);
//! - A_G v against `centroidal_momentum` on random floating trees (the momentum by the base
//!   rows of A times v), and its linear rows against the centre of mass moved along v: M times
//!   the central difference of the centre of mass over `integrate(q, ±v eps)` (no matrix);
//! - refusals: a fixed robot, a wrong output shape.
//!
//! The Pinocchio part needs `python3` with `pin` and `example-robot-data`; it skips visibly
//! otherwise (`ROBODYN_REQUIRE=pinocchio` makes it fail).

use nalgebra::DMatrix;
use robodyn::io::LoadOptions;
use robodyn::{centroidal_map, centroidal_map_into, centroidal_momentum, integrate, Data, Robot};
use robodyn_testing::{self as testing, TreeOptions};
use serde_json::{json, Value};
use std::path::Path;
use std::process::Command;

mod common;
use common::{example_robot_data, find_file, python};

const ROBOTS: [&str; 3] = ["talos_full_v2.urdf", "hyq_no_sensors.urdf", "solo12.urdf"];
const STATES: usize = 200;

fn max_abs(x: &[f64]) -> f64 {
    x.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// A robot's file name, the robot and its states (q, v).
type Case = (&'static str, Robot, Vec<[Vec<f64>; 2]>);

/// The script's output for `cases`.
fn pinocchio_ccrba(cases: &[Case], dir: &Path) -> Value {
    let spec: Vec<Value> = cases
        .iter()
        .map(|(name, robot, states)| {
            let path = find_file(dir, name).unwrap_or_else(|| panic!("{name} not found"));
            let st: Vec<Value> = states
                .iter()
                .map(|[q, v]| json!({"q": q, "v": v}))
                .collect();
            json!({"urdf": path, "joints": robot.coordinates().names(), "states": st})
        })
        .collect();
    let tmp = std::env::temp_dir().join(format!("robodyn_pin_ccrba_{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let (inp, outp) = (tmp.join("in.json"), tmp.join("out.json"));
    std::fs::write(&inp, json!({ "robots": spec }).to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/pinocchio_centroidal.py");
    let st = Command::new(python())
        .arg(&script)
        .arg(&inp)
        .arg(&outp)
        .status()
        .unwrap();
    assert!(st.success(), "pinocchio script failed");
    let res = serde_json::from_str(&std::fs::read_to_string(&outp).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&tmp);
    res
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

#[test]
fn centroidal_map_matches_pinocchio_ccrba() {
    let Some(dir) = example_robot_data("the centroidal momentum matrix vs Pinocchio not checked")
    else {
        return;
    };
    let mut rng = testing::rng(2713);
    let cases: Vec<Case> = ROBOTS
        .iter()
        .map(|&name| {
            let path = find_file(&dir, name).unwrap();
            let robot = robodyn::io::load_with_options(
                &path,
                &Default::default(),
                &LoadOptions::floating(),
            )
            .unwrap();
            let n = robot.dof();
            let states = (0..STATES)
                .map(|_| {
                    let [q, v, _] = testing::random_floating_state(&mut rng, n);
                    [q, v]
                })
                .collect();
            (name, robot, states)
        })
        .collect();
    let reference = pinocchio_ccrba(&cases, &dir);
    for (k, (name, robot, states)) in cases.iter().enumerate() {
        let nv = robot.nv();
        let mut data = Data::new(robot);
        let mut ag = DMatrix::zeros(6, nv);
        let mut worst: f64 = 0.0;
        for (s, [q, v]) in states.iter().enumerate() {
            let r = &reference["robots"][k]["states"][s];
            centroidal_map_into(robot, &mut data, q, &mut ag).unwrap();
            let rows: Vec<Vec<f64>> = r["Ag"].as_array().unwrap().iter().map(numbers).collect();
            let pin = DMatrix::from_fn(6, nv, |i, j| rows[i][j]);
            let scale = max_abs(pin.as_slice()).max(1.0);
            let gap = max_abs((&ag - &pin).as_slice()) / scale;
            assert!(
                gap < 1e-10,
                "{name} state {s}: A_G differs from ccrba by {gap:.2e}"
            );
            let hg = &ag * nalgebra::DVector::from_column_slice(v);
            let pin_hg = numbers(&r["hg"]);
            let hscale = max_abs(&pin_hg).max(1.0);
            let hgap = hg
                .iter()
                .zip(&pin_hg)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(hgap < 1e-10 * hscale, "{name} state {s}: h_G {hgap:.2e}");
            worst = worst.max(gap);
        }
        println!("{name}: A_G vs Pinocchio's ccrba, worst relative gap {worst:.2e} over {STATES}");
    }
}

#[test]
fn centroidal_map_times_v_is_the_momentum_and_moves_the_centre_of_mass() {
    let mut rng = testing::rng(4417);
    for trial in 0..12 {
        let n = 1 + trial % 7;
        let robot = testing::random_floating_tree(&mut rng, n, &TreeOptions::default());
        let [q, v, _] = testing::random_floating_state(&mut rng, robot.dof());
        let ag = centroidal_map(&robot, &q).unwrap();
        let hg = &ag * nalgebra::DVector::from_column_slice(&v);
        let mut data = Data::new(&robot);
        let c = centroidal_momentum(&robot, &mut data, &q, &v).unwrap();
        let h = [c.linear.as_slice(), c.angular.as_slice()].concat();
        let scale = max_abs(&h).max(1.0);
        for k in 0..6 {
            assert!(
                (hg[k] - h[k]).abs() < 1e-12 * scale,
                "trial {trial}: (A_G v)[{k}] = {} vs h_G {}",
                hg[k],
                h[k]
            );
        }
        // linear momentum = M dc/dt, by the centre of mass along integrate (no matrix)
        let eps = 1e-5;
        let com_at = |dt: f64| {
            let qt = integrate(&robot, &q, &v, dt).unwrap();
            centroidal_momentum(&robot, &mut Data::new(&robot), qt.as_slice(), &v)
                .unwrap()
                .com
        };
        let dc = (com_at(eps) - com_at(-eps)) / (2.0 * eps) * c.mass;
        for k in 0..3 {
            assert!(
                (dc[k] - hg[k]).abs() < 1e-6 * scale,
                "trial {trial}: M dc/dt[{k}] = {} vs (A_G v) = {}",
                dc[k],
                hg[k]
            );
        }
    }
}

#[test]
fn centroidal_map_refuses_a_fixed_robot_and_a_wrong_shape() {
    let mut rng = testing::rng(3);
    let fixed = testing::random_tree(&mut rng, 3, &TreeOptions::default());
    let e = centroidal_map(&fixed, &vec![0.0; fixed.nq()])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("centroidal map") && e.contains("fixed base"),
        "{e}"
    );
    let robot = testing::random_floating_tree(&mut rng, 3, &TreeOptions::default());
    let [q, _, _] = testing::random_floating_state(&mut rng, robot.dof());
    let mut wrong = DMatrix::zeros(6, 3);
    let e = centroidal_map_into(&robot, &mut Data::new(&robot), &q, &mut wrong)
        .unwrap_err()
        .to_string();
    assert!(e.contains("A_G"), "{e}");
    let mut bad = q.clone();
    bad[6] = 3.0;
    assert!(centroidal_map(&robot, &bad).is_err());
}
