//! Kinematics of floating robots (issue 27, item 3): placements in the world frame, frame
//! Jacobians (6 x nv, the base twist's 6 columns first) and their time variation in the three
//! references, frame classical accelerations, the centre of mass, its velocity, acceleration
//! and Jacobian (3 x nv), through the same checked functions as a fixed base.
//! - Against Pinocchio's free flyer (`JointModelFreeFlyer` root, an independent
//!   implementation) on Talos full v2, HyQ and Solo12 (example-robot-data): every BODY
//!   frame's placement (`framesForwardKinematics`, matched by link name), one frame per state
//!   (every link in turn) for the rest (`getFrameJacobian`, `getFrameJacobianTimeVariation`,
//!   `getFrameClassicalAcceleration` in WORLD, LOCAL, LOCAL_WORLD_ALIGNED), `centerOfMass`
//!   (q, v, a) and `jacobianCenterOfMass`, to 1e-10 relative to the largest entry (and 1).
//!   Needs `python3` with `pin` and `example-robot-data`; skips visibly otherwise.
//! - Finite differences on random floating trees (robodyn-testing: fixed frames, prismatic
//!   joints): each column k of the LocalWorldAligned Jacobian and of the CoM Jacobian is the
//!   derivative of the frame's position / orientation and of G along integrate(q, ±eps e_k)
//!   (the base's columns move the base on SE(3)); J̇ is the derivative of J along
//!   integrate(q, ±eps v); the frame velocity is J v.
//! - The inverse models and the Newton–Euler frame reader refuse a floating robot.

use nalgebra::{DMatrix, Matrix3, Vector3};
use rand::Rng;
use robodyn::algorithms::kinematics::{
    center_of_mass, center_of_mass_jacobian_from_q_into, center_of_mass_jacobian_into,
};
use robodyn::io::LoadOptions;
use robodyn::{
    forward_kinematics_into, frame_classical_acceleration, frame_jacobian_from_q_into,
    frame_jacobian_into, frame_jacobian_time_variation_into, frame_placement, frame_velocity,
    integrate, placements_into, KinematicsData, Reference, Robot,
};
use robodyn_testing::{self as testing, TreeOptions};
use serde_json::{json, Value};
use std::path::Path;

mod common;
use common::pinocchio::{by_name, joint_indices, numbers, robot_entry, run_script};
use common::{example_robot_data, find_file};

const ROBOTS: [(&str, usize); 3] = [
    ("talos_full_v2.urdf", 300),
    ("hyq_no_sensors.urdf", 500),
    ("solo12.urdf", 500),
];
const TOL: f64 = 1e-10;

/// A random floating state of `robot`: q (nq, the base within 2 m of the origin), v, a (nv).
fn random_state<R: Rng>(rng: &mut R, robot: &Robot) -> [Vec<f64>; 3] {
    let [mut q, v, a] = testing::random_floating_state(rng, robot.dof());
    for x in &mut q[..3] {
        *x = rng.random_range(-2.0..2.0);
    }
    [q, v, a]
}

/// The URDF link names of a floating robot: the root link (on the base) and the others.
fn link_names(robot: &Robot) -> Vec<String> {
    let d = robot.description();
    let mut names: Vec<String> = d.tools.iter().map(|t| t.name.clone()).collect();
    names.extend(d.links.iter().map(|l| l.name.clone()));
    names.retain(|n| !n.ends_with("_aux"));
    names.dedup();
    names
}

/// A JSON matrix with its columns `cols[p]` (robodyn's index of Pinocchio's column p).
fn matrix(v: &Value, cols: &[usize]) -> DMatrix<f64> {
    let rows = v.as_array().unwrap();
    let mut m = DMatrix::zeros(rows.len(), cols.len());
    for (r, row) in rows.iter().enumerate() {
        for (pc, x) in numbers(row).into_iter().enumerate() {
            m[(r, cols[pc])] = x;
        }
    }
    m
}

/// max |a - b| / max(1, max |b|).
fn rel_gap(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    d / b.iter().map(|y| y.abs()).fold(1.0, f64::max)
}

