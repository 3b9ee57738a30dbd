//! Links kept parallel by a loop (§10.3.5): detection and the Newton–Euler recursion that takes
//! their orientation from the partner link (used by the customized closed-chain model).

mod common;

use robodyn::algorithms::base_parameters::closed::ClosedChainSampler;
use robodyn::algorithms::inverse_dynamics::{
    backward_recursion, backward_recursion_sharing, forward_recursion_sharing, rnea,
};
use robodyn::codegen::parallel_links;
use robodyn::Data;
use robodyn_testing::rng;

/// Example 10.1: theta3 = theta7 + pi/2 - theta2 and theta8 = theta2 - theta7, so link 3 keeps
/// the orientation of link 7 (up to a quarter turn; link 7, one joint from the base, is the
/// source) and link 8 that of link 2.
#[test]
fn sr400_parallelogram_links_are_found() {
    let robot = common::robot("sr400.toml");
    let shared = parallel_links(&robot).unwrap();
    let pairs: Vec<(usize, usize)> = shared
        .iter()
        .enumerate()
        .filter_map(|(k, s)| s.as_ref().map(|s| (k + 1, s.link)))
        .collect();
    assert_eq!(pairs, vec![(3, 7), (8, 2)]);
    for s in shared.iter().flatten() {
        // signed permutation: orthogonal with entries in {-1, 0, 1}
        assert!((s.rot.transpose() * s.rot - nalgebra::Matrix3::identity()).amax() < 1e-15);
        assert!(s.rot.iter().all(|x| [-1.0, 0.0, 1.0].contains(x)));
    }
}

/// Torques on 5 consistent closed states (sampled independently of the detection) of every
/// bundled closed robot: `f(name, state, plain rnea, sharing forward + plain backward, sharing
/// forward + moved moments)`. Returns the number of shared links found.
fn on_closed_states(
    seed: u64,
    mut f: impl FnMut(&str, &robodyn::algorithms::closed_chain::ClosedState, &[f64], &[f64], &[f64]),
) -> usize {
    let mut found = 0;
    for (name, robot, ..) in common::cases() {
        let shared = parallel_links(&robot).unwrap();
        found += shared.iter().flatten().count();
        let model = robot.numeric();
        let mut sampler = ClosedChainSampler::new(&robot).unwrap();
        let mut r = rng(seed);
        let mut ws = Data::from_model(model);
        let nl = robot.nl();
        for _ in 0..5 {
            let s = sampler.next_state(&mut r).unwrap();
            // the bundled closed robots have no fixed tree frame: tree arrays = joint vectors
            assert_eq!(robot.dof(), nl);
            let (q, qd, qdd) = (s.q.as_slice(), s.qd.as_slice(), s.qdd.as_slice());
            let mut plain = vec![0.0; nl];
            rnea(model, &mut ws, q, qd, qdd, &mut plain);
            let mut sharing = vec![0.0; nl];
            forward_recursion_sharing(model, &mut ws, q, qd, qdd, &shared);
            backward_recursion(model, &mut ws, qd, qdd, &mut sharing);
            let mut moved = vec![0.0; nl];
            forward_recursion_sharing(model, &mut ws, q, qd, qdd, &shared);
            backward_recursion_sharing(model, &mut ws, qd, qdd, &mut moved, &shared);
            f(name, &s, &plain, &sharing, &moved);
        }
    }
    found
}

/// On consistent closed states the recursion with shared orientations gives the torques of the
/// plain tree recursion, for every bundled closed robot; tree robots have no shared link.
#[test]
fn sharing_recursion_equals_tree_recursion_on_closed_states() {
    let found = on_closed_states(1056, |name, _, plain, tau, _| {
        let scale = plain.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (a, b) in tau.iter().zip(plain) {
            assert!(
                (a - b).abs() < 1e-11 * scale,
                "{name}: {tau:?} vs {plain:?}"
            );
        }
    });
    assert!(found >= 2, "the SR400's two parallel links at least");
    let tree = common::robot("rx90.toml");
    assert!(parallel_links(&tree).unwrap().iter().all(Option::is_none));
}

/// Moving the pure moments of the shared links onto their sources (`backward_recursion_sharing`)
/// changes the tree torques but not their projection: G^T Gamma_tr on consistent closed states of
/// every bundled closed robot equals G^T of the plain recursion's torques (G from the numeric
/// loop closure), while some individual torques of the SR400 do differ.
#[test]
fn moved_moments_keep_the_closed_chain_torques() {
    let mut changed = 0.0f64;
    on_closed_states(1057, |name, s, plain, _, tau| {
        let g = &s.g;
        let a = g.tr_mul(&nalgebra::DVector::from_column_slice(plain));
        let b = g.tr_mul(&nalgebra::DVector::from_column_slice(tau));
        let scale = a.amax().max(1.0);
        assert!(
            (&a - &b).amax() < 1e-11 * scale,
            "{name}: G^T tau {b} vs {a}"
        );
        let diff = plain
            .iter()
            .zip(tau)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
        changed = changed.max(diff / scale);
    });
    assert!(
        changed > 1e-3,
        "the moved moments change some tree torques ({changed:e})"
    );
}
