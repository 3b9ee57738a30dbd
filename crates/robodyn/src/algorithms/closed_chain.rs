//! Dynamic models of robots with closed kinematic chains (§10.3.1–10.3.3): the equivalent tree's
//! Newton–Euler model projected on the actuated joints, evaluated on one assembly branch.
//!
//! - kinematic constraints: W = -Wp^-1 Wa (10.30), G = d q_tr / d q_a (10.40),
//!   qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Ψ (10.42);
//! - inverse model: Γ_cl = G^T Γ_tr (10.40), Lagrange multipliers λ = -Wp^-T Γ_p (10.37) and
//!   Γ_cl = Γ_a + Wa^T λ (10.36, upper part);
//! - direct model: A_cl (10.46), H_cl (10.47), qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.48, Cholesky).
//!
//! [`ClosedChain`] is the model (built once from a [`Robot`]), [`ClosedData`] its per-evaluation
//! buffers and [`Branch`] the branch tracker: the assembly branch (sign of det Wp) and the last
//! closed point reached on it. Every evaluation at q_a first moves the tracker to q_a by
//! continuation along the straight path in q_a (predictor q_p + W dq_a, Newton corrector, steps
//! halved on failure), checking at every step that det Wp keeps its sign, that Wp stays above the
//! hard conditioning limit and that the corrector lands within the predictor's reach, within a
//! step budget (long moves are shortened where the model allows it: [`ClosedChain::step_budget`]). A
//! result therefore depends on (model, branch, inputs) only, never on a hidden history.
//!
//! Public vectors: q_a, qd_a, qdd_a, Γ_cl over the actuated joints
//! ([`ClosedChain::coordinates`]); q_p over the passive joints
//! ([`ClosedChain::passive_coordinates`]); tree states (Γ_tr, q_tr...) over the movable joints of
//! the equivalent tree (`chain.robot().coordinates()`).
//!
//! Allocation: the `_into` functions allocate nothing once the tracker is on the branch (the
//! small p x p solves use the crate's in-place LU); starting a branch
//! ([`ClosedChain::assembly_branch`], [`ClosedChain::branch_from`]) allocates.

use crate::algorithms::inertia_matrix::composite_inertia_matrix;
use crate::algorithms::inverse_dynamics::rnea_with_environment;
use crate::algorithms::loop_closure::{fmt_vec, LoopClosure, LoopConstraint, LoopWorkspace};
use crate::algorithms::regressor::{tree_regressor, tree_wrench_torques, PARAMS_PER_LINK};
use crate::data::Data;
use crate::error::{Configuration, Error, Result};
use crate::linalg::{norm1, rcond_cholesky, SmallLu};
use crate::model::{Coordinates, Environment, JointType, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, DVector};

mod continuation;

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
    closure: LoopClosure,
    coords: Coordinates,
    passive: Coordinates,
    limits: ConditioningLimits,
    max_step: f64,
    budget: usize,
    /// Per actuated joint: on a loop (its value enters the closure equations).
    in_loop: Vec<bool>,
    /// Per actuated joint: revolute.
    revolute: Vec<bool>,
    /// Per passive joint: revolute.
    passive_revolute: Vec<bool>,
}

/// Default [`ClosedChain::step_budget`].
pub const DEFAULT_STEP_BUDGET: usize = 50_000;

/// The branch tracker of a closed chain: the assembly branch (sign of det Wp) and the last
/// closed configuration reached on it, owned by the caller. Made by
/// [`ClosedChain::assembly_branch`] or [`ClosedChain::branch_from`]; every closed-chain
/// evaluation moves it to its q_a (on error it stays where it was).
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    q_a: Vec<f64>,
    q_p: Vec<f64>,
    /// W at (q_a, q_p): the predictor of the next step.
    w: DMatrix<f64>,
    sign: f64,
    rcond: f64,
}

impl Branch {
    fn zeros(n: usize, p: usize) -> Branch {
        Branch {
            q_a: vec![0.0; n],
            q_p: vec![0.0; p],
            w: DMatrix::zeros(p, n),
            sign: 1.0,
            rcond: 0.0,
        }
    }

    /// The actuated values of the tracker's point (after a long move, revolute loop joints hold
    /// the equivalent angle in (-pi, pi]: see [`ClosedChain::step_budget`]).
    pub fn q_a(&self) -> &[f64] {
        &self.q_a
    }

    /// The passive values of the tracker's point.
    pub fn q_p(&self) -> &[f64] {
        &self.q_p
    }

    /// Sign of det Wp on the branch (+1 or -1): the branch invariant.
    pub fn det_sign(&self) -> f64 {
        self.sign
    }

    /// Reciprocal condition number of Wp at the tracker's point.
    pub fn rcond(&self) -> f64 {
        self.rcond
    }
}

