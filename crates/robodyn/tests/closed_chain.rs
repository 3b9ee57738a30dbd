//! Closed-chain dynamic models (§10.3.2–10.3.3): Example 10.1's torque relations, virtual power,
//! the Lagrange-multiplier form against the G^T projection, kinetic energy against A_cl, the
//! power balance against Γ_cl (independent of Newton–Euler), and idm(ddm(tau)) = tau.

mod common;

use common::{cases, robot, ROBOTS};
use nalgebra::{DMatrix, DVector};
use rand::Rng;
use robodyn::algorithms::closed_chain::ClosedState;
use robodyn::algorithms::energy::{kinetic_energy, potential_energy};
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::{
    closed_direct_dynamics, closed_direct_dynamics_into, closed_inertia_matrix_into,
    closed_inverse_dynamics, closed_state, loop_closure, Branch, ClosedChain, ClosedData, Error,
    Robot,
};
use std::f64::consts::{FRAC_PI_2, PI};

fn uniform(rng: &mut impl Rng, n: usize, s: f64) -> Vec<f64> {
    (0..n).map(|_| rng.random_range(-s..s)).collect()
}

/// Random reachable q_a near the reference, its q_p, and random qd_a, qdd_a.
fn random_state(
    cc: &ClosedChain,
    rng: &mut impl Rng,
    qa0: &[f64],
    qp0: &[f64],
    range: f64,
) -> [Vec<f64>; 4] {
    let n = qa0.len();
    let qa: Vec<f64> = qa0
        .iter()
        .zip(uniform(rng, n, range))
        .map(|(a, b)| a + b)
        .collect();
    let mut branch = cc.branch_from(qa0, qp0).unwrap();
    let qp = loop_closure(cc, &mut branch, &qa).unwrap().q_p;
    [
        qa,
        qp.iter().copied().collect(),
        uniform(rng, n, 1.5),
        uniform(rng, n, 3.0),
    ]
}

/// A branch tracker at a closed configuration.
fn at(cc: &ClosedChain, qa: &[f64], qp: &[f64]) -> Branch {
    cc.branch_from(qa, qp).unwrap()
}

fn rel(a: f64, b: f64, scale: f64) -> f64 {
    (a - b).abs() / scale.max(1.0)
}

