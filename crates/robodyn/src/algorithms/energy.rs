//! The Lagrangian route (§10.2.1): link velocities by eqs 10.1–10.2, kinetic and potential
//! energy of the tree, and joint torques by the Euler–Lagrange equations with derivatives by
//! automatic differentiation (hyper-dual numbers, exact to rounding).
//!
//! Independent of the Newton–Euler recursion (it shares only the frame transforms iA_j, iP_j),
//! so the two routes cross-check each other. Conventions (chapter 10, §10.2.1):
//! - link j's kinetic energy about O_j in R_j, `E_j = 1/2 (M V'V + 2 V'(w x MS) + w'J w)`
//!   ([9.16]), plus the rotor's `1/2 Ia_j qd_j^2`;
//! - potential energy `U_j = -g'(M_j 0P_j + 0A_j jMS_j)` ([9.25]);
//! - the base moves with angular velocity w0 and origin velocity v0 (components in R_0);
//! - fe_j, me_j are exerted by link j on the environment: the joints supply their power
//!   `P = sum_j V_j'fe_j + w_j'me_j`, whose generalized force is dP/dqd.

use crate::error::{Error, Result};
use crate::model::{BaseMotion, DynModel, Environment, JointType, LinkConstants, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DVector, Matrix3, Vector3};
use num_dual::HyperDual64;

/// Velocities of every link (eqs 10.1–10.2): `w[j]` = jw_j and `v[j]` = jV_j (velocity of O_j),
/// in R_j, for j = 0..NL (index 0 is the base, with w0 and v0). Also returns the placements
/// 0A_j and 0P_j in `rot0`/`pos0` (index 0 the identity / origin).
#[allow(clippy::too_many_arguments)]
pub fn link_velocities<T: DynScalar>(
    model: &DynModel<T>,
    q: &[T],
    qd: &[T],
    w0: &Vector3<T>,
    v0: &Vector3<T>,
    w: &mut [Vector3<T>],
    v: &mut [Vector3<T>],
    rot0: &mut [Matrix3<T>],
    pos0: &mut [Vector3<T>],
) {
    w[0] = w0.clone();
    v[0] = v0.clone();
    rot0[0] = Matrix3::identity();
    pos0[0] = Vector3::zeros();
    for j in 1..=model.nl {
        let fr = model.frame(j);
        let i = fr.ant;
        let (a, p) = fr.transform(&q[j - 1]);
        let at = a.transpose();
        // (10.1): jw_j = jA_i iw_i + sigma_bar qd a_j
        let mut wj = &at * &w[i];
        // (10.2): jV_j = jA_i (iV_i + iw_i x iP_j) + sigma qd a_j
        let mut vj = &at * (&v[i] + w[i].cross(&p));
        match fr.joint {
            JointType::Revolute => wj.z += qd[j - 1].clone(),
            JointType::Prismatic => vj.z += qd[j - 1].clone(),
            JointType::Fixed => {}
        }
        w[j] = wj;
        v[j] = vj;
        pos0[j] = &pos0[i] + &rot0[i] * &p;
        rot0[j] = &rot0[i] * a;
    }
}

/// The three energy-like quantities of the tree, in scalar `T`.
#[derive(Clone, Debug)]
pub struct Energies<T> {
    /// Kinetic energy of the links ([9.16]) and rotors (1/2 Ia qd^2).
    pub kinetic: T,
    /// Potential energy in the gravity field ([9.25]).
    pub potential: T,
    /// Power the links deliver to the environment through the external wrenches.
    pub wrench_power: T,
}