/// Per-evaluation buffers of a [`ClosedChain`] (its tree's [`Data`] included). One per thread.
#[derive(Clone, Debug)]
pub struct ClosedData {
    n: usize,
    p: usize,
    nl: usize,
    tree: Data,
    lw: LoopWorkspace,
    q_tr: Vec<f64>,
    qd_tr: Vec<f64>,
    qdd_tr: Vec<f64>,
    tau_tr: Vec<f64>,
    r: DVector<f64>,
    jac: DMatrix<f64>,
    lu: SmallLu,
    w: DMatrix<f64>,
    g: DMatrix<f64>,
    psi: DVector<f64>,
    qa: Vec<f64>,
    qp: Vec<f64>,
    pred: Vec<f64>,
    dx: Vec<f64>,
    start_qa: Vec<f64>,
    start_qp: Vec<f64>,
    start_w: DMatrix<f64>,
    start_rcond: f64,
    pred_step: f64,
    /// The tracker before a long move, and before a full turn (continuation).
    saved: Branch,
    probe: Branch,
    target: Vec<f64>,
    turn_end: Vec<f64>,
    turning: Vec<(usize, f64)>,
    a_cl: DMatrix<f64>,
    chol: DMatrix<f64>,
    h_cl: DVector<f64>,
    ag: DMatrix<f64>,
    v_nl: DVector<f64>,
    col_n: DVector<f64>,
    zeros_n: Vec<f64>,
    phi: DMatrix<f64>,
}

impl ClosedData {
    /// The tree's buffers (shared with the closed-chain evaluation).
    pub(crate) fn tree_mut(&mut self) -> &mut Data {
        &mut self.tree
    }

    /// The buffers of `chain`'s evaluations.
    pub fn new(chain: &ClosedChain) -> ClosedData {
        let (n, p, nl) = (chain.dof(), chain.n_equations(), chain.robot().nl());
        ClosedData {
            n,
            p,
            nl,
            tree: Data::new(chain.robot()),
            lw: chain.closure.workspace(),
            q_tr: vec![0.0; nl],
            qd_tr: vec![0.0; nl],
            qdd_tr: vec![0.0; nl],
            tau_tr: vec![0.0; nl],
            r: DVector::zeros(p),
            jac: DMatrix::zeros(p, nl),
            lu: SmallLu::new(p),
            w: DMatrix::zeros(p, n),
            g: DMatrix::zeros(nl, n),
            psi: DVector::zeros(p),
            qa: vec![0.0; n],
            qp: vec![0.0; p],
            pred: vec![0.0; p],
            dx: vec![0.0; p],
            start_qa: vec![0.0; n],
            start_qp: vec![0.0; p],
            start_w: DMatrix::zeros(p, n),
            start_rcond: 0.0,
            pred_step: 0.0,
            saved: Branch::zeros(n, p),
            probe: Branch::zeros(n, p),
            target: vec![0.0; n],
            turn_end: vec![0.0; n],
            turning: Vec::with_capacity(n),
            a_cl: DMatrix::zeros(n, n),
            chol: DMatrix::zeros(n, n),
            h_cl: DVector::zeros(n),
            ag: DMatrix::zeros(nl, n),
            v_nl: DVector::zeros(nl),
            col_n: DVector::zeros(n),
            zeros_n: vec![0.0; n],
            phi: DMatrix::zeros(0, 0),
        }
    }
}

