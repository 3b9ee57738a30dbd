//! Derivatives of the inverse and direct dynamic models on real URDFs (example-robot-data: UR5,
//! Panda, Talos full v2 with a fixed base) against Pinocchio's `computeRNEADerivatives` and
//! `computeABADerivatives` (Carpentier & Mansard's analytical derivatives: an independent
//! derivation and implementation). Joints are matched by name.
//!
//! Friction: robodyn applies the URDF `<dynamics>` as Fv qd + Fs sign(qd); Pinocchio ignores
//! it. So dGamma/dqd is compared with Pinocchio's plus diag(Fv); the direct model is run by
//! Pinocchio at the torques minus robodyn's friction (the same qdd), and its dqdd/dqd gets
//! -A^-1 diag(Fv) (the derivative of the friction term through A^-1). dGamma/dq, A, dqdd/dq,
//! A^-1 are compared as they are.
//!
//! Tolerance 1e-10 relative to the largest entry of each matrix (max with 1): both codes are
//! exact to rounding (their gap is ~1e-13 here); a wrong term is O(1).
//!
//! Needs `python3` with `pin` and `example-robot-data`; skips visibly otherwise
//! (`ROBODYN_REQUIRE=pinocchio` makes it fail).

use nalgebra::{DMatrix, DVector};
use robodyn::{
    direct_dynamics_derivatives_into, inverse_dynamics_derivatives_into, DdmDerivatives,
    DerivativesData, IdmDerivatives, Robot,
};
use robodyn_testing as testing;
use serde_json::{json, Value};
use std::path::Path;

mod common;
use common::pinocchio::{by_name, joint_indices, robot_entry, run_script};
use common::{example_robot_data, find_file};

const ROBOTS: [(&str, usize); 3] = [
    ("ur5_robot.urdf", 100),
    ("panda.urdf", 100),
    ("talos_full_v2.urdf", 20),
];

struct Case {
    name: &'static str,
    robot: Robot,
    /// (q, qd, qdd, tau) over the movable joints; tau is what robodyn's direct model takes.
    states: Vec<[Vec<f64>; 4]>,
}

/// The friction torques robodyn adds, Fv qd + Fs sign(qd), and the vector Fv.
fn friction(robot: &Robot, qd: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let m = robot.dynamic();
    let fv: Vec<f64> = (1..=robot.dof()).map(|k| m.link(k).fv).collect();
    let t = (1..=robot.dof())
        .map(|k| m.link(k).fv * qd[k - 1] + m.link(k).fs * qd[k - 1].signum())
        .collect();
    (t, fv)
}

fn reference(cases: &[Case], dir: &Path) -> Value {
    let robots = cases
        .iter()
        .map(|c| {
            let pin = |v: &[f64]| by_name(&c.robot, v);
            let states = c
                .states
                .iter()
                .map(|[q, qd, qdd, tau]| {
                    let (fr, _) = friction(&c.robot, qd);
                    let pin_tau: Vec<f64> = tau.iter().zip(&fr).map(|(t, f)| t - f).collect();
                    json!({"q": pin(q), "qd": pin(qd), "qdd": pin(qdd), "tau": pin(&pin_tau)})
                })
                .collect();
            robot_entry(dir, c.name, states)
        })
        .collect();
    run_script("pinocchio_derivatives.py", robots)
}

/// A JSON matrix in Pinocchio's v order, rows and columns moved to the robot's joint order.
fn matrix(v: &Value, perm: &[usize]) -> DMatrix<f64> {
    let n = perm.len();
    let mut m = DMatrix::zeros(n, n);
    for (r, row) in v.as_array().unwrap().iter().enumerate() {
        for (c, x) in row.as_array().unwrap().iter().enumerate() {
            m[(perm[r], perm[c])] = x.as_f64().unwrap();
        }
    }
    m
}

fn vector(v: &Value, perm: &[usize]) -> DVector<f64> {
    let mut x = DVector::zeros(perm.len());
    for (r, y) in v.as_array().unwrap().iter().enumerate() {
        x[perm[r]] = y.as_f64().unwrap();
    }
    x
}

