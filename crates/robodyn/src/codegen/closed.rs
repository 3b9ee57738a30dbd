//! The constant Jacobian G = d q_tr / d q_a of closed chains whose loop constraints are linear
//! (parallelograms such as the SR400's, Example 10.1), for Gamma_cl = G^T Gamma_tr (10.40).
//!
//! G is found numerically and then checked to be constant: at several random actuated
//! configurations the loop closure (frame R_k on link a(k) coincides with its twin R_{k+B}) is
//! solved for the passive and cut-joint variables by Gauss–Newton, the constraint Jacobian
//! [J_p J_a] (central differences) gives W = -J_p^+ J_a (10.38–10.39), G = [I; W] in tree order.
//! When the entries differ between configurations, or are not simple rationals, the chain is
//! reported as not supported (a general closed chain needs G(q) at run time).

use crate::error::{Error, Result};
use crate::geometry::frame_transforms;
use crate::Robot;
use nalgebra::{DMatrix, DVector};
use rand::Rng;

/// Loop-closure residual: for each cut joint k, position and orientation difference between
/// R_k and R_{k+B} (12 entries per loop).
fn residual(robot: &Robot, q: &[f64]) -> DVector<f64> {
    let t = frame_transforms(robot, q);
    let (nl, nj) = (robot.nl(), robot.nj());
    let b = nj - nl;
    let mut r = Vec::with_capacity(12 * b);
    for k in nl + 1..=nj {
        let (tk, tt) = (&t[k - 1], &t[k + b - 1]);
        r.extend((tk.pos - tt.pos).iter());
        r.extend((tk.rot - tt.rot).iter());
    }
    DVector::from_vec(r)
}

fn jacobian(robot: &Robot, q: &[f64], cols: &[usize]) -> DMatrix<f64> {
    let h = 1e-6;
    let r0 = residual(robot, q);
    let mut jac = DMatrix::zeros(r0.len(), cols.len());
    let mut qq = q.to_vec();
    for (c, &j) in cols.iter().enumerate() {
        qq[j - 1] = q[j - 1] + h;
        let rp = residual(robot, &qq);
        qq[j - 1] = q[j - 1] - h;
        let rm = residual(robot, &qq);
        qq[j - 1] = q[j - 1];
        jac.set_column(c, &((rp - rm) / (2.0 * h)));
    }
    jac
}

/// Solve the loop closure for the unknown variables `unk` (1-based, tree or cut joints).
fn close_loops<R: Rng>(robot: &Robot, q: &mut [f64], unk: &[usize], rng: &mut R) -> bool {
    for attempt in 0..20 {
        if attempt > 0 {
            for &j in unk {
                q[j - 1] = rng.random_range(-3.0..3.0);
            }
        }
        for _ in 0..60 {
            let r = residual(robot, q);
            if r.norm() < 1e-13 {
                return true;
            }
            let jac = jacobian(robot, q, unk);
            let Ok(pinv) = jac.pseudo_inverse(1e-9) else {
                break;
            };
            let dx = pinv * r;
            for (c, &j) in unk.iter().enumerate() {
                q[j - 1] -= dx[c];
            }
        }
        if residual(robot, q).norm() < 1e-11 {
            return true;
        }
    }
    false
}

/// The constant G (NL rows in tree-joint order, one column per actuated joint in increasing
/// order), or an error when G depends on the configuration.
pub fn constant_g(robot: &Robot) -> Result<DMatrix<f64>> {
    let (nl, nj) = (robot.nl(), robot.nj());
    if nj == nl {
        return Err(Error::Input(
            "the robot has no closed loop (NJ = NL)".into(),
        ));
    }
    let act = robot.actuated_joints();
    let mut unk = robot.passive_joints();
    unk.extend(nl + 1..=nj);
    let mut rng = crate::testing::rng(7);
    let g_at = |q: &[f64]| -> Result<DMatrix<f64>> {
        let ja = jacobian(robot, q, &act);
        let jp = jacobian(robot, q, &unk);
        let pinv = jp
            .pseudo_inverse(1e-9)
            .map_err(|e| Error::Numerical(format!("singular loop-closure Jacobian: {e}")))?;
        let w = -(pinv * ja);
        let mut g = DMatrix::zeros(nl, act.len());
        for (c, &a) in act.iter().enumerate() {
            g[(a - 1, c)] = 1.0;
        }
        for (r, &p) in unk.iter().enumerate() {
            if p <= nl {
                for c in 0..act.len() {
                    g[(p - 1, c)] = w[(r, c)];
                }
            }
        }
        Ok(g)
    };
    let mut qa0 = vec![0.0; nj];
    for &a in &act {
        qa0[a - 1] = rng.random_range(-1.0..1.0);
    }
    // Several assembly modes may exist (a parallelogram and its crossed form): follow each
    // solution found from a random start along a path of q_a (continuation keeps the mode) and
    // accept the first mode whose G stays constant.
    let mut found = None;
    'starts: for _ in 0..8 {
        let mut q = qa0.clone();
        for &p in &unk {
            q[p - 1] = rng.random_range(-3.0..3.0);
        }
        if !close_loops(robot, &mut q, &unk, &mut rng) {
            continue;
        }
        let g0 = g_at(&q)?;
        let dir: Vec<f64> = act.iter().map(|_| rng.random_range(-0.2..0.2)).collect();
        for _ in 0..4 {
            for (c, &a) in act.iter().enumerate() {
                q[a - 1] += dir[c];
            }
            if !close_loops(robot, &mut q, &unk, &mut rng) {
                continue 'starts;
            }
            if (g_at(&q)? - &g0).amax() > 1e-6 {
                continue 'starts;
            }
        }
        found = Some(g0);
        break;
    }
    let Some(g0) = found else {
        return Err(Error::Input(
            "general closed chains are not supported yet by the generator: no assembly mode \
             with a constant G was found (only loops such as parallelograms are supported)"
                .into(),
        ));
    };
    // exact small rationals (0, +-1, +-1/2, ...)
    let mut out = g0.clone();
    for x in out.iter_mut() {
        let r = (*x * 12.0).round() / 12.0;
        if (*x - r).abs() > 1e-6 {
            return Err(Error::Input(format!(
                "general closed chains are not supported yet by the generator: G has the \
                 non-rational entry {x}"
            )));
        }
        *x = r;
    }
    Ok(out)
}
