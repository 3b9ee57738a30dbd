//! Floating-base dynamics of real URDFs (example-robot-data: Talos full v2, HyQ, Solo12 with a
//! free-flyer root) against Pinocchio with `JointModelFreeFlyer`, an independent implementation:
//! inverse dynamics (`rnea`: base wrench and joint torques), the inertia matrix (`crba`,
//! symmetrized) and direct dynamics (`aba`) by both of robodyn's methods (composite and
//! articulated bodies), on 1000 random states per robot, to 1e-10 relative to the largest entry
//! of the compared quantity. The conventions are the same (q = [p, quaternion x y z w, joints],
//! v and a in the base frame), so only the joint order is mapped (by name). Pinocchio ignores
//! URDF `<dynamics>`; robodyn applies them as FV, FS: their torques fv v + fs sign(v) are added
//! to Pinocchio's on our side.
//!
//! Needs `python3` with `pin` and `example-robot-data`; skips visibly otherwise
//! (`ROBODYN_REQUIRE=pinocchio` makes it fail).

use nalgebra::{DMatrix, UnitQuaternion, Vector3};
use rand::Rng;
use robodyn::io::LoadOptions;
use robodyn::{
    centroidal_momentum, direct_dynamics_into, inertia_matrix_into, integrate, Data, Method,
};
use robodyn::{Robot, State};
use robodyn_testing as testing;
use serde_json::{json, Value};
use std::path::Path;

mod common;
use common::pinocchio::{by_name, joint_indices, numbers, robot_entry, run_script};
use common::{example_robot_data, find_file};

const ROBOTS: [&str; 3] = ["talos_full_v2.urdf", "hyq_no_sensors.urdf", "solo12.urdf"];
const STATES: usize = 1000;
const TOL: f64 = 1e-10;

/// A random floating state: q (nq), v, a, tau (nv).
fn random_state<R: Rng>(rng: &mut R, robot: &Robot) -> [Vec<f64>; 4] {
    let n = robot.dof();
    let [qj, vj, aj] = testing::random_state(rng, n);
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let quat = UnitQuaternion::new(axis * rng.random_range(0.0..3.0));
    let mut q: Vec<f64> = (0..3).map(|_| rng.random_range(-2.0..2.0)).collect();
    q.extend([quat.i, quat.j, quat.k, quat.w]);
    q.extend(qj);
    let mut six = |s: f64| {
        (0..6)
            .map(|_| rng.random_range(-s..s))
            .collect::<Vec<f64>>()
    };
    let (v, a, tau) = (six(2.0), six(5.0), six(50.0));
    let tj: Vec<f64> = (0..n).map(|_| rng.random_range(-30.0..30.0)).collect();
    [
        q,
        v.into_iter().chain(vj).collect(),
        a.into_iter().chain(aj).collect(),
        tau.into_iter().chain(tj).collect(),
    ]
}

