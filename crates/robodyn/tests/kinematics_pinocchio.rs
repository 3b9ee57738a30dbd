//! Kinematics of real URDFs (example-robot-data: UR5, Panda, Talos full v2 with a fixed base)
//! against Pinocchio, an independent implementation: frame placements, frame Jacobians and their
//! time variation in the three references, frame classical accelerations, centre of mass, its
//! velocity, acceleration and Jacobian, total mass. Frames are matched by URDF link name
//! (Pinocchio's BODY frames), joints by name.
//!
//! Tolerance: 1e-12 absolute on metre-scale quantities (placements, Jacobians, CoM), and 1e-12
//! relative to the largest entry of the compared quantity for velocities, accelerations and J̇
//! (they scale with the random joint speeds, up to ~3 rad/s per joint and ~100 m/s²). Both
//! codes compose the same ~10 transforms in double precision: their difference is a few ulps
//! of the largest term (~1e-15), so 1e-12 fails on any real disagreement (a wrong axis, sign or
//! lever arm gives O(1)).
//!
//! Needs `python3` with `pin` and `example-robot-data`; skips visibly otherwise
//! (`ROBODYN_REQUIRE=pinocchio` makes it fail).

use nalgebra::DMatrix;
use robodyn::algorithms::kinematics::{center_of_mass, center_of_mass_jacobian_into, total_mass};
use robodyn::{
    forward_kinematics_into, frame_classical_acceleration, frame_jacobian_into,
    frame_jacobian_time_variation_into, frame_placement, KinematicsData, Reference, Robot,
};
use robodyn_testing as testing;
use serde_json::{json, Value};
use std::path::Path;

mod common;
use common::pinocchio::{by_name, joint_indices, numbers, robot_entry, run_script};
use common::{example_robot_data, find_file};

/// States per robot: 1000 on each (Talos's JSON reference, 44 joints and 60 links, is the
/// largest part of the test's time).
const ROBOTS: [(&str, usize); 3] = [
    ("ur5_robot.urdf", 1000),
    ("panda.urdf", 1000),
    ("talos_full_v2.urdf", 1000),
];

/// The URDF link names of a robot loaded by robodyn: its links (auxiliary frames' excepted)
/// and the root link (the named frame on R_0).
fn link_names(robot: &Robot) -> Vec<String> {
    let d = robot.description();
    let mut names: Vec<String> = d
        .tools
        .iter()
        .filter(|t| t.frame == 0)
        .map(|t| t.name.clone())
        .collect();
    names.extend(
        d.links
            .iter()
            .map(|l| l.name.clone())
            .filter(|n| !n.ends_with("_aux")),
    );
    names
}

struct Case {
    name: &'static str,
    robot: Robot,
    states: Vec<[Vec<f64>; 3]>,
    frames: Vec<String>,
}

fn pinocchio_reference(cases: &[Case], dir: &Path) -> Value {
    let robots = cases
        .iter()
        .map(|c| {
            let pin = |v: &[f64]| by_name(&c.robot, v);
            let states = c
                .states
                .iter()
                .zip(&c.frames)
                .map(|([q, qd, qdd], f)| json!({"q": pin(q), "qd": pin(qd), "qdd": pin(qdd), "frame": f}))
                .collect();
            robot_entry(dir, c.name, states)
        })
        .collect();
    run_script("pinocchio_kinematics.py", robots)
}

/// A JSON matrix (rows of numbers) with its columns reordered from Pinocchio's v order to the
/// robot's joint vectors.
fn matrix(v: &Value, cols: &[usize]) -> DMatrix<f64> {
    let rows = v.as_array().unwrap();
    let mut m = DMatrix::zeros(rows.len(), cols.len());
    for (r, row) in rows.iter().enumerate() {
        let row = row.as_array().unwrap();
        for (pc, &k) in cols.iter().enumerate() {
            m[(r, k)] = row[pc].as_f64().unwrap();
        }
    }
    m
}

/// The largest |a - b| over the entries, with the scale max(1, max |b|).
fn gap(a: &[f64], b: &[f64]) -> (f64, f64) {
    assert_eq!(a.len(), b.len());
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let s = b.iter().map(|y| y.abs()).fold(1.0, f64::max);
    (d, s)
}