#[test]
fn sr400_example_10_1_torque_relations() {
    let r = robot("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let mut rng = robodyn_testing::rng(10);
    let (qa0, qp0, range) = (ROBOTS[0].1, ROBOTS[0].2, ROBOTS[0].3);
    let mut worst: f64 = 0.0;
    for _ in 0..30 {
        let [qa, qp, qd, qdd] = random_state(&cc, &mut rng, qa0, qp0, range);
        let idm = closed_inverse_dynamics(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &qdd).unwrap();
        let t = |j: usize| idm.gamma_tr[j - 1];
        let scale = idm.gamma_tr.amax();
        // q_a = [θ1 θ2 θ4 θ5 θ6 θ7]
        let expected = [
            t(1),
            t(2) - t(3) + t(8),
            t(4),
            t(5),
            t(6),
            t(7) + t(3) - t(8),
        ];
        for (k, e) in expected.iter().enumerate() {
            let err = rel(idm.gamma_cl[k], *e, scale);
            worst = worst.max(err);
            assert!(err < 1e-10, "Gamma_cl[{k}] = {} vs {e}", idm.gamma_cl[k]);
        }
        // and qd_p = W qd_a is the book's: qd3 = qd7 - qd2, qd8 = qd2 - qd7
        let s = &idm.state;
        assert!((s.qd[2] - (qd[5] - qd[1])).abs() < 1e-10);
        assert!((s.qd[7] - (qd[1] - qd[5])).abs() < 1e-10);
        assert!((s.qdd[2] - (qdd[5] - qdd[1])).abs() < 1e-9);
    }
    println!("SR400 Example 10.1 torque relations: max relative error {worst:.2e}");
}

#[test]
fn virtual_power_and_lagrange_form() {
    let mut rng = robodyn_testing::rng(11);
    for (name, r, qa0, qp0, range) in cases() {
        let cc = ClosedChain::new(&r).unwrap();
        let (mut w_vp, mut w_l): (f64, f64) = (0.0, 0.0);
        for _ in 0..20 {
            let [qa, qp, qd, qdd] = random_state(&cc, &mut rng, qa0, qp0, range);
            let idm = closed_inverse_dynamics(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &qdd).unwrap();
            // Γ_cl' qd_a = Γ_tr' qd_tr
            let p_cl = idm.gamma_cl.dot(&DVector::from_column_slice(&qd));
            let p_tr = idm.gamma_tr.dot(&idm.state.qd);
            let scale = idm.gamma_tr.amax() * idm.state.qd.amax();
            let e = rel(p_cl, p_tr, scale);
            w_vp = w_vp.max(e);
            assert!(e < 1e-10, "{name}: power {p_cl} vs {p_tr}");
            // (10.36) with (10.37) against (10.40)
            for k in 0..qa.len() {
                let e = rel(
                    idm.gamma_cl[k],
                    idm.gamma_cl_lagrange[k],
                    idm.gamma_tr.amax(),
                );
                w_l = w_l.max(e);
                assert!(e < 1e-10, "{name}");
            }
            // passive rows of (10.36): Γ_p + Wp^T λ = 0
            let wl = idm.state.wp.transpose() * &idm.lambda;
            for (k, &j) in cc.passive_coordinates().frames().iter().enumerate() {
                assert!(rel(idm.gamma_tr[j - 1], -wl[k], idm.gamma_tr.amax()) < 1e-10);
            }
        }
        println!("{name}: virtual power {w_vp:.2e}, Lagrange vs G^T {w_l:.2e}");
    }
}

/// Kinetic and potential energy of the tree at a consistent state, by the Lagrangian route's
/// energies (link velocities 10.1–10.2), not from Newton–Euler.
fn energy(r: &Robot, s: &ClosedState) -> (f64, f64) {
    (
        kinetic_energy(r, s.q.as_slice(), s.qd.as_slice()).unwrap(),
        potential_energy(r, s.q.as_slice()).unwrap(),
    )
}

#[test]
fn kinetic_energy_matches_a_cl() {
    let mut rng = robodyn_testing::rng(12);
    for (name, r, qa0, qp0, range) in cases() {
        let cc = ClosedChain::new(&r).unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..10 {
            let [qa, qp, qd, _] = random_state(&cc, &mut rng, qa0, qp0, range);
            let tau = vec![0.0; qa.len()];
            let ddm = closed_direct_dynamics(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &tau).unwrap();
            let qdv = DVector::from_column_slice(&qd);
            let ke_a = 0.5 * qdv.dot(&(&ddm.a_cl * &qdv));
            let (ke, _) = energy(&r, &ddm.state);
            // the inertia matrix alone (10.46), on its own tracker: the direct model's A_cl
            let mut a_cl = DMatrix::zeros(qa.len(), qa.len());
            let mut data = ClosedData::new(&cc);
            closed_inertia_matrix_into(&cc, &mut data, &mut at(&cc, &qa, &qp), &qa, &mut a_cl)
                .unwrap();
            assert_eq!(a_cl, ddm.a_cl, "{name}: closed_inertia_matrix_into");
            let e = (ke - ke_a).abs() / ke.abs().max(1e-3);
            worst = worst.max(e);
            assert!(
                e < 1e-10,
                "{name}: kinetic energy {ke} vs qd' A_cl qd / 2 = {ke_a}"
            );
        }
        println!("{name}: kinetic energy vs A_cl, max relative error {worst:.2e}");
    }
}

#[test]
fn power_balance_matches_gamma_cl_along_smooth_paths() {
    // dE/dt = Γ_cl' qd_a without friction and external wrenches: checks G, Ψ and the projection
    // against energies computed from link velocities (no Newton–Euler involved).
    let mut rng = robodyn_testing::rng(13);
    for (name, r, qa0, qp0, range) in cases() {
        let mut d = r.into_description();
        for l in d.links.iter_mut() {
            l.params[11] = robodyn::Expr::zero();
            l.params[12] = robodyn::Expr::zero();
        }
        let r = Robot::new(d).unwrap();
        let cc = ClosedChain::new(&r).unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..4 {
            let [c0, qp, _, _] = random_state(&cc, &mut rng, qa0, qp0, range * 0.5);
            let n = c0.len();
            let amp = uniform(&mut rng, n, 0.3);
            let om: Vec<f64> = (0..n).map(|_| rng.random_range(0.5..3.0)).collect();
            let ph = uniform(&mut rng, n, 3.0);
            let path = |t: f64| -> [Vec<f64>; 3] {
                let q = (0..n)
                    .map(|i| c0[i] + amp[i] * ((om[i] * t + ph[i]).sin() - ph[i].sin()))
                    .collect();
                let qd = (0..n)
                    .map(|i| amp[i] * om[i] * (om[i] * t + ph[i]).cos())
                    .collect();
                let qdd = (0..n)
                    .map(|i| -amp[i] * om[i] * om[i] * (om[i] * t + ph[i]).sin())
                    .collect();
                [q, qd, qdd]
            };
            let mut e_at = |t: f64| {
                let [q, qd, qdd] = path(t);
                let s = closed_state(&cc, &mut at(&cc, &q, &qp), &q, &qd, &qdd).unwrap();
                let (ke, pe) = energy(&r, &s);
                ke + pe
            };
            let d = |h: f64, e_at: &mut dyn FnMut(f64) -> f64| (e_at(h) - e_at(-h)) / (2.0 * h);
            let de = (4.0 * d(5e-4, &mut e_at) - d(1e-3, &mut e_at)) / 3.0;
            let [q, qd, qdd] = path(0.0);
            let idm = closed_inverse_dynamics(&cc, &mut at(&cc, &q, &qp), &q, &qd, &qdd).unwrap();
            let power = idm.gamma_cl.dot(&DVector::from_column_slice(&qd));
            let e = (de - power).abs() / power.abs().max(1.0);
            worst = worst.max(e);
            assert!(e < 1e-6, "{name}: dE/dt = {de} vs Γ_cl' qd_a = {power}");
        }
        println!("{name}: power balance, max relative error {worst:.2e}");
    }
}

#[test]
fn idm_of_ddm_is_identity() {
    let mut rng = robodyn_testing::rng(14);
    for (name, r, qa0, qp0, range) in cases() {
        let cc = ClosedChain::new(&r).unwrap();
        let mut worst: f64 = 0.0;
        for _ in 0..20 {
            let [qa, qp, qd, _] = random_state(&cc, &mut rng, qa0, qp0, range);
            let tau = uniform(&mut rng, qa.len(), 20.0);
            let ddm = closed_direct_dynamics(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &tau).unwrap();
            let qdd: Vec<f64> = ddm.qdd_a.iter().copied().collect();
            let idm = closed_inverse_dynamics(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &qdd).unwrap();
            let scale = tau.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            for (k, t) in tau.iter().enumerate() {
                let e = (idm.gamma_cl[k] - t).abs() / scale;
                worst = worst.max(e);
                assert!(e < 1e-9, "{name}: tau {} vs {t}", idm.gamma_cl[k]);
            }
            // the passive accelerations of the ddm are the consistent ones (10.42)
            for (k, &j) in cc.passive_coordinates().frames().iter().enumerate() {
                assert!((ddm.qdd_p[k] - idm.state.qdd[j - 1]).abs() < 1e-8 * scale.max(1.0));
            }
        }
        println!("{name}: idm(ddm(tau)) vs tau, max relative error {worst:.2e}");
    }
}

#[test]
fn tracker_follows_a_walk_in_small_steps() {
    let r = robot("fivebar.toml");
    let cc = ClosedChain::new(&r).unwrap();
    assert_eq!(cc.dof(), 2);
    let mut b = cc.branch_from(&[0.0, 0.0], &[0.0, 0.0]).unwrap();
    let mut qa = [0.0, 0.0];
    // walk in small steps: each evaluation continues from the tracker's previous point
    for _ in 0..20 {
        qa[0] += 0.01;
        qa[1] -= 0.01;
        let a = closed_direct_dynamics(&cc, &mut b, &qa, &[0.1, -0.2], &[0.0, 0.0]).unwrap();
        assert!(a.qdd_a.iter().all(|x| x.is_finite()));
        assert_eq!(b.q_a(), &qa[..]);
        assert!(loop_closure(&cc, &mut b, &qa).unwrap().residual < 1e-11);
    }
}

#[test]
fn bad_inputs_are_errors() {
    let r = robot("fourbar.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let e = closed_inverse_dynamics(&cc, &mut b, &[0.0, 1.0], &[0.0], &[0.0]).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Dimension {
                expected: 1,
                got: 2,
                ..
            }
        ) && e.to_string().contains("actuated"),
        "{e}"
    );
    let e = closed_direct_dynamics(&cc, &mut b, &[0.0], &[f64::NAN], &[0.0]).unwrap_err();
    assert!(
        matches!(e, Error::NotFinite { .. }) && e.to_string().contains("finite"),
        "{e}"
    );
    // a tree is not a closed chain
    let tree = robodyn_testing::random_tree(
        &mut robodyn_testing::rng(1),
        3,
        &robodyn_testing::TreeOptions::default(),
    );
    assert!(ClosedChain::new(&tree).is_err());
}