impl ClosedChain {
    /// The closed-chain model of `robot`: chooses the independent closure equations of each
    /// loop by rank (see [`crate::algorithms::loop_closure`]) and checks that they are as many as
    /// the passive joints. Error for a tree or a wrong number of actuators.
    pub fn new(robot: &Robot) -> Result<ClosedChain> {
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

    /// A tracker on the branch of the robot's assembly configuration (its `assembly`, else
    /// q = 0). Errors: [`Error::LoopNotClosed`] when the loops do not close near it,
    /// [`Error::SingularStart`] when the robot has no assembly and Wp is singular at q = 0
    /// (the start does not define a branch), [`Error::Singular`] for a singular assembly.
    pub fn assembly_branch(&self) -> Result<Branch> {
        let robot = self.robot();
        let reference = robot
            .description()
            .assembly
            .clone()
            .unwrap_or_else(|| vec![0.0; robot.nl()]);
        let qa: Vec<f64> = self
            .coords
            .frames()
            .iter()
            .map(|&j| reference[j - 1])
            .collect();
        let qp: Vec<f64> = self
            .passive
            .frames()
            .iter()
            .map(|&j| reference[j - 1])
            .collect();
        match self.branch_from(&qa, &qp) {
            Err(Error::Singular { rcond, .. }) if robot.description().assembly.is_none() => {
                Err(Error::SingularStart {
                    robot: robot.name().to_string(),
                    rcond,
                })
            }
            r => r,
        }
    }

    /// A tracker on the branch through (q_a, q_p ≈ `q_p_guess`): the loops are closed at q_a
    /// from the guess (damped Newton) and Wp must be regular there. Allocates.
    pub fn branch_from(&self, q_a: &[f64], q_p_guess: &[f64]) -> Result<Branch> {
        self.coords.check("q_a", q_a, "actuated joints")?;
        self.passive
            .check("q_p guess", q_p_guess, "passive joints")?;
        let mut d = ClosedData::new(self);
        let sol = self.closure.solve_from_guess(&mut d.lw, q_a, q_p_guess)?;
        d.qa.copy_from_slice(q_a);
        d.qp.copy_from_slice(&sol.q_p);
        self.closure.assemble(&d.qa, &d.qp, &mut d.q_tr);
        self.factor_wp(&mut d);
        let rcond = d.lu.rcond();
        if rcond < self.limits.wp_hard {
            return Err(self.singular_wp(rcond, &d.q_tr));
        }
        let mut b = Branch {
            q_a: q_a.to_vec(),
            q_p: sol.q_p,
            w: DMatrix::zeros(self.n_equations(), self.dof()),
            sign: d.lu.det_sign(),
            rcond,
        };
        self.compute_w(&mut d);
        b.w.copy_from(&d.w);
        Ok(b)
    }

    fn singular_wp(&self, rcond: f64, q_tr: &[f64]) -> Error {
        let labels: Vec<String> = self.loops().iter().map(|l| l.label()).collect();
        Error::Singular {
            what: format!(
                "Wp (derivative of the closure equations of {} with respect to the passive \
                 joints {:?})",
                labels.join(", "),
                self.passive.frames()
            ),
            rcond,
            limit: self.limits.wp_hard,
            at: Configuration::Joints {
                name: "q_tr",
                values: q_tr.to_vec(),
            },
            hint: "the mechanism is at a singular configuration: q_p is not determined by q_a"
                .into(),
        }
    }

    fn check_data(&self, d: &ClosedData, b: &Branch) -> Result<()> {
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

    /// Kinematics at d.q_tr, the constraint Jacobian and the LU of Wp (in d.lu).
    fn factor_wp(&self, d: &mut ClosedData) {
        let lc = &self.closure;
        lc.kinematics(&mut d.lw, &d.q_tr, None, None);
        lc.constraint_jacobian(&mut d.lw, &mut d.jac);
        for (c, &j) in lc.passive_joints().iter().enumerate() {
            for r in 0..d.p {
                d.lu.lu[(r, c)] = d.jac[(r, j - 1)];
            }
        }
        d.lu.factor();
    }

    /// W = -Wp^-1 Wa into d.w (after [`Self::factor_wp`]) and G = [I; W] into d.g (tree rows).
    fn compute_w(&self, d: &mut ClosedData) {
        let lc = &self.closure;
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            for r in 0..d.p {
                d.w[(r, c)] = -d.jac[(r, j - 1)];
            }
        }
        let mut w = std::mem::replace(&mut d.w, DMatrix::zeros(0, 0));
        d.lu.solve_matrix(&mut w);
        d.w = w;
        d.g.as_mut_slice().fill(0.0);
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            d.g[(j - 1, c)] = 1.0;
        }
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            for c in 0..d.n {
                d.g[(j - 1, c)] = d.w[(r, c)];
            }
        }
    }

    fn conditioning(&self, b: &Branch, a_cl: Option<f64>) -> Conditioning {
        let l = &self.limits;
        Conditioning {
            wp: b.rcond,
            a_cl,
            warning: b.rcond < l.wp_soft || a_cl.is_some_and(|a| a < l.a_cl_soft),
        }
    }

    /// Check the inputs, move the tracker to q_a and fill the consistent tree state for
    /// (qd_a, qdd_a) into d.q_tr, d.qd_tr, d.qdd_tr (10.29, 10.42).
    fn state_into(&self, d: &mut ClosedData, b: &mut Branch, x: [(&str, &[f64]); 3]) -> Result<()> {
        self.check_data(d, b)?;
        for (name, v) in x {
            self.coords.check(name, v, "actuated joints")?;
        }
        let (q_a, qd_a, qdd_a) = (x[0].1, x[1].1, x[2].1);
        self.track(d, b, q_a)?;
        let lc = &self.closure;
        lc.assemble(&b.q_a, &b.q_p, &mut d.q_tr);
        for r in 0..d.nl {
            let (mut v, mut a) = (0.0, 0.0);
            for c in 0..d.n {
                v += d.g[(r, c)] * qd_a[c];
                a += d.g[(r, c)] * qdd_a[c];
            }
            d.qd_tr[r] = v;
            d.qdd_tr[r] = a;
        }
        lc.kinematics(&mut d.lw, &d.q_tr, Some(&d.qd_tr), None);
        lc.psi(&d.lw, &mut d.psi);
        // qdd_p += -Wp^-1 Ψ (10.42)
        for (x, p) in d.dx.iter_mut().zip(d.psi.iter()) {
            *x = -p;
        }
        d.lu.solve(&mut d.dx);
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            d.qdd_tr[j - 1] += d.dx[r];
        }
        Ok(())
    }

    /// Γ_cl = G^T Γ_tr into `out` after [`Self::state_into`] and the tree torques in d.tau_tr.
    fn project(d: &ClosedData, tree: &[f64], out: &mut [f64]) {
        for (c, o) in out.iter_mut().enumerate() {
            *o = (0..d.nl).map(|r| d.g[(r, c)] * tree[r]).sum();
        }
    }

    /// A_tr (composite links, into `d.tree.a`) at `d.q_tr` and A_cl = G^T A_tr G (10.46) into
    /// `d.a_cl`, G of the tracker's point (small products written out: nalgebra's gemm packs its
    /// operands on the heap).
    fn a_cl_into(&self, d: &mut ClosedData) {
        let mut a_tr = std::mem::replace(&mut d.tree.a, DMatrix::zeros(0, 0));
        composite_inertia_matrix(self.robot().numeric(), &mut d.tree, &d.q_tr, &mut a_tr);
        mul_into(&a_tr, &d.g, &mut d.ag);
        tr_mul_into(&d.g, &d.ag, &mut d.a_cl);
        d.tree.a = a_tr;
    }

    fn direct_into(
        &self,
        d: &mut ClosedData,
        b: &mut Branch,
        env: &Environment,
        x: [&[f64]; 3],
        coulomb_smoothing: Option<f64>,
        qdd_a: &mut [f64],
    ) -> Result<Conditioning> {
        env.check(self.robot().nl())?;
        self.coords
            .check_output("qdd_a", qdd_a, "actuated joints")?;
        self.coords.check("tau", x[2], "actuated joints")?;
        // the consistent state with qdd_a = 0: qdd_tr = [0; -Wp^-1 Ψ]
        let z = std::mem::take(&mut d.zeros_n);
        let r = self.state_into(d, b, [("q_a", x[0]), ("qd_a", x[1]), ("qdd_a", &z)]);
        d.zeros_n = z;
        r?;
        let model = self.robot().numeric();
        // A_tr by composite links and A_cl = G^T A_tr G (10.46); H_tr = Γ_tr(q, qd, 0) (10.32)
        self.a_cl_into(d);
        let a_tr = std::mem::replace(&mut d.tree.a, DMatrix::zeros(0, 0));
        let z = std::mem::take(&mut d.tree.zeros);
        rnea_with_environment(
            model,
            &mut d.tree,
            env,
            &d.q_tr,
            &d.qd_tr,
            &z,
            &mut d.tau_tr,
        );
        d.tree.zeros = z;
        if let Some(v) = coulomb_smoothing.filter(|v| *v > 0.0) {
            for &j in self.robot().coordinates().frames() {
                let s = d.qd_tr[j - 1];
                d.tau_tr[j - 1] -= model.link(j).fs * (s.sign() - (s / v).tanh());
            }
        }
        // (10.47): H_cl = G^T (H_tr + A_tr qdd0)
        for r in 0..d.nl {
            let mut v = d.tau_tr[r];
            for c in 0..d.nl {
                v += a_tr[(r, c)] * d.qdd_tr[c];
            }
            d.v_nl[r] = v;
        }
        d.tree.a = a_tr;
        d.h_cl.gemv_tr(1.0, &d.g, &d.v_nl, 0.0);
        d.chol.copy_from(&d.a_cl);
        let buf = std::mem::replace(&mut d.chol, DMatrix::zeros(0, 0));
        let Some(chol) = nalgebra::Cholesky::new(buf) else {
            d.chol = DMatrix::zeros(d.n, d.n);
            return Err(self.singular_a_cl(0.0, &d.q_tr));
        };
        let rcond = rcond_cholesky(&chol, norm1(&d.a_cl), &mut d.col_n);
        if rcond < self.limits.a_cl_hard {
            d.chol = chol.unpack_dirty();
            return Err(self.singular_a_cl(rcond, &d.q_tr));
        }
        for c in 0..d.n {
            d.col_n[c] = x[2][c] - d.h_cl[c];
        }
        chol.solve_mut(&mut d.col_n);
        d.chol = chol.unpack_dirty();
        qdd_a.copy_from_slice(d.col_n.as_slice());
        // (10.42): qdd_p = W qdd_a - Wp^-1 Ψ (already in qdd_tr's passive rows)
        let lc = &self.closure;
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            d.qdd_tr[j - 1] = qdd_a[c];
        }
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            let a: f64 = (0..d.n).map(|c| d.w[(r, c)] * qdd_a[c]).sum();
            d.qdd_tr[j - 1] += a;
        }
        Ok(self.conditioning(b, Some(rcond)))
    }

    fn singular_a_cl(&self, rcond: f64, q_tr: &[f64]) -> Error {
        Error::Singular {
            what: "the closed-chain inertia matrix A_cl (10.46)".into(),
            rcond,
            limit: self.limits.a_cl_hard,
            at: Configuration::Joints {
                name: "q_tr",
                values: q_tr.to_vec(),
            },
            hint: "check masses and inertias, or the configuration is singular".into(),
        }
    }

    /// Tree vector (NL) over the movable joints of the equivalent tree.
    fn tree_vector(&self, v: &[f64]) -> DVector<f64> {
        let c = self.robot().coordinates();
        DVector::from_iterator(c.len(), c.frames().iter().map(|&j| v[j - 1]))
    }

    fn state_result(&self, d: &ClosedData, b: &Branch, cond: Conditioning) -> ClosedState {
        let c = self.robot().coordinates();
        let lc = &self.closure;
        let g = DMatrix::from_fn(c.len(), d.n, |r, col| d.g[(c.frame(r) - 1, col)]);
        let wa = DMatrix::from_fn(d.p, d.n, |r, col| d.jac[(r, lc.actuated_joints()[col] - 1)]);
        let wp = DMatrix::from_fn(d.p, d.p, |r, col| d.jac[(r, lc.passive_joints()[col] - 1)]);
        ClosedState {
            q_a: DVector::from_column_slice(&b.q_a),
            q_p: DVector::from_column_slice(&b.q_p),
            q: self.tree_vector(&d.q_tr),
            qd: self.tree_vector(&d.qd_tr),
            qdd: self.tree_vector(&d.qdd_tr),
            psi: d.psi.clone(),
            wa,
            wp,
            w: d.w.clone(),
            g,
            conditioning: cond,
        }
    }
}