/// Kinetic, potential energy and external-wrench power for a base moving with angular
/// velocity `w0` and origin velocity `v0` (components in R_0). Allocates its buffers.
pub fn energies<T: DynScalar>(
    model: &DynModel<T>,
    q: &[T],
    qd: &[T],
    w0: &Vector3<T>,
    v0: &Vector3<T>,
) -> Energies<T> {
    let n = model.nl + 1;
    let mut w = vec![Vector3::zeros(); n];
    let mut v = vec![Vector3::zeros(); n];
    let mut rot0 = vec![Matrix3::identity(); n];
    let mut pos0 = vec![Vector3::zeros(); n];
    link_velocities(model, q, qd, w0, v0, &mut w, &mut v, &mut rot0, &mut pos0);
    let half = T::from_f64(0.5);
    let mut kinetic = T::zero();
    let mut potential = T::zero();
    let mut wrench_power = T::zero();
    for j in 1..=model.nl {
        let l = model.link(j);
        let (wj, vj) = (&w[j], &v[j]);
        // [9.16]: 2 E_j = M V'V + 2 V'(w x MS) + w'J w
        let two_e = l.mass.clone() * vj.dot(vj)
            + T::from_f64(2.0) * vj.dot(&wj.cross(&l.ms))
            + wj.dot(&(&l.inertia * wj));
        kinetic += half.clone() * two_e;
        if model.frame(j).joint.is_movable() {
            kinetic += half.clone() * l.ia.clone() * qd[j - 1].clone() * qd[j - 1].clone();
        }
        // [9.25]: U_j = -g'(M 0P_j + 0A_j MS_j)
        let mc = &pos0[j] * l.mass.clone() + &rot0[j] * &l.ms;
        potential -= model.env.gravity.dot(&mc);
        let e = model.env.wrench(j);
        wrench_power += vj.dot(&e.force) + wj.dot(&e.moment);
    }
    Energies {
        kinetic,
        potential,
        wrench_power,
    }
}

fn map3<T: DynScalar>(v: &Vector3<f64>) -> Vector3<T> {
    v.map(T::from_f64)
}

/// The numeric model in another scalar (constants with zero derivative parts).
pub fn convert_model<T: DynScalar>(m: &DynModel<f64>) -> DynModel<T> {
    let f = T::from_f64;
    DynModel {
        nl: m.nl,
        frames: m.frames.iter().map(|c| c.map(|&x| f(x))).collect(),
        links: m
            .links
            .iter()
            .map(|l| LinkConstants {
                inertia: l.inertia.map(f),
                inertia_diff: map3(&l.inertia_diff),
                ms: map3(&l.ms),
                mass: f(l.mass),
                ia: f(l.ia),
                fs: f(l.fs),
                fv: f(l.fv),
            })
            .collect(),
        env: convert_environment(&m.env),
        link_of: m.link_of.clone(),
        index: m.index.clone(),
        folded: m
            .folded
            .iter()
            .map(|fl| crate::model::FoldedLink {
                host: fl.host,
                link: fl.link,
                rot: fl.rot.map(f),
                pos: map3(&fl.pos),
            })
            .collect(),
    }
}

fn convert_environment<T: DynScalar>(e: &Environment) -> Environment<T> {
    let b = &e.base;
    let mut out = Environment::new(
        map3(&e.gravity),
        BaseMotion {
            w0: map3(&b.w0),
            wp0: map3(&b.wp0),
            v0: map3(&b.v0),
            vp0: map3(&b.vp0),
        },
        e.n_links(),
    );
    for (k, w) in e.wrenches().iter().enumerate() {
        out.set_wrench_by_link(k + 1, map3(&w.force), map3(&w.moment))
            .expect("same number of links");
    }
    out
}

/// Check joint vectors over the movable joints and scatter them into tree arrays (NL entries).
fn tree_arrays<const K: usize>(
    robot: &Robot,
    names: [&str; K],
    x: [&[f64]; K],
) -> Result<[Vec<f64>; K]> {
    let c = robot.coordinates();
    let mut out: [Vec<f64>; K] = std::array::from_fn(|_| vec![0.0; robot.nl()]);
    for k in 0..K {
        c.check(names[k], x[k], "movable joints")?;
        c.scatter(x[k], &mut out[k]);
    }
    Ok(out)
}

fn finite(x: f64, what: &str) -> Result<f64> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(Error::Numerical(format!("{what} is not finite ({x})")))
    }
}