/// A robot's file name, the robot and its random states (q, v, a, tau).
type Case = (&'static str, Robot, Vec<[Vec<f64>; 4]>);

fn pinocchio_reference(cases: &[Case], dir: &Path) -> Value {
    let robots = cases
        .iter()
        .map(|(name, robot, states)| {
            let pin = |v: &[f64]| by_name(robot, v);
            let states = states
                .iter()
                .map(|[q, v, a, t]| {
                    json!({"base_q": &q[..7], "base_v": &v[..6], "base_a": &a[..6],
                           "base_tau": &t[..6], "q": pin(&q[7..]), "v": pin(&v[6..]),
                           "a": pin(&a[6..]), "tau": pin(&t[6..])})
                })
                .collect();
            robot_entry(dir, name, states)
        })
        .collect();
    run_script("pinocchio_floating.py", robots)
}

/// Pinocchio's nv vector in robodyn's order (`perm[p]`: robodyn index of Pinocchio entry p).
fn reorder(v: &[f64], perm: &[usize]) -> Vec<f64> {
    let mut out = vec![0.0; v.len()];
    for (p, &k) in perm.iter().enumerate() {
        out[k] = v[p];
    }
    out
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

/// The joint torques of URDF `<dynamics>` (FV v + FS sign v), robodyn's order over nv.
fn joint_friction(robot: &Robot, v: &[f64]) -> Vec<f64> {
    let m = robot.dynamic();
    let mut f = vec![0.0; v.len()];
    for k in 0..robot.dof() {
        let l = m.link(k + 1);
        let x = v[6 + k];
        f[6 + k] = l.fv * x + l.fs * if x == 0.0 { 0.0 } else { x.signum() };
    }
    f
}

#[test]
fn floating_dynamics_match_pinocchio_free_flyer() {
    let Some(dir) = example_robot_data("floating-base dynamics vs Pinocchio not checked") else {
        return;
    };
    let mut rng = testing::rng(27);
    let mut cases = Vec::new();
    for name in ROBOTS {
        let path = find_file(&dir, name).unwrap_or_else(|| panic!("{name} not found"));
        let robot =
            robodyn::io::load_with_options(&path, &Default::default(), &LoadOptions::floating())
                .unwrap();
        assert!(robot.is_floating());
        let states = (0..STATES)
            .map(|_| random_state(&mut rng, &robot))
            .collect();
        cases.push((name, robot, states));
    }
    let res = pinocchio_reference(&cases, &dir);
    for (ci, (name, robot, states)) in cases.iter().enumerate() {
        let r = &res["robots"][ci];
        let nv = robot.nv();
        assert_eq!(r["nv"].as_u64().unwrap() as usize, nv, "{name}: nv");
        let mut perm: Vec<usize> = (0..6).collect();
        perm.extend(joint_indices(robot, &r["joints"]).iter().map(|k| 6 + k));
        let mass: f64 = robot.floating_base().unwrap().body.mass
            + (1..=robot.dof())
                .map(|k| robot.dynamic().link(k).mass)
                .sum::<f64>();
        let total = robodyn::algorithms::kinematics::total_mass(robot);
        assert!(
            (total - mass).abs() < 1e-9 * mass,
            "{name}: total_mass {total} vs {mass}"
        );
        assert!(
            (mass - r["mass"].as_f64().unwrap()).abs() < 1e-9 * mass,
            "{name}: total mass {mass} vs {}",
            r["mass"]
        );
        let mut data = Data::new(robot);
        let env = robot.environment();
        let (mut tau, mut qdd) = (vec![0.0; nv], vec![0.0; nv]);
        let mut a_mat = DMatrix::zeros(nv, nv);
        let mut worst = [0.0f64; 6];
        for (s, [q, v, a, t]) in states.iter().enumerate() {
            let p = &r["states"][s];
            let ctx = format!("{name}, state {s}");
            let fr = joint_friction(robot, v);
            // inverse dynamics
            let state = State { q, qd: v, qdd: a };
            robodyn::inverse_dynamics_state_into(robot, &mut data, env, state, &mut tau).unwrap();
            let pin_tau: Vec<f64> = reorder(&numbers(&p["rnea"]), &perm)
                .iter()
                .zip(&fr)
                .map(|(x, f)| x + f)
                .collect();
            let e = rel_gap(&tau, &pin_tau);
            worst[0] = worst[0].max(e);
            assert!(e <= TOL, "{ctx}: rnea differs by {e:e}");
            // inertia matrix
            inertia_matrix_into(robot, &mut data, q, &mut a_mat).unwrap();
            let rows = p["crba"].as_array().unwrap();
            let mut pin_m = DMatrix::zeros(nv, nv);
            for (pr, row) in rows.iter().enumerate() {
                for (pc, x) in numbers(row).into_iter().enumerate() {
                    pin_m[(perm[pr], perm[pc])] = x;
                }
            }
            let e = rel_gap(a_mat.as_slice(), pin_m.as_slice());
            worst[1] = worst[1].max(e);
            assert!(e <= TOL, "{ctx}: crba differs by {e:e}");
            // direct dynamics, both methods, torques with our joint friction added
            let pin_a = reorder(&numbers(&p["aba"]), &perm);
            let tr: Vec<f64> = t.iter().zip(&fr).map(|(x, f)| x + f).collect();
            for (m, w) in [(Method::Composite, 2), (Method::ArticulatedBody, 3)] {
                direct_dynamics_into(robot, &mut data, env, q, v, &tr, m, &mut qdd).unwrap();
                let e = rel_gap(&qdd, &pin_a);
                worst[w] = worst[w].max(e);
                assert!(e <= TOL, "{ctx}: {} differs from aba by {e:e}", m.name());
            }
            // centroidal momentum and centre of mass (world frame)
            let c = centroidal_momentum(robot, &mut data, q, v).unwrap();
            let ours: Vec<f64> = c.linear.iter().chain(c.angular.iter()).copied().collect();
            let e = rel_gap(&ours, &numbers(&p["hg"]));
            worst[4] = worst[4].max(e);
            assert!(e <= TOL, "{ctx}: centroidal momentum differs by {e:e}");
            let e = rel_gap(c.com.as_slice(), &numbers(&p["com"]));
            assert!(e <= TOL, "{ctx}: centre of mass differs by {e:e}");
            assert!((c.mass - mass).abs() < 1e-9 * mass);
            // integration on SE(3): the base pose after 0.01 s at v (quaternion up to sign)
            let next = integrate(robot, q, v, 0.01).unwrap();
            let pin_next = numbers(&p["integrate"]);
            let sign = if next[6] * pin_next[6] < 0.0 {
                -1.0
            } else {
                1.0
            };
            let ours: Vec<f64> = (0..7)
                .map(|k| if k >= 3 { sign * next[k] } else { next[k] })
                .collect();
            let e = rel_gap(&ours, &pin_next);
            worst[5] = worst[5].max(e);
            assert!(e <= TOL, "{ctx}: integrate differs by {e:e}");
            let qn = nalgebra::Vector4::new(next[3], next[4], next[5], next[6]).norm();
            assert!((qn - 1.0).abs() < 1e-14, "{ctx}: |quaternion| = {qn}");
            for k in 0..robot.dof() {
                assert_eq!(next[7 + k], q[7 + k] + v[6 + k] * 0.01);
            }
        }
        eprintln!(
            "{name}: worst relative gaps rnea {:.1e}, crba {:.1e}, composite {:.1e}, aba {:.1e}, \
             centroidal {:.1e}, integrate {:.1e}",
            worst[0], worst[1], worst[2], worst[3], worst[4], worst[5]
        );
    }
}