/// A closed configuration on the tracker's branch.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosureSolution {
    /// q_a (actuated joints).
    pub q_a: DVector<f64>,
    /// q_p (passive joints, [`ClosedChain::passive_coordinates`]).
    pub q_p: DVector<f64>,
    /// Cut-joint variables q_c (NL+1..NJ), rad or m.
    pub q_c: DVector<f64>,
    /// q_tr over the movable joints of the equivalent tree.
    pub q_tree: DVector<f64>,
    /// W = d q_p / d q_a (p x N, 10.30).
    pub w: DMatrix<f64>,
    /// Largest residual of all candidate closure equations (m or rad).
    pub residual: f64,
    /// Conditioning of Wp.
    pub conditioning: Conditioning,
}

/// A consistent state of the equivalent tree (10.29, 10.42) with its constraint matrices.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedState {
    /// q_a.
    pub q_a: DVector<f64>,
    /// q_p.
    pub q_p: DVector<f64>,
    /// q_tr over the movable joints of the equivalent tree.
    pub q: DVector<f64>,
    /// qd_tr = G qd_a.
    pub qd: DVector<f64>,
    /// qdd_tr = G qdd_a + [0; -Wp^-1 Ψ].
    pub qdd: DVector<f64>,
    /// Ψ of (10.28) (p entries).
    pub psi: DVector<f64>,
    /// Wa (p x N), columns in actuated order.
    pub wa: DMatrix<f64>,
    /// Wp (p x p), columns in passive order.
    pub wp: DMatrix<f64>,
    /// W = -Wp^-1 Wa (p x N).
    pub w: DMatrix<f64>,
    /// G = d q_tr / d q_a (movable joints x N).
    pub g: DMatrix<f64>,
    /// Conditioning of Wp.
    pub conditioning: Conditioning,
}