/// Kinetic energy of the tree (J): links [9.16] with velocities 10.1–10.2 including the base
/// velocities w0, v0 of the robot's environment, plus rotors 1/2 Ia qd^2. `q`, `qd` over the
/// movable joints.
pub fn kinetic_energy(robot: &Robot, q: &[f64], qd: &[f64]) -> Result<f64> {
    let rotors = drive_energy(robot, qd);
    let [q, qd] = tree_arrays(robot, ["q", "qd"], [q, qd])?;
    let m = robot.numeric();
    let b = &m.env.base;
    finite(
        energies(m, &q, &qd, &b.w0, &b.v0).kinetic + rotors,
        "the kinetic energy",
    )
}

/// The kinetic energy of the motors of a transmission, 1/2 m_d' Ia m_d
/// ([`crate::model::MotorDrives`]; 0 without one). A vector of the wrong length gives 0 here:
/// the caller's check of the vectors refuses it.
fn drive_energy(robot: &Robot, qd: &[f64]) -> f64 {
    match robot.motor_drives() {
        Some(d) if qd.len() == robot.dof() => d.kinetic_energy(qd),
        _ => 0.0,
    }
}

/// Potential energy in the gravity field (J, [9.25]), zero at 0P = 0. `q` over the movable
/// joints.
pub fn potential_energy(robot: &Robot, q: &[f64]) -> Result<f64> {
    let [q] = tree_arrays(robot, ["q"], [q])?;
    let m = robot.numeric();
    let zeros = vec![0.0; q.len()];
    let b = &m.env.base;
    finite(
        energies(m, &q, &zeros, &b.w0, &b.v0).potential,
        "the potential energy",
    )
}

/// Total mechanical energy (J): kinetic + potential.
pub fn total_energy(robot: &Robot, q: &[f64], qd: &[f64]) -> Result<f64> {
    let rotors = drive_energy(robot, qd);
    let [q, qd] = tree_arrays(robot, ["q", "qd"], [q, qd])?;
    let m = robot.numeric();
    let b = &m.env.base;
    let e = energies(m, &q, &qd, &b.w0, &b.v0);
    finite(e.kinetic + e.potential + rotors, "the total energy")
}

/// Power (W) the links deliver to the environment through their external wrenches,
/// `sum_j V_j'fe_j + w_j'me_j`.
pub fn wrench_power(robot: &Robot, q: &[f64], qd: &[f64]) -> Result<f64> {
    let [q, qd] = tree_arrays(robot, ["q", "qd"], [q, qd])?;
    let m = robot.numeric();
    let b = &m.env.base;
    finite(
        energies(m, &q, &qd, &b.w0, &b.v0).wrench_power,
        "the external-wrench power",
    )
}

