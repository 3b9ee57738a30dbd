//! The branch tracker's continuation: moving a [`Branch`] to a target q_a, step by step, within
//! the chain's step budget ([`ClosedChain::step_budget`]).
//!
//! **A move** follows the straight path in q_a from the tracker's point (predictor q_p + W dq_a,
//! Newton corrector, steps of at most 0.25 rad or m per joint, halved on failure), checking at
//! every step that det Wp keeps its sign, that Wp stays above the hard conditioning limit and that
//! the corrector lands within the predictor's reach. Every step tried counts against the budget;
//! a move that needs more is refused with [`Error::ContinuationBudget`].
//!
//! **A long move** (its straight path needs more than half the budget's steps) is shortened
//! first by two properties of the model, so that any finite q_a either is reached in a bounded
//! number of steps or is refused at once:
//! 1. An actuated joint that is on no loop (the SR400's base and wrist joints) does not enter the
//!    closure equations: they are written in the cut frame R_k, which every joint between the base
//!    and the loop's root moves rigidly with the rest of the loop, and the joints after the loop
//!    do not move it. Its value is set at once; q_p does not depend on it (exact).
//! 2. A revolute joint on a loop enters only through the sine and cosine of its angle. Whole
//!    turns are dropped from its move when one full turn of that joint, followed by the tracker
//!    from its point with the other joints still, brings the mechanism back to the same
//!    configuration (q_p equal modulo whole turns of the passive revolute joints, within 1e-6):
//!    the branch is then periodic in that joint and k turns change nothing. The tracker's point and
//!    the target are replaced by the equivalent angles in (-pi, pi] (computed from the sine and
//!    cosine, so an angle of 1e300 is reduced exactly, not by the rounded 2 pi), and the rest of
//!    the move, less than half a turn, is followed. The result is the configuration reached
//!    along "the whole turns, then the short way"; it is the straight path's whenever no
//!    singularity lies between the two paths. A joint whose full turn fails (it cannot turn
//!    fully on the branch: the mechanism's reach or a singularity) or ends on another assembly
//!    keeps its turns, and the move is refused with [`Error::ContinuationBudget`].
//!
//! The tracker's point then holds the reduced angles (the same configuration), and the passive
//! revolute joints keep the values reached on the short way (whole turns of them are not
//! counted). Moves within half the budget follow the straight path unchanged.

use super::{fmt_vec, Branch, ClosedChain, ClosedData};
use crate::error::{Error, Result};
use std::f64::consts::PI;

/// Why a continuation step was refused.
#[derive(Clone, Copy, Debug, PartialEq)]
enum StepFailure {
    NoConvergence,
    Singular,
    SignChange,
    IllConditioned(f64),
    Jump,
}

/// Largest corrector iterations of one continuation step.
const CORRECTOR_ITERATIONS: usize = 12;
/// The corrected q_p may differ from the prediction by half the predicted motion plus this.
const JUMP_FLOOR: f64 = 1e-3;
/// After a full turn, q_p must be back within this (rad or m, modulo whole turns).
const SAME_CONFIGURATION: f64 = 1e-6;

/// The equivalent angle in (-pi, pi] of `x`, from its sine and cosine (exact argument reduction:
/// within an ulp for any finite `x`, where `x % (2 pi)` would use a rounded 2 pi).
fn principal_angle(x: f64) -> f64 {
    let (s, c) = libm::sincos(x);
    libm::atan2(s, c)
}

/// `x` (|x| a few turns at most) plus or minus whole turns, in (-pi, pi].
fn wrap(x: f64) -> f64 {
    let y = x - 2.0 * PI * (x / (2.0 * PI)).round();
    if y <= -PI {
        y + 2.0 * PI
    } else {
        y
    }
}

/// Largest |a - b| over the entries.
fn max_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// `dst` = `src` (same chain: no allocation).
fn copy_branch(dst: &mut Branch, src: &Branch) {
    dst.q_a.copy_from_slice(&src.q_a);
    dst.q_p.copy_from_slice(&src.q_p);
    dst.w.copy_from(&src.w);
    dst.sign = src.sign;
    dst.rcond = src.rcond;
}

impl ClosedChain {
    /// Steps of the straight path from `from` to `to` (steps of at most `max_step`).
    fn nominal_steps(&self, from: &[f64], to: &[f64]) -> f64 {
        max_distance(from, to) / self.max_step
    }