/// Result of the closed-chain inverse dynamic model.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedIdm {
    /// Γ_cl (N), actuated order: G^T Γ_tr (10.40).
    pub gamma_cl: DVector<f64>,
    /// Γ_tr (movable joints of the tree) at the consistent state.
    pub gamma_tr: DVector<f64>,
    /// Lagrange multipliers λ = -Wp^-T Γ_p (10.37): the cut-joint reactions along the kept
    /// closure equations.
    pub lambda: DVector<f64>,
    /// Γ_cl by the multiplier form Γ_a + Wa^T λ (10.36).
    pub gamma_cl_lagrange: DVector<f64>,
    /// The consistent state.
    pub state: ClosedState,
}

/// Result of the closed-chain direct dynamic model.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedDdm {
    /// qdd_a (10.48).
    pub qdd_a: DVector<f64>,
    /// qdd_p (10.42).
    pub qdd_p: DVector<f64>,
    /// A_cl (10.46).
    pub a_cl: DMatrix<f64>,
    /// H_cl (10.47).
    pub h_cl: DVector<f64>,
    /// The consistent state (qdd with the computed qdd_a).
    pub state: ClosedState,
    /// Conditioning of Wp and A_cl.
    pub conditioning: Conditioning,
}

/// Loop closure on the tracker's branch into `q_p` (passive joints): moves `branch` to `q_a`
/// (actuated joints, rad or m). Allocation-free on the branch.
///
/// Errors: [`Error::Dimension`] / [`Error::NotFinite`] for bad inputs, [`Error::BranchLost`]
/// when q_a cannot be reached on the branch, [`Error::Singular`] when Wp is singular at q_a.
pub fn loop_closure_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    q_a: &[f64],
    q_p: &mut [f64],
) -> Result<Conditioning> {
    chain.check_data(data, branch)?;
    chain.coords.check("q_a", q_a, "actuated joints")?;
    chain.passive.check_output("q_p", q_p, "passive joints")?;
    chain.track(data, branch, q_a)?;
    q_p.copy_from_slice(&branch.q_p);
    Ok(chain.conditioning(branch, None))
}