/// dE/dt (W) = dE/dq qd + dE/dqd qdd of the total energy E = T + U for a fixed base
/// (w0 = v0 = 0), by forward automatic differentiation (exact to rounding).
pub fn total_energy_rate(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<f64> {
    let rotors = match robot.motor_drives() {
        Some(d) if qd.len() == robot.dof() && qdd.len() == robot.dof() => {
            d.kinetic_energy_rate(qd, qdd)
        }
        _ => 0.0,
    };
    let [q, qd, qdd] = tree_arrays(robot, ["q", "qd", "qdd"], [q, qd, qdd])?;
    let m: DynModel<HyperDual64> = convert_model(robot.numeric());
    let qh: Vec<_> = (0..q.len())
        .map(|i| HyperDual64::new(q[i], qd[i], 0.0, 0.0))
        .collect();
    let qdh: Vec<_> = (0..q.len())
        .map(|i| HyperDual64::new(qd[i], qdd[i], 0.0, 0.0))
        .collect();
    let z = Vector3::zeros();
    let e = energies(&m, &qh, &qdh, &z, &z);
    finite((e.kinetic + e.potential).eps1 + rotors, "dE/dt")
}

/// Joint torques of the movable joints by the Euler–Lagrange equations (§10.2.1):
///
/// `Gamma_k = d/dt(dT/dqd_k) - dT/dq_k + dU/dq_k + Fs_k sign(qd_k) + Fv_k qd_k + dP/dqd_k`,
///
/// where T includes the rotors (so `Ia qdd` comes out of d/dt(dT/dqd); with a motor–joint
/// transmission the motors' `1/2 (R qd)' Ia (R qd)` and their friction through R'), P is the power
/// delivered to the environment by the external wrenches, and the base may move: T depends on
/// time through w0 and v0 (components in R_0), whose rates are wp0 and vp0 - w0 x v0.
/// d/dt(dT/dqd_k) is the mixed second derivative of T along e_{qd_k} and the direction
/// (qd, qdd, wp0, vp0 - w0 x v0), computed exactly with hyper-dual numbers.
/// O(NL^2); a reference, not a fast path (use
/// [`crate::algorithms::inverse_dynamics::inverse_dynamics_into`]).
pub fn lagrangian_torques(
    robot: &Robot,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Result<DVector<f64>> {
    let [q, qd, qdd] = tree_arrays(robot, ["q", "qd", "qdd"], [q, qd, qdd])?;
    let num = robot.numeric();
    let m: DynModel<HyperDual64> = convert_model(num);
    let n = robot.nl();
    let h = HyperDual64::new;
    // d/dt of the components of w0 and v0 in the moving frame R_0.
    let base = &num.env.base;
    let w0_rate = base.wp0;
    let v0_rate = base.vp0 - base.w0.cross(&base.v0);
    let mut tau = DVector::zeros(n);
    let mut qh: Vec<HyperDual64> = Vec::with_capacity(n);
    let mut qdh: Vec<HyperDual64> = Vec::with_capacity(n);
    for k in 0..n {
        let fr = num.frame(k + 1);
        if !fr.joint.is_movable() {
            continue;
        }
        let delta = |i: usize| if i == k { 1.0 } else { 0.0 };
        // e1 along qd_k, e2 along the time direction: eps1 = dT/dqd_k, eps1eps2 = d/dt(dT/dqd_k).
        qh.clear();
        qh.extend((0..n).map(|i| h(q[i], 0.0, qd[i], 0.0)));
        qdh.clear();
        qdh.extend((0..n).map(|i| h(qd[i], delta(i), qdd[i], 0.0)));
        let w0 = Vector3::from_fn(|r, _| h(base.w0[r], 0.0, w0_rate[r], 0.0));
        let v0 = Vector3::from_fn(|r, _| h(base.v0[r], 0.0, v0_rate[r], 0.0));
        let e = energies(&m, &qh, &qdh, &w0, &v0);
        let ddt_dt_dqd = e.kinetic.eps1eps2;
        let dp_dqd = e.wrench_power.eps1;
        // e1 along q_k: eps1 = dT/dq_k and dU/dq_k.
        qh.clear();
        qh.extend((0..n).map(|i| h(q[i], delta(i), 0.0, 0.0)));
        qdh.clear();
        qdh.extend((0..n).map(|i| h(qd[i], 0.0, 0.0, 0.0)));
        let w0 = map3::<HyperDual64>(&base.w0);
        let v0 = map3::<HyperDual64>(&base.v0);
        let e = energies(&m, &qh, &qdh, &w0, &v0);
        let (dt_dq, du_dq) = (e.kinetic.eps1, e.potential.eps1);
        let l = num.link(k + 1);
        tau[k] =
            ddt_dt_dqd - dt_dq + du_dq + l.fs * DynScalar::sign(&qd[k]) + l.fv * qd[k] + dp_dqd;
    }
    if let Some(k) = tau.iter().position(|x| !x.is_finite()) {
        return Err(Error::Numerical(format!(
            "Lagrangian torque of joint {} is not finite",
            k + 1
        )));
    }
    let c = robot.coordinates();
    let mut out = DVector::from_iterator(c.len(), c.frames().iter().map(|&j| tau[j - 1]));
    if let Some(d) = robot.motor_drives() {
        // T of the motors, 1/2 (R qd)' Ia (R qd): d/dt(dT/dqd) = R' Ia R qdd, dT/dq = 0
        let (qd, qdd) = (&moved(robot, &qd), &moved(robot, &qdd));
        d.add_torques(qd, Some(qdd), out.as_mut_slice());
    }
    Ok(out)
}

/// A tree array's entries of the movable joints (the joint vector).
fn moved(robot: &Robot, x: &[f64]) -> Vec<f64> {
    robot
        .coordinates()
        .frames()
        .iter()
        .map(|&j| x[j - 1])
        .collect()
}