/// A closed chain evaluated on a tracker (what a simulator holds).
struct Sys {
    cc: ClosedChain,
    data: ClosedData,
    branch: Branch,
}

/// One RK4 step of (q_a, qd_a) under zero torques.
fn rk4(sys: &mut Sys, q: &[f64], v: &[f64], dt: f64) -> (Vec<f64>, Vec<f64>) {
    let n = q.len();
    let zero = vec![0.0; n];
    let add = |a: &[f64], b: &[f64], h: f64| -> Vec<f64> {
        a.iter().zip(b).map(|(x, y)| x + h * y).collect()
    };
    let acc = |sys: &mut Sys, q: &[f64], v: &[f64]| -> Vec<f64> {
        let mut a = vec![0.0; q.len()];
        let env = sys.cc.robot().environment().clone();
        closed_direct_dynamics_into(
            &sys.cc,
            &mut sys.data,
            &mut sys.branch,
            &env,
            q,
            v,
            &zero,
            &mut a,
        )
        .unwrap();
        a
    };
    let (k1q, k1v) = (v.to_vec(), acc(sys, q, v));
    let (q2, v2) = (add(q, &k1q, dt / 2.0), add(v, &k1v, dt / 2.0));
    let (k2q, k2v) = (v2.clone(), acc(sys, &q2, &v2));
    let (q3, v3) = (add(q, &k2q, dt / 2.0), add(v, &k2v, dt / 2.0));
    let (k3q, k3v) = (v3.clone(), acc(sys, &q3, &v3));
    let (q4, v4) = (add(q, &k3q, dt), add(v, &k3v, dt));
    let (k4q, k4v) = (v4.clone(), acc(sys, &q4, &v4));
    let comb = |x: &[f64], a: &[f64], b: &[f64], c: &[f64], d: &[f64]| -> Vec<f64> {
        (0..n)
            .map(|i| x[i] + dt / 6.0 * (a[i] + 2.0 * b[i] + 2.0 * c[i] + d[i]))
            .collect()
    };
    (
        comb(q, &k1q, &k2q, &k3q, &k4q),
        comb(v, &k1v, &k2v, &k3v, &k4v),
    )
}