/// Loop closure on the tracker's branch: q_p, the cut-joint variables, W and the conditioning
/// at q_a. Allocates.
///
/// # Example
///
/// A four-bar linkage (`robots/fourbar.toml`: crank 1 actuated, joints 2 and 3 passive, cut
/// joint 4 with its twin frame 5 on the rocker) driven to crank angles far apart: each is
/// reached from the previous one on the same assembly branch, and the cut joint's frame 4 meets
/// its twin 5.
///
/// ```
/// use robodyn::{geometry::frame_transforms_with_cuts, loop_closure, ClosedChain};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/fourbar.toml");
/// let robot = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&robot)?;
/// let mut branch = chain.assembly_branch()?; // closed at q = 0
/// for q1 in [2.5, -2.0, 0.7] {
///     let s = loop_closure(&chain, &mut branch, &[q1])?;
///     assert!(!s.conditioning.warning);
///     // an independent check: compose the frames of the tree (joints 1..3, cut joint 4)
///     let t = frame_transforms_with_cuts(&robot, s.q_tree.as_slice(), s.q_c.as_slice())?;
///     assert!((t[3].pos - t[4].pos).norm() < 1e-9); // O_4 = O_5
///     println!("q1 = {q1}: q_p = {}, W = {}", s.q_p, s.w);
/// }
/// # Ok(())
/// # }
/// ```
pub fn loop_closure(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
) -> Result<ClosureSolution> {
    let mut d = ClosedData::new(chain);
    let mut q_p = vec![0.0; chain.n_equations()];
    let cond = loop_closure_into(chain, &mut d, branch, q_a, &mut q_p)?;
    let lc = &chain.closure;
    lc.assemble(&branch.q_a, &branch.q_p, &mut d.q_tr);
    lc.kinematics(&mut d.lw, &d.q_tr, None, None);
    Ok(ClosureSolution {
        q_a: DVector::from_column_slice(q_a),
        q_p: DVector::from_vec(q_p),
        q_c: DVector::from_vec(lc.cut_variables(&d.lw)),
        q_tree: chain.tree_vector(&d.q_tr),
        w: d.w.clone(),
        residual: lc.max_residual(&d.lw),
        conditioning: cond,
    })
}

/// The consistent tree state for (q_a, qd_a, qdd_a) on the tracker's branch: q_p by loop
/// closure, qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Ψ (10.42). Allocates.
pub fn closed_state(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
) -> Result<ClosedState> {
    let mut d = ClosedData::new(chain);
    chain.state_into(
        &mut d,
        branch,
        [("q_a", q_a), ("qd_a", qd_a), ("qdd_a", qdd_a)],
    )?;
    let cond = chain.conditioning(branch, None);
    Ok(chain.state_result(&d, branch, cond))
}

/// Closed-chain inverse dynamic model into `tau_a`: Γ_cl = G^T Γ_tr (10.40, N m or N) of the
/// actuated joints for q_a, qd_a, qdd_a (actuated joints) under `env`, on the tracker's branch.
/// Allocation-free on the branch. Returns the conditioning of Wp (check `warning`).
///
/// # Example
///
/// Torques of the Acma SR400 (a parallelogram loop, Example 10.1) along a trajectory, with the
/// buffers and the branch tracker made once:
///
/// ```
/// use robodyn::{closed_inverse_dynamics_into, ClosedChain, ClosedData};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
/// let sr400 = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&sr400)?; // vectors over the actuated joints 1, 2, 4, 5, 6, 7
/// let mut data = ClosedData::new(&chain);
/// let mut branch = chain.assembly_branch()?; // the parallelogram assembly of the file
/// let mut gamma = vec![0.0; chain.dof()];
/// for k in 0..100 {
///     let s = k as f64 * 0.01;
///     let q_a = [0.1 + s, 0.2 - s, 0.3, 0.4, 0.5 + s, 1.6];
///     let cond = closed_inverse_dynamics_into(
///         &chain, &mut data, &mut branch, sr400.environment(),
///         &q_a, &[0.1; 6], &[0.0; 6], &mut gamma,
///     )?;
///     assert!(!cond.warning, "near a singular configuration: {cond:?}");
/// }
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn closed_inverse_dynamics_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    env: &Environment,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
    tau_a: &mut [f64],
) -> Result<Conditioning> {
    env.check(chain.robot().nl())?;
    chain
        .coords
        .check_output("tau_a", tau_a, "actuated joints")?;
    chain.state_into(
        data,
        branch,
        [("q_a", q_a), ("qd_a", qd_a), ("qdd_a", qdd_a)],
    )?;
    let d = data;
    rnea_with_environment(
        chain.robot().numeric(),
        &mut d.tree,
        env,
        &d.q_tr,
        &d.qd_tr,
        &d.qdd_tr,
        &mut d.tau_tr,
    );
    ClosedChain::project(d, &d.tau_tr, tau_a);
    Ok(chain.conditioning(branch, None))
}