#[derive(Default)]
struct Worst(std::collections::BTreeMap<&'static str, f64>);

impl Worst {
    /// Assert |ours - pin| <= 1e-12 (absolute, or relative to the scale when `relative`).
    fn check(&mut self, what: &'static str, ours: &[f64], pin: &[f64], relative: bool, ctx: &str) {
        let (d, s) = gap(ours, pin);
        let e = if relative { d / s } else { d };
        let w = self.0.entry(what).or_insert(0.0);
        *w = w.max(e);
        assert!(
            e <= 1e-12,
            "{ctx}: {what} differs by {e:e}\n robodyn {ours:?}\n pinocchio {pin:?}"
        );
    }
}

#[test]
fn frames_jacobians_accelerations_and_com_match_pinocchio() {
    let Some(dir) = example_robot_data("kinematics vs Pinocchio not checked") else {
        return;
    };
    let mut rng = testing::rng(20261126);
    let mut cases = Vec::new();
    for (name, n) in ROBOTS {
        let path = find_file(&dir, name).unwrap_or_else(|| panic!("{name} not found"));
        let robot = robodyn::io::load(&path).unwrap();
        let links = link_names(&robot);
        let states: Vec<_> = (0..n)
            .map(|_| testing::random_state(&mut rng, robot.dof()))
            .collect();
        // every link in turn, from a random start
        let frames = (0..n).map(|s| links[s % links.len()].clone()).collect();
        cases.push(Case {
            name,
            robot,
            states,
            frames,
        });
    }
    let res = pinocchio_reference(&cases, &dir);
    let mut worst = Worst::default();
    for (ci, c) in cases.iter().enumerate() {
        let r = &res["robots"][ci];
        let robot = &c.robot;
        let n = robot.dof();
        assert_eq!(r["nv"].as_u64().unwrap() as usize, n, "{}: nv", c.name);
        let cols = joint_indices(robot, &r["joints"]);
        let mass = total_mass(robot);
        assert!(mass > 1.0, "{}: mass {mass}", c.name);
        worst.check(
            "mass",
            &[mass],
            &[r["mass"].as_f64().unwrap()],
            false,
            c.name,
        );
        let mut data = KinematicsData::new(robot);
        let mut jac = DMatrix::zeros(6, n);
        let mut jcom = DMatrix::zeros(3, n);
        for (s, ([q, qd, qdd], fname)) in c.states.iter().zip(&c.frames).enumerate() {
            let p = &r["states"][s];
            let ctx = format!("{}, state {s}, frame {fname}", c.name);
            let f = robot.frame_id(fname).unwrap();
            forward_kinematics_into(robot, &mut data, q, qd, qdd).unwrap();
            let t = frame_placement(robot, &data, &f).unwrap().matrix();
            let pin_m = matrix(&p["M"], &[0, 1, 2, 3]);
            worst.check("placement", t.as_slice(), pin_m.as_slice(), false, &ctx);
            for rf in Reference::ALL {
                let key = rf.name();
                frame_jacobian_into(robot, &data, &f, rf, &mut jac).unwrap();
                let pj = matrix(&p["J"][key], &cols);
                worst.check(
                    "J",
                    jac.as_slice(),
                    pj.as_slice(),
                    false,
                    &format!("{ctx}, {key}"),
                );
                frame_jacobian_time_variation_into(robot, &data, &f, rf, &mut jac).unwrap();
                let pj = matrix(&p["dJ"][key], &cols);
                worst.check(
                    "dJ",
                    jac.as_slice(),
                    pj.as_slice(),
                    true,
                    &format!("{ctx}, {key}"),
                );
                let a = frame_classical_acceleration(robot, &data, &f, rf).unwrap();
                let pa = numbers(&p["acc"][key]);
                worst.check(
                    "acc",
                    a.to_vector().as_slice(),
                    &pa,
                    true,
                    &format!("{ctx}, {key}"),
                );
            }
            let com = center_of_mass(robot, &mut data, None).unwrap();
            worst.check(
                "com",
                com.position.as_slice(),
                &numbers(&p["com"]),
                false,
                &ctx,
            );
            worst.check(
                "vcom",
                com.velocity.as_slice(),
                &numbers(&p["vcom"]),
                true,
                &ctx,
            );
            worst.check(
                "acom",
                com.acceleration.as_slice(),
                &numbers(&p["acom"]),
                true,
                &ctx,
            );
            center_of_mass_jacobian_into(robot, &mut data, None, &mut jcom).unwrap();
            let pj = matrix(&p["Jcom"], &cols);
            worst.check("Jcom", jcom.as_slice(), pj.as_slice(), false, &ctx);
        }
    }
    eprintln!("largest differences to Pinocchio: {:?}", worst.0);
}