#[test]
fn conservative_simulation_keeps_energy_and_closure() {
    // 10 s without friction and torques (RK4, dt = 2 ms), loops re-solved at every call from the
    // previous solution: the energy from link velocities must stay constant. The five-bar is
    // mounted upside down (gravity +y0) so that it swings about a regular equilibrium instead of
    // falling into its parallel singularity; the SR400 moves without gravity (a free drift that
    // keeps the parallelogram away from its flat configurations for 10 s).
    for (name, qa0, qp0, v0, g) in [
        (
            "fivebar.toml",
            vec![0.0, 0.0],
            vec![0.0, 0.0],
            vec![1.0, -0.5],
            [0.0, 9.81, 0.0],
        ),
        (
            "sr400.toml",
            vec![0.0, 0.0, 0.0, 0.0, 0.0, FRAC_PI_2],
            vec![PI, -FRAC_PI_2],
            vec![0.1, 0.05, -0.1, 0.2, 0.3, -0.05],
            [0.0, 0.0, 0.0],
        ),
    ] {
        let mut d = robot(name).into_description();
        d.gravity = g.map(robodyn::Expr::num);
        for l in d.links.iter_mut() {
            l.params[11] = robodyn::Expr::zero();
            l.params[12] = robodyn::Expr::zero();
        }
        let r = Robot::new(d).unwrap();
        let cc = ClosedChain::new(&r).unwrap();
        let mut sys = Sys {
            data: ClosedData::new(&cc),
            branch: cc.branch_from(&qa0, &qp0).unwrap(),
            cc,
        };
        let e_of = |sys: &mut Sys, q: &[f64], v: &[f64]| {
            let z = vec![0.0; q.len()];
            let s = closed_state(&sys.cc, &mut sys.branch, q, v, &z).unwrap();
            let (ke, pe) = energy(&r, &s);
            (ke + pe, ke)
        };
        let (mut q, mut v) = (qa0.clone(), v0.clone());
        let (e0, ke0) = e_of(&mut sys, &q, &v);
        let dt = 2e-3;
        let mut drift: f64 = 0.0;
        let mut residual: f64 = 0.0;
        for step in 1..=5000 {
            (q, v) = rk4(&mut sys, &q, &v, dt);
            if step % 100 == 0 {
                let (e, _) = e_of(&mut sys, &q, &v);
                drift = drift.max((e - e0).abs() / ke0.max(e0.abs()));
                residual =
                    residual.max(loop_closure(&sys.cc, &mut sys.branch, &q).unwrap().residual);
            }
        }
        println!(
            "{name}: 10 s conservative: energy drift {drift:.2e}, closure residual {residual:.1e}"
        );
        assert!(drift < 1e-6, "{name}: relative energy drift {drift}");
        assert!(residual < 1e-11, "{name}: closure residual {residual}");
    }
}