    /// Move the tracker to q_a (see the module documentation). On success the buffers of `d`
    /// hold the closed configuration (placements, Wp factors, W, G); on error the tracker stays
    /// where it was.
    pub(super) fn track(&self, d: &mut ClosedData, b: &mut Branch, q_a: &[f64]) -> Result<()> {
        if self.nominal_steps(&b.q_a, q_a) <= (self.budget / 2) as f64 {
            return self.follow(d, b, q_a, self.budget).map(|_| ());
        }
        copy_branch(&mut d.saved, b);
        let r = self.track_long(d, b, q_a);
        if r.is_err() {
            copy_branch(b, &d.saved);
        }
        r
    }

    /// A long move: joints on no loop set at once, then whole turns of revolute loop joints
    /// dropped where a full turn is verified to change nothing (module documentation).
    fn track_long(&self, d: &mut ClosedData, b: &mut Branch, q_a: &[f64]) -> Result<()> {
        for k in 0..d.n {
            if !self.in_loop[k] {
                b.q_a[k] = q_a[k];
            }
        }
        if self.nominal_steps(&b.q_a, q_a) <= (self.budget / 2) as f64 {
            return self.follow(d, b, q_a, self.budget).map(|_| ());
        }
        // the tracker's point and the target as angles in (-pi, pi] (the same configuration)
        let mut turning = std::mem::take(&mut d.turning);
        turning.clear();
        for k in 0..d.n {
            let move_k = q_a[k] - b.q_a[k];
            d.target[k] = q_a[k];
            if self.in_loop[k] && self.revolute[k] && move_k.abs() > PI {
                let from = principal_angle(b.q_a[k]);
                b.q_a[k] = from;
                d.target[k] = from + wrap(principal_angle(q_a[k]) - from);
                turning.push((k, move_k.signum()));
            }
        }
        let r = self.drop_turns(d, b, q_a, &turning);
        d.turning = turning;
        r
    }

    /// Check that every joint of `turning` may drop its whole turns, then follow the short move
    /// to `d.target`.
    fn drop_turns(
        &self,
        d: &mut ClosedData,
        b: &mut Branch,
        q_a: &[f64],
        turning: &[(usize, f64)],
    ) -> Result<()> {
        let refused = |reason: String| Error::ContinuationBudget {
            at: q_a.to_vec(),
            budget: self.budget,
            reason,
        };
        let rest = max_distance(&b.q_a, &d.target);
        if rest / self.max_step > (self.budget / 2) as f64 {
            let k = (0..d.n)
                .max_by(|&x, &y| {
                    let dx = (d.target[x] - b.q_a[x]).abs();
                    dx.total_cmp(&(d.target[y] - b.q_a[y]).abs())
                })
                .unwrap_or(0);
            let kind = if self.revolute[k] {
                "revolute"
            } else {
                "prismatic"
            };
            return Err(refused(format!(
                "the path moves {kind} joint {} by {:.3e} (steps of at most {}), beyond what \
                 the continuation follows",
                self.coords.frame(k),
                rest,
                self.max_step
            )));
        }
        let mut used = 0;
        for &(k, direction) in turning {
            used += self
                .full_turn(d, b, k, direction, self.budget - used)
                .map_err(|why| {
                    refused(format!(
                        "whole turns of revolute joint {} cannot be dropped: {why}",
                        self.coords.frame(k)
                    ))
                })?;
        }
        let target = std::mem::take(&mut d.target);
        let r = self.follow(d, b, &target, self.budget - used);
        d.target = target;
        r.map(|_| ())
    }

    /// Follow one full turn of actuated joint `k` (index) from the tracker's point and come back:
    /// the steps used, or why the turn does not bring the mechanism back to the same
    /// configuration. The tracker ends where it started.
    fn full_turn(
        &self,
        d: &mut ClosedData,
        b: &mut Branch,
        k: usize,
        direction: f64,
        budget: usize,
    ) -> std::result::Result<usize, String> {
        copy_branch(&mut d.probe, b);
        let mut end = std::mem::take(&mut d.turn_end);
        end.copy_from_slice(&b.q_a);
        end[k] += direction * 2.0 * PI;
        let r = self.follow(d, b, &end, budget);
        d.turn_end = end;
        let used = r.map_err(|e| format!("a full turn of it on this branch fails ({e})"))?;
        let same = (0..d.p).all(|r| {
            let dq = b.q_p[r] - d.probe.q_p[r];
            let dq = if self.passive_revolute[r] {
                wrap(dq)
            } else {
                dq
            };
            dq.abs() <= SAME_CONFIGURATION
        });
        let result = if same {
            Ok(used)
        } else {
            Err(format!(
                "a full turn of it on this branch does not come back to the same configuration \
                 (q_p = {} before, {} after: another assembly)",
                fmt_vec(&d.probe.q_p),
                fmt_vec(&b.q_p)
            ))
        };
        copy_branch(b, &d.probe);
        result
    }