/// Closed-chain inverse dynamic model with the robot's environment: Γ_cl, Γ_tr, the Lagrange
/// multipliers (10.37) and the consistent state. Allocates.
pub fn closed_inverse_dynamics(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
) -> Result<ClosedIdm> {
    let mut d = ClosedData::new(chain);
    let mut gamma_cl = DVector::zeros(chain.dof());
    let cond = closed_inverse_dynamics_into(
        chain,
        &mut d,
        branch,
        chain.robot().environment(),
        q_a,
        qd_a,
        qdd_a,
        gamma_cl.as_mut_slice(),
    )?;
    let lc = &chain.closure;
    let gp: Vec<f64> = lc
        .passive_joints()
        .iter()
        .map(|&j| d.tau_tr[j - 1])
        .collect();
    // (10.37): Wp^T λ = -Γ_p
    let mut lambda: Vec<f64> = gp.iter().map(|x| -x).collect();
    d.lu.solve_transpose(&mut lambda);
    let lambda = DVector::from_vec(lambda);
    let state = chain.state_result(&d, branch, cond);
    let ga = DVector::from_iterator(
        chain.dof(),
        lc.actuated_joints().iter().map(|&j| d.tau_tr[j - 1]),
    );
    let gamma_cl_lagrange = ga + state.wa.transpose() * &lambda;
    Ok(ClosedIdm {
        gamma_cl,
        gamma_tr: chain.tree_vector(&d.tau_tr),
        lambda,
        gamma_cl_lagrange,
        state,
    })
}

/// Inertia matrix of the closed chain, A_cl = G^T A_tr G (10.46), N x N over the actuated
/// joints, at `q_a`: the loops closed on the branch tracker (continued from its point), A_tr by
/// composite links at the consistent tree configuration. Allocation-free; errors as
/// [`closed_direct_dynamics_into`] for the closure.
pub fn closed_inertia_matrix_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    q_a: &[f64],
    a_cl: &mut DMatrix<f64>,
) -> Result<Conditioning> {
    chain.check_data(data, branch)?;
    chain.coords.check("q_a", q_a, "actuated joints")?;
    let n = chain.dof();
    if a_cl.shape() != (n, n) {
        return Err(Error::dimension(
            "A_cl",
            n * n,
            a_cl.len(),
            format!("{n} x {n} (actuated joints)"),
        ));
    }
    chain.track(data, branch, q_a)?;
    chain
        .closure
        .assemble(&branch.q_a, &branch.q_p, &mut data.q_tr);
    chain.a_cl_into(data);
    a_cl.copy_from(&data.a_cl);
    Ok(chain.conditioning(branch, None))
}

/// Closed-chain direct dynamic model into `qdd_a`: qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.46–10.48,
/// rad/s² or m/s²) for q_a, qd_a and the actuated torques `tau_a` under `env`, on the tracker's
/// branch. Allocation-free on the branch. Returns the conditioning of Wp and A_cl.
#[allow(clippy::too_many_arguments)]
pub fn closed_direct_dynamics_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    env: &Environment,
    q_a: &[f64],
    qd_a: &[f64],
    tau_a: &[f64],
    qdd_a: &mut [f64],
) -> Result<Conditioning> {
    chain.direct_into(data, branch, env, [q_a, qd_a, tau_a], None, qdd_a)
}

/// [`closed_direct_dynamics_into`] with the Coulomb friction of every tree joint taken as
/// Fs tanh(qd / v) instead of Fs sign(qd) (the simulator's smoothing; v > 0).
#[allow(clippy::too_many_arguments)]
pub(crate) fn closed_direct_dynamics_smoothed(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    env: &Environment,
    x: [&[f64]; 3],
    coulomb_smoothing: Option<f64>,
    qdd_a: &mut [f64],
) -> Result<Conditioning> {
    chain.direct_into(data, branch, env, x, coulomb_smoothing, qdd_a)
}

/// Closed-chain direct dynamic model with the robot's environment: qdd_a, qdd_p, A_cl, H_cl and
/// the consistent state. Allocates.
pub fn closed_direct_dynamics(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    tau_a: &[f64],
) -> Result<ClosedDdm> {
    let mut d = ClosedData::new(chain);
    let mut qdd_a = DVector::zeros(chain.dof());
    let cond = chain.direct_into(
        &mut d,
        branch,
        chain.robot().environment(),
        [q_a, qd_a, tau_a],
        None,
        qdd_a.as_mut_slice(),
    )?;
    let lc = &chain.closure;
    let qdd_p = DVector::from_iterator(
        chain.n_equations(),
        lc.passive_joints().iter().map(|&j| d.qdd_tr[j - 1]),
    );
    Ok(ClosedDdm {
        qdd_a,
        qdd_p,
        a_cl: d.a_cl.clone(),
        h_cl: d.h_cl.clone(),
        state: chain.state_result(&d, branch, cond),
        conditioning: cond,
    })
}

