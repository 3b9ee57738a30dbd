//! The closed-chain model: [`ClosedChain`] (the loop-closure equations on the equivalent tree,
//! the actuated and passive coordinates, the continuation settings), built once from a
//! [`Robot`], with its accessors and builders, and its conditioning limits.

use super::{Branch, ClosedData};
use crate::algorithms::loop_closure::{LoopClosure, LoopConstraint};
use crate::error::{Error, Result};
use crate::model::{Coordinates, JointType, Robot};
use nalgebra::DVector;

/// Conditioning limits of a closed chain: reciprocal 1-norm condition numbers
/// 1 / (||M||_1 ||M^-1||_1) below which a result is flagged (`soft`) or refused (`hard`).
///
/// The default hard limit of Wp, 1e-5, comes from the closure tolerance (1e-12): at a fold of the
/// closure manifold (a parallel singularity, e.g. the five-bar's distal links aligned) q_p is
/// determined only to its square root, ~1e-6 rad or m, and the reciprocal condition number
/// reached there is ~1e-6: anything below 1e-5 is indistinguishable from exactly singular, and
/// W ~ 1/rcond is then meaningless. Below the soft limit 1e-3, W and the closed-chain torques
/// are amplified more than a thousand times: correct, but sensitive to every input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConditioningLimits {
    /// Wp below this: warning (default 1e-3).
    pub wp_soft: f64,
    /// Wp below this: [`Error::Singular`] (default 1e-5).
    pub wp_hard: f64,
    /// A_cl below this: warning (default 1e-8).
    pub a_cl_soft: f64,
    /// A_cl below this: [`Error::Singular`] (default 1e-13).
    pub a_cl_hard: f64,
}

impl Default for ConditioningLimits {
    fn default() -> Self {
        ConditioningLimits {
            wp_soft: 1e-3,
            wp_hard: 1e-5,
            a_cl_soft: 1e-8,
            a_cl_hard: 1e-13,
        }
    }
}

/// Conditioning of a closed-chain result, returned next to it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conditioning {
    /// Reciprocal 1-norm condition number of Wp at the configuration.
    pub wp: f64,
    /// Reciprocal 1-norm condition number of A_cl (direct model only).
    pub a_cl: Option<f64>,
    /// True when a value is below its soft limit: the configuration is near a singularity and
    /// the result is sensitive to its inputs.
    pub warning: bool,
}

impl Conditioning {
    /// "reciprocal condition number of Wp 3.2e-6 (warning below 1e-4)", for messages.
    pub fn describe(&self, limits: &ConditioningLimits) -> String {
        let mut s = format!(
            "reciprocal condition number of Wp {:.1e} (warning below {:.0e})",
            self.wp, limits.wp_soft
        );
        if let Some(a) = self.a_cl {
            s.push_str(&format!(
                ", of A_cl {a:.1e} (warning below {:.0e})",
                limits.a_cl_soft
            ));
        }
        s
    }
}

/// Closed-chain model: the loop-closure equations of its loops on the equivalent tree, the
/// actuated and passive coordinates, the conditioning limits and the continuation settings.
#[derive(Clone, Debug)]
pub struct ClosedChain {
    pub(super) closure: LoopClosure,
    pub(super) coords: Coordinates,
    pub(super) passive: Coordinates,
    pub(super) limits: ConditioningLimits,
    pub(super) max_step: f64,
    pub(super) budget: usize,
    /// Per actuated joint: on a loop (its value enters the closure equations).
    pub(super) in_loop: Vec<bool>,
    /// Per actuated joint: revolute.
    pub(super) revolute: Vec<bool>,
    /// Per passive joint: revolute.
    pub(super) passive_revolute: Vec<bool>,
}

/// Default [`ClosedChain::step_budget`].
pub const DEFAULT_STEP_BUDGET: usize = 50_000;

impl ClosedChain {
    /// The closed-chain model of `robot`: chooses the independent closure equations of each
    /// loop by rank (see [`crate::algorithms::loop_closure`]) and checks that they are as many as
    /// the passive joints. Error for a tree or a wrong number of actuators.
    pub fn new(robot: &Robot) -> Result<ClosedChain> {
        robot.require_fixed_base("the closed-chain model")?;
        robot.require_no_motor_drives("the closed-chain model")?;
        let closure = LoopClosure::new(robot)?;
        let coords_of = |js: &[usize]| {
            Coordinates::new(
                js.to_vec(),
                js.iter().map(|&j| robot.frame(j).name.clone()).collect(),
                robot.nl(),
            )
        };
        let on_loop: std::collections::BTreeSet<usize> = robot
            .structure()
            .loops
            .iter()
            .flat_map(|l| l.tree_joints())
            .collect();
        let revolute = |js: &[usize]| -> Vec<bool> {
            js.iter()
                .map(|&j| robot.frame(j).joint == JointType::Revolute)
                .collect()
        };
        Ok(ClosedChain {
            coords: coords_of(closure.actuated_joints()),
            passive: coords_of(closure.passive_joints()),
            in_loop: closure
                .actuated_joints()
                .iter()
                .map(|j| on_loop.contains(j))
                .collect(),
            revolute: revolute(closure.actuated_joints()),
            passive_revolute: revolute(closure.passive_joints()),
            closure,
            limits: ConditioningLimits::default(),
            max_step: 0.25,
            budget: DEFAULT_STEP_BUDGET,
        })
    }