    /// Follow the straight path from the tracker's point to `q_a` with at most `budget` steps
    /// tried: the steps tried. On error the tracker is back where it started.
    fn follow(
        &self,
        d: &mut ClosedData,
        b: &mut Branch,
        q_a: &[f64],
        budget: usize,
    ) -> Result<usize> {
        d.start_qa.copy_from_slice(&b.q_a);
        d.start_qp.copy_from_slice(&b.q_p);
        d.start_w.copy_from(&b.w);
        d.start_rcond = b.rcond;
        let dist = max_distance(q_a, &b.q_a);
        let max_h = if dist == 0.0 {
            1.0
        } else {
            (self.max_step / dist).min(1.0)
        };
        let mut h = max_h;
        let mut s = 0.0;
        let mut failure: StepFailure;
        let mut tried = 0;
        loop {
            if tried == budget {
                let near = fmt_vec(&d.qa);
                self.restore(d, b);
                return Err(Error::ContinuationBudget {
                    at: q_a.to_vec(),
                    budget: self.budget,
                    reason: format!(
                        "the continuation tried {tried} steps and stopped near q_a = {near} \
                         (steps were halved on the way: a tight or nearly singular passage)"
                    ),
                });
            }
            tried += 1;
            let t = if s + h >= 1.0 - 1e-12 { 1.0 } else { s + h };
            self.predict(d, b, q_a, t);
            match self.correct(d).and_then(|()| self.accept(d, b)) {
                Ok(rcond) => {
                    self.compute_w(d);
                    b.q_a.copy_from_slice(&d.qa);
                    b.q_p.copy_from_slice(&d.qp);
                    b.w.copy_from(&d.w);
                    b.rcond = rcond;
                    s = t;
                    if t == 1.0 {
                        return Ok(tried);
                    }
                    h = (2.0 * h).min(max_h);
                }
                Err(f) => {
                    failure = f;
                    if let (1.0, StepFailure::IllConditioned(rcond)) = (t, f) {
                        // the target itself is singular (reached on the branch)
                        if h <= max_h / 64.0 || s == 0.0 && dist == 0.0 {
                            self.restore(d, b);
                            return Err(self.singular_wp(rcond, &d.q_tr));
                        }
                    }
                    h *= 0.5;
                    if h * dist.max(1.0) < 1e-9 {
                        break;
                    }
                }
            }
        }
        // where it failed: the last tried q_a
        let near = fmt_vec(&d.qa);
        self.restore(d, b);
        Err(Error::BranchLost {
            at: q_a.to_vec(),
            reason: self.lost_reason(failure, &near),
        })
    }

    /// The point at `t` of the straight path from the start to `q_a` into d.qa, and the
    /// predictor (10.29) q_p + W (q_a - q_a_branch) into d.pred.
    fn predict(&self, d: &mut ClosedData, b: &Branch, q_a: &[f64], t: f64) {
        if t == 1.0 {
            d.qa.copy_from_slice(q_a);
        } else {
            for k in 0..d.n {
                d.qa[k] = d.start_qa[k] + t * (q_a[k] - d.start_qa[k]);
            }
        }
        d.pred_step = 0.0;
        for r in 0..d.p {
            let mut x = b.q_p[r];
            for c in 0..d.n {
                x += b.w[(r, c)] * (d.qa[c] - b.q_a[c]);
            }
            d.pred_step = d.pred_step.max((x - b.q_p[r]).abs());
            d.pred[r] = x;
        }
    }