/// Regressor of the closed chain into `phi` (N x 13 NL): G^T Φ (10.40), so that
/// Γ_cl = G^T Φ K + Γ_e,cl, and Γ_e,cl = G^T Γ_e into `tau_e` (actuated joints), for q_a, qd_a,
/// qdd_a on the tracker's branch under `env`. Allocation-free on the branch.
#[allow(clippy::too_many_arguments)]
pub fn closed_regressor_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    env: &Environment,
    x: [&[f64]; 3],
    phi: &mut DMatrix<f64>,
    tau_e: &mut [f64],
) -> Result<Conditioning> {
    env.check(chain.robot().nl())?;
    let (n, nl) = (chain.dof(), chain.robot().nl());
    if phi.shape() != (n, PARAMS_PER_LINK * nl) {
        return Err(Error::dimension(
            "Phi",
            n * PARAMS_PER_LINK * nl,
            phi.len(),
            format!(
                "{n} x {} (actuated joints x 13 per link)",
                PARAMS_PER_LINK * nl
            ),
        ));
    }
    chain
        .coords
        .check_output("tau_e", tau_e, "actuated joints")?;
    chain.state_into(
        data,
        branch,
        [("q_a", x[0]), ("qd_a", x[1]), ("qdd_a", x[2])],
    )?;
    let d = data;
    let model = chain.robot().numeric();
    let mut full = std::mem::replace(&mut d.phi, DMatrix::zeros(0, 0));
    if full.shape() != (nl, PARAMS_PER_LINK * nl) {
        full = DMatrix::zeros(nl, PARAMS_PER_LINK * nl); // first call only
    }
    tree_regressor(
        model,
        &mut d.tree,
        env,
        &d.q_tr,
        &d.qd_tr,
        &d.qdd_tr,
        &mut full,
    );
    tr_mul_into(&d.g, &full, phi);
    d.phi = full;
    tree_wrench_torques(model, &mut d.tree, env, &d.q_tr, &mut d.tau_tr);
    ClosedChain::project(d, &d.tau_tr, tau_e);
    Ok(chain.conditioning(branch, None))
}

/// Tree state (q_tr, qd_tr) of the last evaluation in `data`, over tree arrays (NL entries):
/// for the simulator's energy.
pub(crate) fn last_tree_state(data: &ClosedData) -> (&[f64], &[f64]) {
    (&data.q_tr, &data.qd_tr)
}

/// The closure residual (max over all loops' candidate equations) at the last evaluation.
pub(crate) fn last_residual(chain: &ClosedChain, data: &ClosedData) -> f64 {
    chain.closure.max_residual(&data.lw)
}

/// Newton steps on the kept closure equations (q_p -= Wp^-1 phi) beyond the closure tolerance,
/// until the residual stops decreasing: q_p at q_a to the rounding level (for the numerical
/// base parameters, whose rank decision would see the solver's 1e-12).
pub(crate) fn refine_closure(chain: &ClosedChain, q_a: &[f64], q_p: &[f64]) -> Vec<f64> {
    let lc = &chain.closure;
    let mut d = ClosedData::new(chain);
    let mut q_p = q_p.to_vec();
    let residual = |d: &mut ClosedData, q_p: &[f64]| {
        lc.assemble(q_a, q_p, &mut d.q_tr);
        chain.factor_wp(d);
        lc.residual(&d.lw, &mut d.r);
        d.r.amax()
    };
    let mut norm = residual(&mut d, &q_p);
    for _ in 0..6 {
        if norm == 0.0 || !d.lu.regular {
            break;
        }
        let mut step: Vec<f64> = d.r.iter().copied().collect();
        d.lu.solve(&mut step);
        let trial: Vec<f64> = q_p.iter().zip(&step).map(|(a, b)| a - b).collect();
        let nt = residual(&mut d, &trial);
        if nt >= norm {
            break;
        }
        q_p = trial;
        norm = nt;
    }
    q_p
}

/// out = a b (dense, written out: no heap packing).
fn mul_into(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    for c in 0..b.ncols() {
        for r in 0..a.nrows() {
            out[(r, c)] = (0..a.ncols()).map(|k| a[(r, k)] * b[(k, c)]).sum();
        }
    }
}

/// out = a^T b (dense, written out: no heap packing).
fn tr_mul_into(a: &DMatrix<f64>, b: &DMatrix<f64>, out: &mut DMatrix<f64>) {
    for c in 0..b.ncols() {
        for r in 0..a.ncols() {
            out[(r, c)] = (0..a.nrows()).map(|k| a[(k, r)] * b[(k, c)]).sum();
        }
    }
}
