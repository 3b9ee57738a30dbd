//! Generated derivatives of the inverse dynamic model (`ModelKind::IdmDerivatives`): the
//! customized IDM program differentiated in forward mode (`Program::differentiate`), then the
//! program optimisations of every model.
//!
//! Three steps:
//! 1. record the customized IDM Gamma(q, qd, qdd) (Newton–Euler, as `ModelKind::Idm`) and the
//!    inertia matrix A(q) (composite links, as `ModelKind::Inertia`) in one recording, so that
//!    they share the sines and cosines;
//! 2. differentiate the IDM's assignments along each joint position `q<j>` and velocity `QP<j>`:
//!    every assignment `v = f(args)` gives `dv/dx = sum of df/darg * darg/dx` over the arguments
//!    that depend on x; an intermediate that does not depend on x has no derivative (most
//!    depend on a few joints: the forward recursion's link k on joints 1..k, the backward one
//!    on its subtree), numbers fold, a trivial derivative is used inline;
//! 3. the outputs: dGamma/dq, dGamma/dqd and A = dGamma/dqdd, each N x N column-major, A's
//!    upper triangle a copy of its lower one.
//!
//! Coulomb friction FS sign(qd) contributes nothing: its derivative is 0 wherever it is smooth
//! (qd != 0), as in the numeric derivatives; viscous friction FV qd contributes FV to
//! dGamma/dqd.

use super::pair_name;
use robodyn_symbolic::{Assignment, Expr, Program};
use std::collections::{HashMap, HashSet};

/// Output name prefixes of the three blocks: `DGQ<i><k>` = dGamma_i/dq_k, `DGQP<i><k>` =
/// dGamma_i/dqd_k, `A<i><k>` (frame numbers; `_` between them beyond 9).
pub const BLOCKS: [&str; 3] = ["DGQ", "DGQP", "A"];

/// The assignments and outputs of the derivative program from one recording of the IDM and A:
/// `gam` the IDM's outputs (one per movable joint, in frame order), `a_low` the lower triangle
/// of A row by row, `frames` the movable joints' frame numbers.
pub(super) fn derivative_program(
    recorded: Vec<Assignment>,
    gam: Vec<Assignment>,
    a_low: Vec<Assignment>,
    frames: &[usize],
) -> (Vec<Assignment>, Vec<Assignment>) {
    let n = frames.len();
    // the IDM alone: the assignments its torques read, optimized
    let mut idm = Program {
        assignments: recorded.clone(),
        outputs: gam,
        ..Program::default()
    };
    idm.remove_dead();
    let raw_idm: HashSet<String> = idm.assignments.iter().map(|a| a.name.clone()).collect();
    // optimized before it is differentiated: fewer, shared intermediates have fewer
    // derivatives (the Panda's derivatives: 9450 operations, against 10053 from the recording)
    idm.optimize();
    let vars: Vec<String> = ["q", "QP"]
        .iter()
        .flat_map(|kind| frames.iter().map(move |j| super::joint_symbol(kind, *j)))
        .collect();
    let tangents = idm.differentiate(&vars);
    let mut assignments = tangents.assignments;
    let a_low = append_inertia(&mut assignments, &raw_idm, recorded, a_low);
    let mut outputs = Vec::with_capacity(3 * n * n);
    for (block, prefix) in BLOCKS[..2].iter().enumerate() {
        for (k, &jk) in frames.iter().enumerate() {
            for (i, &ji) in frames.iter().enumerate() {
                outputs.push(Assignment {
                    name: pair_name(prefix, ji, jk),
                    expr: tangents.outputs[block * n + k][i].clone(),
                });
            }
        }
    }
    let low = |i: usize, k: usize| -> Expr {
        let (r, c) = if i >= k { (i, k) } else { (k, i) };
        a_low[r * (r + 1) / 2 + c].expr.clone()
    };
    for (k, &jk) in frames.iter().enumerate() {
        for (i, &ji) in frames.iter().enumerate() {
            outputs.push(Assignment {
                name: pair_name(BLOCKS[2], ji, jk),
                expr: low(i, k),
            });
        }
    }
    (assignments, outputs)
}

/// Append the assignments the inertia matrix `a_low` reads to `assignments` (the optimized and
/// differentiated IDM of the same recording) and return `a_low` as they name it. An assignment
/// of the recorded IDM (`raw_idm`, its names) that `assignments` still has is not repeated:
/// the optimisations keep the value of every name they keep (they substitute, share and
/// inline). A name they introduced (`T1`, `GAM2`, `DWI12_q2`) that the recording gave another
/// value is renamed.
fn append_inertia(
    assignments: &mut Vec<Assignment>,
    raw_idm: &HashSet<String>,
    recorded: Vec<Assignment>,
    a_low: Vec<Assignment>,
) -> Vec<Assignment> {
    let mut closure = Program {
        assignments: recorded,
        outputs: a_low,
        ..Program::default()
    };
    closure.remove_dead();
    let mut taken: HashSet<String> = assignments.iter().map(|a| a.name.clone()).collect();
    let kept: HashSet<String> = taken.intersection(raw_idm).cloned().collect();
    let mut rename: HashMap<String, Expr> = HashMap::new();
    let mut fresh = Vec::new();
    for a in closure.assignments {
        if kept.contains(&a.name) {
            continue;
        }
        let expr = a.expr.substitute(&|s| rename.get(s).cloned());
        let name = if taken.insert(a.name.clone()) {
            a.name
        } else {
            let n = (2..)
                .map(|k| format!("{}_{k}", a.name))
                .find(|n| taken.insert(n.clone()))
                .expect("an unused name");
            rename.insert(a.name, Expr::symbol(n.clone()));
            n
        };
        fresh.push(Assignment { name, expr });
    }
    assignments.extend(fresh);
    closure
        .outputs
        .into_iter()
        .map(|o| Assignment {
            name: o.name,
            expr: o.expr.substitute(&|s| rename.get(s).cloned()),
        })
        .collect()
}