    /// The checks of a corrected step: det Wp keeps its sign, Wp above the hard limit, the
    /// correction within the predictor's reach. The reciprocal condition number of Wp.
    fn accept(&self, d: &mut ClosedData, b: &Branch) -> std::result::Result<f64, StepFailure> {
        let jump = max_distance(&d.qp, &d.pred);
        if d.lu.det_sign() != b.sign {
            return Err(StepFailure::SignChange);
        }
        let rcond = d.lu.rcond();
        if rcond < self.limits.wp_hard {
            return Err(StepFailure::IllConditioned(rcond));
        }
        if jump > 0.5 * d.pred_step + JUMP_FLOOR {
            return Err(StepFailure::Jump);
        }
        Ok(rcond)
    }

    fn lost_reason(&self, failure: StepFailure, near: &str) -> String {
        match failure {
            StepFailure::SignChange => format!(
                "the path crosses a singular configuration (det Wp changes sign near q_a = \
                 {near}): the configuration belongs to another assembly branch or lies beyond \
                 a singularity"
            ),
            StepFailure::IllConditioned(r) => format!(
                "Wp is singular on the path near q_a = {near} (reciprocal condition number \
                 {r:.1e} < {:.0e})",
                self.limits.wp_hard
            ),
            StepFailure::Singular => format!("Wp is singular on the path near q_a = {near}"),
            StepFailure::Jump => format!(
                "the closure solution jumps to another assembly near q_a = {near} (a fold or \
                 bifurcation of the branch)"
            ),
            StepFailure::NoConvergence => format!(
                "the closure equations have no solution near q_a = {near} on the branch (beyond \
                 the reach of the mechanism)"
            ),
        }
    }

    /// Newton corrector at d.qa from d.pred into d.qp; on success the placements, the Jacobian
    /// and the LU of Wp are those of the solution.
    fn correct(&self, d: &mut ClosedData) -> std::result::Result<(), StepFailure> {
        let lc = &self.closure;
        d.qp.copy_from_slice(&d.pred);
        let mut previous = f64::INFINITY;
        for _ in 0..CORRECTOR_ITERATIONS {
            lc.assemble(&d.qa, &d.qp, &mut d.q_tr);
            lc.kinematics(&mut d.lw, &d.q_tr, None, None);
            lc.residual(&d.lw, &mut d.r);
            if d.r.amax() <= lc.tolerance {
                self.factor_wp(d);
                if !d.lu.regular {
                    return Err(StepFailure::Singular);
                }
                if lc.flipped_loop(&d.lw).is_some() {
                    return Err(StepFailure::Jump);
                }
                return Ok(());
            }
            self.factor_wp(d);
            if !d.lu.regular {
                return Err(StepFailure::Singular);
            }
            for (x, r) in d.dx.iter_mut().zip(d.r.iter()) {
                *x = -r;
            }
            d.lu.solve(&mut d.dx);
            let step = d.dx.iter().fold(0.0_f64, |a, b| a.max(b.abs()));
            if !step.is_finite() || step > 0.5 * previous {
                return Err(StepFailure::NoConvergence);
            }
            previous = step;
            for (q, x) in d.qp.iter_mut().zip(&d.dx) {
                *q += x;
            }
        }
        Err(StepFailure::NoConvergence)
    }

    fn restore(&self, d: &ClosedData, b: &mut Branch) {
        b.q_a.copy_from_slice(&d.start_qa);
        b.q_p.copy_from_slice(&d.start_qp);
        b.w.copy_from(&d.start_w);
        b.rcond = d.start_rcond;
    }
}

#[cfg(test)]
mod tests {
    use super::{principal_angle, wrap};
    use std::f64::consts::PI;

    /// The reduced angle has the sine and cosine of the original (libm's exact reduction), where
    /// `x % (2 pi)` with the rounded 2 pi is wrong for large x.
    #[test]
    fn principal_angles_keep_sine_and_cosine() {
        for x in [0.3, -2.0, 7.0, 1e5, -3.3e9, 1e17, 1e300, -1.7e308, f64::MAX] {
            let r = principal_angle(x);
            assert!(r > -PI && r <= PI, "{x}: {r}");
            assert!((libm::sin(r) - libm::sin(x)).abs() < 1e-15, "{x}");
            assert!((libm::cos(r) - libm::cos(x)).abs() < 1e-15, "{x}");
        }
        // the naive reduction is off by far more for 1e300
        let naive = 1e300 % (2.0 * PI);
        assert!((libm::sin(naive) - libm::sin(1e300)).abs() > 1e-3);
        assert_eq!(wrap(3.0 * PI / 2.0), -PI / 2.0);
        assert!((wrap(-PI) - PI).abs() < 1e-15);
    }
}