    /// The continuation's step budget: the most steps (each a predictor and a Newton corrector)
    /// one evaluation may try to move the branch tracker to its q_a; more is
    /// [`Error::ContinuationBudget`], so that every evaluation ends in bounded time (default
    /// [`DEFAULT_STEP_BUDGET`]: at most about half a second for the bundled closed robots).
    ///
    /// A move whose straight path needs more than half the budget (steps of at most 0.25 rad or
    /// m per joint) is shortened first: actuated joints on no loop are set at once (the closure
    /// equations do not depend on them), and whole turns of a revolute joint on a loop are
    /// dropped when one full turn of it, followed on the branch, comes back to the same
    /// configuration. The angles of such a move are then held as their equivalents in
    /// (-pi, pi] (reduced exactly, from their sine and cosine), and the passive revolute joints
    /// keep the values reached on the short way. A joint that cannot turn fully on its branch
    /// keeps its turns, and a move that is still too long is refused.
    pub fn step_budget(&self) -> usize {
        self.budget
    }

    /// The same chain with another step budget (at least 1).
    pub fn with_step_budget(mut self, steps: usize) -> Self {
        self.budget = steps.max(1);
        self
    }

    /// The equivalent tree.
    pub fn robot(&self) -> &Robot {
        self.closure.robot()
    }

    /// Coordinates of the public vectors: the actuated joints q_a, in frame order.
    pub fn coordinates(&self) -> &Coordinates {
        &self.coords
    }

    /// Coordinates of q_p: the passive tree joints, in frame order.
    pub fn passive_coordinates(&self) -> &Coordinates {
        &self.passive
    }

    /// N, the degrees of freedom (actuated joints).
    pub fn dof(&self) -> usize {
        self.coords.len()
    }

    /// p, the number of independent closure equations (= passive joints).
    pub fn n_equations(&self) -> usize {
        self.closure.n_equations()
    }

    /// The loops with their kept closure equations.
    pub fn loops(&self) -> &[LoopConstraint] {
        self.closure.loops()
    }

    /// The conditioning limits.
    pub fn limits(&self) -> &ConditioningLimits {
        &self.limits
    }

    /// The same chain with other conditioning limits.
    pub fn with_limits(mut self, limits: ConditioningLimits) -> Self {
        self.limits = limits;
        self
    }

    /// Closure tolerance: the largest kept closure equation at a solution (m or rad; default
    /// 1e-12).
    pub fn tolerance(&self) -> f64 {
        self.closure.tolerance
    }

    /// The same chain with another closure tolerance (> 0).
    pub fn with_tolerance(mut self, tolerance: f64) -> Self {
        self.closure.tolerance = tolerance;
        self
    }

    #[cfg_attr(not(feature = "codegen"), allow(dead_code))]
    pub(crate) fn closure(&self) -> &LoopClosure {
        &self.closure
    }

    pub(super) fn check_data(&self, d: &ClosedData, b: &Branch) -> Result<()> {
        if d.n != self.dof() || d.p != self.n_equations() || d.nl != self.robot().nl() {
            return Err(Error::dimension(
                "closed data",
                self.dof(),
                d.n,
                "actuated joints: the ClosedData was made for another closed chain",
            ));
        }
        if b.q_a.len() != self.dof() || b.q_p.len() != self.n_equations() {
            return Err(Error::dimension(
                "branch",
                self.dof(),
                b.q_a.len(),
                "actuated joints: the Branch was made for another closed chain",
            ));
        }
        Ok(())
    }

    pub(super) fn conditioning(&self, b: &Branch, a_cl: Option<f64>) -> Conditioning {
        let l = &self.limits;
        Conditioning {
            wp: b.rcond,
            a_cl,
            warning: b.rcond < l.wp_soft || a_cl.is_some_and(|a| a < l.a_cl_soft),
        }
    }

    /// Tree vector (NL) over the movable joints of the equivalent tree.
    pub(super) fn tree_vector(&self, v: &[f64]) -> DVector<f64> {
        let c = self.robot().coordinates();
        DVector::from_iterator(c.len(), c.frames().iter().map(|&j| v[j - 1]))
    }
}