/// max |ours - pin| / max(1, max |pin|) <= 1e-10; returns the gap.
fn check(what: &str, ours: &DMatrix<f64>, pin: &DMatrix<f64>, ctx: &str) -> f64 {
    let e = (ours - pin).amax() / pin.amax().max(1.0);
    assert!(
        e <= 1e-10,
        "{ctx}: {what} differs by {e:e}\nrobodyn {ours}\npinocchio {pin}"
    );
    e
}

#[test]
fn derivatives_match_pinocchio_on_ur5_panda_talos() {
    let Some(dir) = example_robot_data("derivatives vs Pinocchio not checked") else {
        return;
    };
    let mut rng = testing::rng(28_2026);
    let mut cases = Vec::new();
    for (name, count) in ROBOTS {
        let path = find_file(&dir, name).unwrap_or_else(|| panic!("{name} not found"));
        let robot = robodyn::io::load(&path).unwrap();
        let n = robot.dof();
        let states = (0..count)
            .map(|_| {
                let [q, qd, qdd] = testing::random_state(&mut rng, n);
                let tau: Vec<f64> = (0..n).map(|j| 5.0 * (qdd[j] - q[j])).collect();
                [q, qd, qdd, tau]
            })
            .collect();
        cases.push(Case {
            name,
            robot,
            states,
        });
    }
    let res = reference(&cases, &dir);
    let mut worst = std::collections::BTreeMap::new();
    let mut note = |what: &'static str, e: f64| {
        let w = worst.entry(what).or_insert(0.0f64);
        *w = w.max(e);
    };
    for (ci, c) in cases.iter().enumerate() {
        let robot = &c.robot;
        let r = &res["robots"][ci];
        assert_eq!(
            r["nv"].as_u64().unwrap() as usize,
            robot.dof(),
            "{}",
            c.name
        );
        let perm = joint_indices(robot, &r["joints"]);
        let env = robot.environment();
        let mut data = DerivativesData::new(robot);
        let mut idm = IdmDerivatives::new(robot);
        let mut ddm = DdmDerivatives::new(robot);
        let mut friction_seen = false;
        for (s, [q, qd, qdd, tau]) in c.states.iter().enumerate() {
            let p = &r["states"][s];
            let ctx = format!("{}, state {s}", c.name);
            let (_, fv) = friction(robot, qd);
            friction_seen |= fv.iter().any(|&x| x > 0.0);
            let fv = DMatrix::from_diagonal(&DVector::from_vec(fv));
            inverse_dynamics_derivatives_into(robot, &mut data, env, q, qd, qdd, &mut idm).unwrap();
            let pin_dv = matrix(&p["dtau_dv"], &perm) + &fv;
            note(
                "dtau_dq",
                check("dtau_dq", &idm.dtau_dq, &matrix(&p["dtau_dq"], &perm), &ctx),
            );
            note("dtau_dqd", check("dtau_dqd", &idm.dtau_dqd, &pin_dv, &ctx));
            note("A", check("A", &idm.a, &matrix(&p["M"], &perm), &ctx));
            direct_dynamics_derivatives_into(robot, &mut data, env, q, qd, tau, &mut ddm).unwrap();
            let pin_minv = matrix(&p["Minv"], &perm);
            let pin_qdd =
                DMatrix::from_column_slice(qd.len(), 1, vector(&p["ddq"], &perm).as_slice());
            let our_qdd = DMatrix::from_column_slice(qd.len(), 1, ddm.qdd.as_slice());
            note("qdd", check("qdd", &our_qdd, &pin_qdd, &ctx));
            let pin_ddv = matrix(&p["ddq_dv"], &perm) - &pin_minv * &fv;
            note(
                "dqdd_dq",
                check("dqdd_dq", &ddm.dqdd_dq, &matrix(&p["ddq_dq"], &perm), &ctx),
            );
            note("dqdd_dqd", check("dqdd_dqd", &ddm.dqdd_dqd, &pin_ddv, &ctx));
            note("Ainv", check("Ainv", &ddm.ainv, &pin_minv, &ctx));
        }
        eprintln!("{}: URDF viscous friction present: {friction_seen}", c.name);
    }
    eprintln!("largest relative differences to Pinocchio: {worst:?}");
}
