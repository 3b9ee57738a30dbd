//! Derivatives of the closed-chain models (docs/models/derivatives.md, C1–C11) against central
//! finite differences ALONG THE BRANCH: the closed models re-evaluated at q_a ± h e_k, the
//! loops re-closed there by the branch tracker (an independent route: only the closed models'
//! values, no derivative formula), on SR400, the five-bar, the spatial loop, the four-bar and
//! the two-loop linkage at random states (fixed seeds).
//!
//! Tolerances. With h = 1e-4 the central difference's truncation error is h²/6 |f'''| ~ 2e-9
//! |f'''| and the closure tolerance (1e-12 on q_p, usually reached to rounding) adds at most
//! ~1e-12 / h = 1e-8 relative; the bound 2e-6 relative to max(|dΓ/dq|, 1) leaves two decades
//! above both. Along qd_a, Γ_cl is quadratic: the central difference is exact to rounding.
//! Each test also checks that the closure terms (dG/dq_a, db/dq_a) are far above the
//! tolerance at its states: the tree-only derivative G^T dΓ_tr/dq G misses the bound by more
//! than a hundred times, so a dropped closure term cannot pass.

mod common;

use common::robot;
use nalgebra::DMatrix;
use rand::Rng;
use robodyn::{
    closed_direct_dynamics, closed_direct_dynamics_derivatives,
    closed_direct_dynamics_derivatives_into, closed_inverse_dynamics,
    closed_inverse_dynamics_derivatives, closed_inverse_dynamics_derivatives_into,
    inverse_dynamics_derivatives, Branch, ClosedChain, ClosedDdmDerivatives, ClosedDerivativesData,
    ClosedIdmDerivatives, Error,
};

/// A closed model evaluated on a tracker: its N values at a state.
type Model<'a> = dyn Fn(&mut Branch, &[Vec<f64>; 3]) -> Vec<f64> + 'a;

const H: f64 = 1e-4;
const TOL: f64 = 2e-6;

/// Random states near the assembly on its branch (no warning of the conditioning there).
fn states(chain: &ClosedChain, seed: u64, count: usize) -> Vec<[Vec<f64>; 3]> {
    let mut rng = robodyn_testing::rng(seed);
    let b0 = chain.assembly_branch().unwrap();
    let n = chain.dof();
    let mut out = Vec::new();
    while out.len() < count {
        let u = |rng: &mut dyn rand::RngCore, s: f64| -> Vec<f64> {
            (0..n).map(|_| rng.random_range(-s..s)).collect()
        };
        let q: Vec<f64> = b0
            .q_a()
            .iter()
            .zip(u(&mut rng, 0.3))
            .map(|(a, b)| a + b)
            .collect();
        let (qd, qdd) = (u(&mut rng, 1.5), u(&mut rng, 3.0));
        let mut b = b0.clone();
        match robodyn::loop_closure(chain, &mut b, &q) {
            Ok(s) if !s.conditioning.warning => out.push([q, qd, qdd]),
            _ => {}
        }
    }
    out
}

/// Central differences of `f(branch, x)` (N values) along argument `which` of the state, each
/// evaluation from a copy of `branch` at the state (the tracker re-closes the loops at q ± h).
fn central(branch: &Branch, x: &[Vec<f64>; 3], which: usize, f: &Model<'_>) -> DMatrix<f64> {
    let n = x[0].len();
    let mut m = DMatrix::zeros(n, n);
    for k in 0..n {
        let at = |s: f64| {
            let mut y = x.clone();
            y[which][k] += s;
            f(&mut branch.clone(), &y)
        };
        let (p, q) = (at(H), at(-H));
        for j in 0..n {
            m[(j, k)] = (p[j] - q[j]) / (2.0 * H);
        }
    }
    m
}

fn rel(m: &DMatrix<f64>, e: &DMatrix<f64>) -> f64 {
    (m - e).amax() / e.amax().max(1.0)
}

/// The tree-only part of dΓ_cl/dq_a, G^T dΓ_tr/dq G (G held constant, b ignored): what a
/// derivative without the closure terms would give.
fn tree_only(chain: &ClosedChain, branch: &mut Branch, x: &[Vec<f64>; 3]) -> DMatrix<f64> {
    let s = closed_inverse_dynamics(chain, branch, &x[0], &x[1], &x[2])
        .unwrap()
        .state;
    let t = inverse_dynamics_derivatives(
        chain.robot(),
        s.q.as_slice(),
        s.qd.as_slice(),
        s.qdd.as_slice(),
    )
    .unwrap();
    s.g.transpose() * t.dtau_dq * &s.g
}