#[derive(Default)]
struct Worst(std::collections::BTreeMap<&'static str, f64>);

impl Worst {
    fn check(&mut self, what: &'static str, ours: &[f64], pin: &[f64], ctx: &str) {
        let e = rel_gap(ours, pin);
        let w = self.0.entry(what).or_insert(0.0);
        *w = w.max(e);
        assert!(
            e <= TOL,
            "{ctx}: {what} differs by {e:e}\n robodyn {ours:?}\n pinocchio {pin:?}"
        );
    }
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
            let zeros = vec![0.0; c.robot.nv()];
            let states = c
                .states
                .iter()
                .zip(&c.frames)
                .map(|([q, v, a], f)| {
                    json!({"base_q": &q[..7], "base_v": &v[..6], "base_a": &a[..6],
                           "base_tau": &zeros[..6], "q": pin(&q[7..]), "v": pin(&v[6..]),
                           "a": pin(&a[6..]), "tau": pin(&zeros[6..]), "frame": f})
                })
                .collect();
            robot_entry(dir, c.name, states)
        })
        .collect();
    run_script("pinocchio_floating.py", robots)
}

fn load_cases(dir: &Path) -> Vec<Case> {
    let mut rng = testing::rng(2703);
    ROBOTS
        .iter()
        .map(|&(name, n)| {
            let path = find_file(dir, name).unwrap_or_else(|| panic!("{name} not found"));
            let robot = robodyn::io::load_with_options(
                &path,
                &Default::default(),
                &LoadOptions::floating(),
            )
            .unwrap();
            let links = link_names(&robot);
            let states = (0..n).map(|_| random_state(&mut rng, &robot)).collect();
            let frames = (0..n).map(|s| links[s % links.len()].clone()).collect();
            Case {
                name,
                robot,
                states,
                frames,
            }
        })
        .collect()
}

#[test]
fn floating_kinematics_match_pinocchio_free_flyer() {
    let Some(dir) = example_robot_data("floating-base kinematics vs Pinocchio not checked") else {
        return;
    };
    let cases = load_cases(&dir);
    let res = pinocchio_reference(&cases, &dir);
    let mut worst = Worst::default();
    let mut placements = 0usize;
    for (ci, c) in cases.iter().enumerate() {
        let r = &res["robots"][ci];
        let robot = &c.robot;
        let nv = robot.nv();
        assert_eq!(r["nv"].as_u64().unwrap() as usize, nv, "{}: nv", c.name);
        let mut cols: Vec<usize> = (0..6).collect();
        cols.extend(joint_indices(robot, &r["joints"]).iter().map(|k| 6 + k));
        let mut data = KinematicsData::new(robot);
        let mut scratch = KinematicsData::new(robot);
        let (mut jac, mut jq) = (DMatrix::zeros(6, nv), DMatrix::zeros(6, nv));
        let (mut jcom, mut jcom_q) = (DMatrix::zeros(3, nv), DMatrix::zeros(3, nv));
        for (s, ([q, v, a], fname)) in c.states.iter().zip(&c.frames).enumerate() {
            let p = &r["states"][s];
            let ctx = format!("{}, state {s}, frame {fname}", c.name);
            forward_kinematics_into(robot, &mut data, q, v, a).unwrap();
            // every BODY frame's placement, by link name
            for (link, m) in p["placements"].as_object().unwrap() {
                let f = robot.frame_id(link).unwrap();
                let t = frame_placement(robot, &data, &f).unwrap().matrix();
                let pm = matrix(m, &[0, 1, 2, 3]);
                worst.check("placements", t.as_slice(), pm.as_slice(), &ctx);
                placements += 1;
            }
            let f = robot.frame_id(fname).unwrap();
            for rf in Reference::ALL {
                let ctx = format!("{ctx}, {}", rf.name());
                let key = rf.name();
                frame_jacobian_into(robot, &data, &f, rf, &mut jac).unwrap();
                let pj = matrix(&p["J"][key], &cols);
                worst.check("J", jac.as_slice(), pj.as_slice(), &ctx);
                // the support-only route of computeFrameJacobian gives the same matrix
                frame_jacobian_from_q_into(robot, &mut scratch, q, &f, rf, &mut jq).unwrap();
                worst.check("J from q", jq.as_slice(), pj.as_slice(), &ctx);
                frame_jacobian_time_variation_into(robot, &data, &f, rf, &mut jac).unwrap();
                let pj = matrix(&p["dJ"][key], &cols);
                worst.check("dJ", jac.as_slice(), pj.as_slice(), &ctx);
                let acc = frame_classical_acceleration(robot, &data, &f, rf).unwrap();
                let pa = numbers(&p["acc"][key]);
                worst.check("acc", acc.to_vector().as_slice(), &pa, &ctx);
            }
            let com = center_of_mass(robot, &mut data, None).unwrap();
            worst.check("com", com.position.as_slice(), &numbers(&p["com"]), &ctx);
            worst.check("vcom", com.velocity.as_slice(), &numbers(&p["vcom"]), &ctx);
            worst.check(
                "acom",
                com.acceleration.as_slice(),
                &numbers(&p["acom"]),
                &ctx,
            );
            assert!((com.mass - r["mass"].as_f64().unwrap()).abs() < 1e-9 * com.mass);
            center_of_mass_jacobian_into(robot, &mut data, None, &mut jcom).unwrap();
            let pj = matrix(&p["Jcom"], &cols);
            worst.check("Jcom", jcom.as_slice(), pj.as_slice(), &ctx);
            let g = center_of_mass_jacobian_from_q_into(robot, &mut scratch, q, None, &mut jcom_q)
                .unwrap();
            worst.check("Jcom from q", jcom_q.as_slice(), pj.as_slice(), &ctx);
            worst.check("com from q", g.as_slice(), &numbers(&p["com"]), &ctx);
        }
    }
    assert!(placements > 10_000, "{placements} placements compared");
    eprintln!(
        "floating kinematics, {placements} placements; largest relative differences to \
         Pinocchio: {:?}",
        worst.0
    );
}

