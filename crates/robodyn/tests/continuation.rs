//! The branch tracker on long moves (issue 24 item 1): every finite q_a is reached or refused in
//! a bounded number of continuation steps. Joints on no loop are set at once; whole turns of a
//! revolute loop joint are dropped when a full turn is periodic on the branch; otherwise the move
//! is refused with the structured [`Error::ContinuationBudget`], the tracker unmoved. Answers are
//! checked with the geometric model (the cut frame meets its twin) and against the same joints
//! less whole turns, computed here from the periodicity of sine and cosine (x - 2 pi k), not by
//! the tracker's reduction.

mod common;

use common::{closure_gap, robot, slider_crank};
use robodyn::algorithms::closed_chain::DEFAULT_STEP_BUDGET;
use robodyn::{
    closed_inverse_dynamics_into, loop_closure, loop_closure_into, ClosedChain, ClosedData, Error,
};
use std::f64::consts::PI;

/// `x` less the whole turns nearest to it (rounding ~1e-9 at |x| = 1e7).
fn less_turns(x: f64) -> f64 {
    x - 2.0 * PI * (x / (2.0 * PI)).round()
}

/// A crank that turns fully (the four-bar's, the slider-crank's): any angle is answered, closed,
/// and equal to the angle less whole turns (passive revolute joints modulo 2 pi, the slider
/// exactly), whether the move is followed step by step (within the budget) or shortened.
#[test]
fn whole_turns_of_a_crank_are_dropped_exactly() {
    for (label, r) in [
        ("four-bar", robot("fourbar.toml")),
        ("slider-crank", slider_crank()),
    ] {
        let cc = ClosedChain::new(&r).unwrap();
        let revolute: Vec<bool> = cc
            .passive_coordinates()
            .frames()
            .iter()
            .map(|&j| r.frame(j).joint == robodyn::model::JointType::Revolute)
            .collect();
        for q1 in [3000.0, -4.4e4, 1e6, -3.3e6, 1e300, -1.7e308] {
            let far = loop_closure(&cc, &mut cc.assembly_branch().unwrap(), &[q1]).unwrap();
            assert!(closure_gap(&r, &cc, &far) < 1e-9, "{label} at {q1:e}");
            if q1.abs() > 1e7 {
                continue;
            }
            let near =
                loop_closure(&cc, &mut cc.assembly_branch().unwrap(), &[less_turns(q1)]).unwrap();
            for (k, rev) in revolute.iter().enumerate() {
                let d = far.q_p[k] - near.q_p[k];
                let d = if *rev { less_turns(d) } else { d };
                assert!(
                    d.abs() < 1e-7,
                    "{label} at {q1:e}: q_p[{k}] {} vs {}",
                    far.q_p[k],
                    near.q_p[k]
                );
            }
        }
    }
}

/// The SR400's base joint is on no loop: any value leaves q_p as it is (the base turns the
/// whole mechanism).
#[test]
fn joints_off_the_loops_are_set_at_once() {
    let r = robot("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let at = |q1: f64| {
        let s = loop_closure(
            &cc,
            &mut cc.assembly_branch().unwrap(),
            &[q1, 0.2, 0.3, 0.4, 0.5, 1.6],
        )
        .unwrap();
        assert!(closure_gap(&r, &cc, &s) < 1e-9, "q1 = {q1:e}");
        s.q_p
    };
    let reference = at(0.1);
    for q1 in [1e300, -1e17, 1e6] {
        assert!((at(q1) - &reference).amax() < 1e-9, "q1 = {q1:e}");
    }
}

/// A loop joint that cannot turn fully on its branch (the SR400's parallelogram flattens), or a
/// budget too small for one turn: [`Error::ContinuationBudget`] naming the joint, the tracker
/// where it was. A budget that allows one turn drops the turns.
#[test]
fn moves_that_cannot_be_shortened_are_refused_with_the_budget() {
    let r = robot("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    assert_eq!(cc.step_budget(), DEFAULT_STEP_BUDGET);
    let mut b = cc.assembly_branch().unwrap();
    let start = b.clone();
    match loop_closure(&cc, &mut b, &[0.1, 1e300, 0.3, 0.4, 0.5, 1.6]) {
        Err(Error::ContinuationBudget { budget, reason, .. }) => {
            assert_eq!(budget, DEFAULT_STEP_BUDGET);
            assert!(reason.contains("revolute joint 2"), "{reason}");
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(b, start, "the tracker moved");
    let fourbar = robot("fourbar.toml");
    let tight = ClosedChain::new(&fourbar).unwrap().with_step_budget(10);
    let mut b = tight.assembly_branch().unwrap();
    assert!(matches!(
        loop_closure(&tight, &mut b, &[1e300]),
        Err(Error::ContinuationBudget { budget: 10, .. })
    ));
    let enough = ClosedChain::new(&fourbar).unwrap().with_step_budget(80);
    let s = loop_closure(&enough, &mut enough.assembly_branch().unwrap(), &[100.0]).unwrap();
    assert!(closure_gap(&fourbar, &enough, &s) < 1e-9);
}

/// Long moves and short ones, one after the other on one tracker: finite results, the tracker
/// holding equivalent angles after a long move.
#[test]
fn long_moves_keep_the_results_finite() {
    let r = robot("fourbar.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let mut d = ClosedData::new(&cc);
    let (mut tau, mut qp) = ([0.0], [0.0, 0.0]);
    for q1 in [1e300, -2.5, 7e12, 0.3, -1e9] {
        closed_inverse_dynamics_into(
            &cc,
            &mut d,
            &mut b,
            r.environment(),
            &[q1],
            &[1.0],
            &[0.5],
            &mut tau,
        )
        .unwrap();
        loop_closure_into(&cc, &mut d, &mut b, &[q1], &mut qp).unwrap();
        assert!(
            tau[0].is_finite() && qp.iter().all(|x| x.is_finite()),
            "{q1:e}"
        );
        assert!(
            b.q_a()[0].abs() <= 2.0 * PI + 3.0,
            "held as an equivalent angle: {:?}",
            b.q_a()
        );
    }
}