/// Worst relative gaps of the inverse derivatives to the central differences (q, qd), of A to
/// A_cl, and the smallest gap of the tree-only derivative.
/// `linear`: the closure is linear in q_a (W constant, b = 0: the SR400's parallelogram), so
/// the tree-only derivative is the whole of it and must agree; otherwise it must not.
fn check_inverse(name: &str, seed: u64, linear: bool) -> [f64; 4] {
    let chain = ClosedChain::new(&robot(name)).unwrap();
    let mut worst = [0.0_f64, 0.0, 0.0, f64::INFINITY];
    let idm = |b: &mut Branch, y: &[Vec<f64>; 3]| -> Vec<f64> {
        let r = closed_inverse_dynamics(&chain, b, &y[0], &y[1], &y[2]).unwrap();
        r.gamma_cl.as_slice().to_vec()
    };
    for x in states(&chain, seed, 4) {
        let mut b = chain.assembly_branch().unwrap();
        let d = closed_inverse_dynamics_derivatives(&chain, &mut b, &x[0], &x[1], &x[2]).unwrap();
        let fq = central(&b, &x, 0, &idm);
        let fv = central(&b, &x, 1, &idm);
        let a = closed_direct_dynamics(&chain, &mut b, &x[0], &x[1], &x[2])
            .unwrap()
            .a_cl;
        let tau = idm(&mut b.clone(), &x);
        let gaps = [rel(&d.dtau_dq, &fq), rel(&d.dtau_dqd, &fv), rel(&d.a, &a)];
        for (w, g) in worst.iter_mut().zip(gaps) {
            *w = w.max(g);
        }
        assert!(
            (d.tau.as_slice().iter().zip(&tau))
                .all(|(a, b)| (a - b).abs() < 1e-12 * b.abs().max(1.0)),
            "{name}: Γ_cl {} vs {tau:?}",
            d.tau
        );
        worst[3] = worst[3].min(rel(&tree_only(&chain, &mut b, &x), &fq));
    }
    assert!(worst[0] < TOL, "{name}: dΓ_cl/dq_a vs FD {:e}", worst[0]);
    assert!(worst[1] < TOL, "{name}: dΓ_cl/dqd_a vs FD {:e}", worst[1]);
    assert!(worst[2] < 1e-12, "{name}: A vs A_cl {:e}", worst[2]);
    if linear {
        assert!(
            worst[3] < TOL,
            "{name}: a linear closure's tree-only derivative {:e}",
            worst[3]
        );
    } else {
        assert!(
            worst[3] > 100.0 * TOL,
            "{name}: the closure terms are too small at these states to be tested ({:e})",
            worst[3]
        );
    }
    eprintln!(
        "{name}: inverse vs FD: dq {:.1e}, dqd {:.1e}, A {:.1e}; tree-only dq off by {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    worst
}

#[test]
fn inverse_derivatives_match_finite_differences_along_the_branch() {
    for (name, seed, linear) in [
        ("sr400.toml", 1, true),
        ("fivebar.toml", 2, false),
        ("spatial_loop.toml", 3, false),
        ("fourbar.toml", 4, false),
        ("twoloops.toml", 5, false),
    ] {
        check_inverse(name, seed, linear);
    }
}

/// The direct derivatives: against central differences of the closed direct model along the
/// branch, dqdd/dΓ A_cl = I, and -A_cl^-1 of the inverse derivatives at qdd_a = ddm(Γ).
fn check_direct(name: &str, seed: u64) -> [f64; 4] {
    let chain = ClosedChain::new(&robot(name)).unwrap();
    let n = chain.dof();
    let mut worst = [0.0_f64; 4];
    let ddm = |b: &mut Branch, y: &[Vec<f64>; 3]| -> Vec<f64> {
        let r = closed_direct_dynamics(&chain, b, &y[0], &y[1], &y[2]).unwrap();
        r.qdd_a.as_slice().to_vec()
    };
    for s in states(&chain, seed, 3) {
        let mut b = chain.assembly_branch().unwrap();
        // torques of the random accelerations: a state whose qdd_a is s[2]
        let tau = closed_inverse_dynamics(&chain, &mut b, &s[0], &s[1], &s[2])
            .unwrap()
            .gamma_cl;
        let x = [s[0].clone(), s[1].clone(), tau.as_slice().to_vec()];
        let d = closed_direct_dynamics_derivatives(&chain, &mut b, &x[0], &x[1], &x[2]).unwrap();
        let qdd_scale = d.qdd.amax().max(1.0);
        assert!((&d.qdd - nalgebra::DVector::from_column_slice(&s[2])).amax() < 1e-8 * qdd_scale);
        let inv =
            closed_inverse_dynamics_derivatives(&chain, &mut b, &x[0], &x[1], d.qdd.as_slice())
                .unwrap();
        let eye = DMatrix::identity(n, n);
        let gaps = [
            rel(&d.dqdd_dq, &central(&b, &x, 0, &ddm)),
            rel(&d.dqdd_dqd, &central(&b, &x, 1, &ddm)),
            (&d.ainv * &inv.a - &eye).amax(),
            rel(&d.dqdd_dq, &(-&d.ainv * &inv.dtau_dq))
                .max(rel(&d.dqdd_dqd, &(-&d.ainv * &inv.dtau_dqd))),
        ];
        for (w, g) in worst.iter_mut().zip(gaps) {
            *w = w.max(g);
        }
    }
    assert!(worst[0] < TOL, "{name}: dqdd/dq_a vs FD {:e}", worst[0]);
    assert!(worst[1] < TOL, "{name}: dqdd/dqd_a vs FD {:e}", worst[1]);
    assert!(
        worst[2] < 1e-10,
        "{name}: dqdd/dGamma A_cl - I {:e}",
        worst[2]
    );
    assert!(
        worst[3] < 1e-12,
        "{name}: direct vs -A_cl^-1 inverse {:e}",
        worst[3]
    );
    eprintln!(
        "{name}: direct vs FD: dq {:.1e}, dqd {:.1e}; Ainv A_cl - I {:.1e}; vs inverse {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    worst
}

#[test]
fn direct_derivatives_match_finite_differences_and_the_inverse_ones() {
    for (name, seed) in [
        ("sr400.toml", 11),
        ("fivebar.toml", 12),
        ("spatial_loop.toml", 13),
        ("fourbar.toml", 14),
        ("twoloops.toml", 15),
    ] {
        check_direct(name, seed);
    }
}

#[test]
fn the_into_forms_reuse_their_buffers_along_a_path() {
    // one data and one branch along a path: the same numbers as fresh calls at each state
    let chain = ClosedChain::new(&robot("spatial_loop.toml")).unwrap();
    let env = chain.robot().environment();
    let mut data = ClosedDerivativesData::new(&chain);
    let (mut di, mut dd) = (
        ClosedIdmDerivatives::new(&chain),
        ClosedDdmDerivatives::new(&chain),
    );
    let mut b = chain.assembly_branch().unwrap();
    for x in states(&chain, 21, 4) {
        closed_inverse_dynamics_derivatives_into(
            &chain, &mut data, &mut b, env, &x[0], &x[1], &x[2], &mut di,
        )
        .unwrap();
        let fresh = closed_inverse_dynamics_derivatives(
            &chain,
            &mut chain.assembly_branch().unwrap(),
            &x[0],
            &x[1],
            &x[2],
        )
        .unwrap();
        assert!(rel(&di.dtau_dq, &fresh.dtau_dq) < 1e-9);
        closed_direct_dynamics_derivatives_into(
            &chain, &mut data, &mut b, env, &x[0], &x[1], &x[2], &mut dd,
        )
        .unwrap();
        let fresh = closed_direct_dynamics_derivatives(
            &chain,
            &mut chain.assembly_branch().unwrap(),
            &x[0],
            &x[1],
            &x[2],
        )
        .unwrap();
        assert!(rel(&dd.dqdd_dq, &fresh.dqdd_dq) < 1e-9);
    }
}

#[test]
fn bad_inputs_are_errors() {
    let chain = ClosedChain::new(&robot("fivebar.toml")).unwrap();
    let other = ClosedChain::new(&robot("sr400.toml")).unwrap();
    let env = chain.robot().environment();
    let mut b = chain.assembly_branch().unwrap();
    let q = b.q_a().to_vec();
    let z = vec![0.0; chain.dof()];
    // an output of the wrong size
    let mut data = ClosedDerivativesData::new(&chain);
    let mut d = ClosedIdmDerivatives::new(&other);
    let e = closed_inverse_dynamics_derivatives_into(
        &chain, &mut data, &mut b, env, &q, &z, &z, &mut d,
    );
    assert!(matches!(e, Err(Error::Dimension { .. })), "{e:?}");
    // a data of another chain
    let mut wrong = ClosedDerivativesData::new(&other);
    let mut d = ClosedIdmDerivatives::new(&chain);
    let e = closed_inverse_dynamics_derivatives_into(
        &chain, &mut wrong, &mut b, env, &q, &z, &z, &mut d,
    );
    assert!(matches!(e, Err(Error::Dimension { .. })), "{e:?}");
    // a wrong state length, a NaN
    let e = closed_inverse_dynamics_derivatives(&chain, &mut b, &q[..1], &z, &z);
    assert!(matches!(e, Err(Error::Dimension { .. })), "{e:?}");
    let e = closed_direct_dynamics_derivatives(&chain, &mut b, &q, &[f64::NAN, 0.0], &z);
    assert!(matches!(e, Err(Error::NotFinite { .. })), "{e:?}");
    // a move the tracker cannot make within a one-step budget: an error, the branch kept
    let short = chain.clone().with_step_budget(1);
    let far: Vec<f64> = q.iter().map(|x| x + 1.0).collect();
    let before = b.clone();
    let e = closed_inverse_dynamics_derivatives(&short, &mut b, &far, &z, &z);
    assert!(e.is_err(), "{e:?}");
    assert_eq!(b, before);
}