#[test]
fn a_cl_and_h_cl_match_newton_euler_columns() {
    // A_cl (10.46) uses the composite-link A_tr; here A_tr column i is rebuilt by Newton–Euler as
    // Γ_tr(q, 0, e_i) - Γ_tr(q, 0, 0) (gravity and wrenches cancel, friction is zero at qd = 0),
    // and H_cl (10.47) = G^T Γ_tr(q, qd_tr, qdd_tr(qdd_a = 0)).
    let mut rng = robodyn_testing::rng(23);
    for (name, r, qa0, qp0, range) in cases() {
        let cc = ClosedChain::new(&r).unwrap();
        let nl = r.nl();
        let model = r.numeric();
        let mut tree_ws = robodyn::Data::from_model(model);
        let mut worst: f64 = 0.0;
        for _ in 0..10 {
            let [qa, qp, qd, _] = random_state(&cc, &mut rng, qa0, qp0, range);
            let tau = uniform(&mut rng, qa.len(), 10.0);
            let d = closed_direct_dynamics(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &tau).unwrap();
            let q = d.state.q.as_slice();
            let zeros = vec![0.0; nl];
            let mut t0 = vec![0.0; nl];
            rnea(model, &mut tree_ws, q, &zeros, &zeros, &mut t0);
            let mut a_tr = DMatrix::zeros(nl, nl);
            for j in r.movable_joints() {
                let mut e = zeros.clone();
                e[j - 1] = 1.0;
                let mut t = vec![0.0; nl];
                rnea(model, &mut tree_ws, q, &zeros, &e, &mut t);
                for i in 0..nl {
                    a_tr[(i, j - 1)] = t[i] - t0[i];
                }
            }
            let g = &d.state.g;
            let a_ne = g.transpose() * &a_tr * g;
            let s0 =
                closed_state(&cc, &mut at(&cc, &qa, &qp), &qa, &qd, &vec![0.0; qa.len()]).unwrap();
            let mut h = vec![0.0; nl];
            rnea(
                model,
                &mut tree_ws,
                s0.q.as_slice(),
                s0.qd.as_slice(),
                s0.qdd.as_slice(),
                &mut h,
            );
            let h_ne = g.transpose() * DVector::from_column_slice(&h);
            let sa = a_ne.amax().max(1e-12);
            let sh = h_ne.amax().max(1.0);
            let ea = (&d.a_cl - &a_ne).amax() / sa;
            let eh = (&d.h_cl - &h_ne).amax() / sh;
            worst = worst.max(ea).max(eh);
            assert!(ea < 1e-12, "{name}: A_cl off by {ea}");
            assert!(eh < 1e-12, "{name}: H_cl off by {eh}");
        }
        println!("{name}: A_cl, H_cl vs Newton–Euler columns: max relative difference {worst:.1e}");
    }
}