/// The frame's placement and G at `q`.
fn pose_and_com(
    robot: &Robot,
    data: &mut KinematicsData,
    q: &[f64],
    f: &robodyn::FrameId,
) -> (Vector3<f64>, Matrix3<f64>, Vector3<f64>) {
    forward_kinematics_into(
        robot,
        data,
        q,
        &vec![0.0; robot.nv()],
        &vec![0.0; robot.nv()],
    )
    .unwrap();
    let t = frame_placement(robot, data, f).unwrap();
    let g = center_of_mass(robot, data, None).unwrap().position;
    (t.pos, t.rot, g)
}

#[test]
fn floating_jacobians_are_derivatives_along_integrate() {
    let mut rng = testing::rng(2704);
    let eps = 1e-6;
    let mut worst = [0.0f64; 4];
    for case in 0..40 {
        let n = 1 + case % 9;
        let robot = testing::random_floating_tree(&mut rng, n, &TreeOptions::default());
        let nv = robot.nv();
        let [q, v, _] = testing::random_floating_state(&mut rng, robot.dof());
        let names = robot.frame_names();
        let f = robot
            .frame_id(names[rng.random_range(0..names.len())])
            .unwrap();
        let mut data = KinematicsData::new(&robot);
        let (mut j, mut jcom) = (DMatrix::zeros(6, nv), DMatrix::zeros(3, nv));
        placements_into(&robot, &mut data, &q).unwrap();
        frame_jacobian_into(&robot, &data, &f, Reference::LocalWorldAligned, &mut j).unwrap();
        center_of_mass_jacobian_into(&robot, &mut data, None, &mut jcom).unwrap();
        let ctx = format!("case {case} ({n} joints), frame {:?}", f.parent());
        for k in 0..nv {
            let mut e = vec![0.0; nv];
            e[k] = 1.0;
            let qp = integrate(&robot, &q, &e, eps).unwrap();
            let qm = integrate(&robot, &q, &e, -eps).unwrap();
            let (pp, rp, gp) = pose_and_com(&robot, &mut data, qp.as_slice(), &f);
            let (pm, rm, gm) = pose_and_com(&robot, &mut data, qm.as_slice(), &f);
            let dp = (pp - pm) / (2.0 * eps);
            // the rotation from qm to qp in world axes, from its skew part (sin θ = θ to θ³/6;
            // an angle read from the trace, acos near 1, would keep half the digits)
            let d = rp * rm.transpose();
            let dw = Vector3::new(
                d[(2, 1)] - d[(1, 2)],
                d[(0, 2)] - d[(2, 0)],
                d[(1, 0)] - d[(0, 1)],
            ) / (4.0 * eps);
            let dg = (gp - gm) / (2.0 * eps);
            let fd = [dp.x, dp.y, dp.z, dw.x, dw.y, dw.z];
            let col: Vec<f64> = j.column(k).iter().copied().collect();
            let gap = rel_gap(&col, &fd);
            worst[0] = worst[0].max(gap);
            assert!(gap < 1e-7, "{ctx}: J column {k} vs FD: {col:?} {fd:?}");
            let col: Vec<f64> = jcom.column(k).iter().copied().collect();
            let gap = rel_gap(&col, dg.as_slice());
            worst[1] = worst[1].max(gap);
            assert!(gap < 1e-7, "{ctx}: Jcom column {k} vs FD: {col:?} {dg:?}");
        }
        // the frame velocity is J v; J̇ is the derivative of J along integrate(q, ±eps v)
        forward_kinematics_into(&robot, &mut data, &q, &v, &vec![0.0; nv]).unwrap();
        for rf in Reference::ALL {
            frame_jacobian_into(&robot, &data, &f, rf, &mut j).unwrap();
            let jv = &j * nalgebra::DVector::from_column_slice(&v);
            let vel = frame_velocity(&robot, &data, &f, rf).unwrap().to_vector();
            let gap = rel_gap(jv.as_slice(), vel.as_slice());
            worst[2] = worst[2].max(gap);
            assert!(gap < 1e-12, "{ctx}, {}: J v vs velocity", rf.name());
            let mut jd = DMatrix::zeros(6, nv);
            frame_jacobian_time_variation_into(&robot, &data, &f, rf, &mut jd).unwrap();
            let mut jm = [DMatrix::zeros(6, nv), DMatrix::zeros(6, nv)];
            let mut other = KinematicsData::new(&robot);
            for (s, sign) in [1.0, -1.0].into_iter().enumerate() {
                let qs = integrate(&robot, &q, &v, sign * eps).unwrap();
                placements_into(&robot, &mut other, qs.as_slice()).unwrap();
                frame_jacobian_into(&robot, &other, &f, rf, &mut jm[s]).unwrap();
            }
            let fd = (&jm[0] - &jm[1]) / (2.0 * eps);
            let gap = rel_gap(jd.as_slice(), fd.as_slice());
            worst[3] = worst[3].max(gap);
            assert!(gap < 1e-6, "{ctx}, {}: dJ vs FD gap {gap:e}", rf.name());
        }
    }
    eprintln!(
        "floating kinematics vs finite differences: J {:.1e}, Jcom {:.1e}, J v {:.1e}, dJ {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
}

#[test]
fn inverse_models_refuse_floating_robots_with_the_reason() {
    let mut rng = testing::rng(2705);
    let robot = testing::random_floating_tree(&mut rng, 6, &TreeOptions::default());
    let f = robot.frame_id_of(robot.nl()).unwrap();
    let q = vec![0.0; robot.dof()];
    let ik = robodyn::algorithms::inverse_geometry::inverse_kinematics(
        &robot,
        &q,
        &f,
        Reference::LocalWorldAligned,
        &[0.0; 6],
        &Default::default(),
    );
    let numeric =
        robodyn::algorithms::inverse_geometry::NumericIgm::new(&robot, f, Default::default());
    let closed = robodyn::algorithms::inverse_geometry::ClosedFormIgm::new(&robot);
    for msg in [
        ik.unwrap_err().to_string(),
        numeric.err().unwrap().to_string(),
        closed.err().unwrap().to_string(),
    ] {
        assert!(
            msg.contains("floating base") && msg.contains("fixed base"),
            "{msg}"
        );
    }
    let data = robodyn::Data::new(&robot);
    let err = robodyn::algorithms::kinematics::frame_motion_from_newton_euler(
        &robot,
        &data,
        robot.environment(),
        &f,
    )
    .unwrap_err()
    .to_string();
    assert!(err.contains("floating base"), "{err}");
}

#[test]
fn floating_kinematics_check_their_inputs() {
    let mut rng = testing::rng(2706);
    let robot = testing::random_floating_tree(&mut rng, 4, &TreeOptions::default());
    let mut data = KinematicsData::new(&robot);
    let [q, v, a] = testing::random_floating_state(&mut rng, robot.dof());
    // joint vectors alone (N entries) are not a floating configuration
    let err = placements_into(&robot, &mut data, &q[7..])
        .unwrap_err()
        .to_string();
    assert!(err.contains("nq = 7 + 4"), "{err}");
    let err = forward_kinematics_into(&robot, &mut data, &q, &v[6..], &a)
        .unwrap_err()
        .to_string();
    assert!(err.contains("nv = 6 + 4"), "{err}");
    let mut bad = q.clone();
    bad[6] += 0.1;
    let err = placements_into(&robot, &mut data, &bad)
        .unwrap_err()
        .to_string();
    assert!(err.contains("quaternion"), "{err}");
    // a Jacobian over the joints only is the wrong size
    placements_into(&robot, &mut data, &q).unwrap();
    let f = robot.frame_id_of(1).unwrap();
    let mut j = DMatrix::zeros(6, robot.dof());
    let err = frame_jacobian_into(&robot, &data, &f, Reference::World, &mut j)
        .unwrap_err()
        .to_string();
    assert!(err.contains("6 x 10"), "{err}");
}
