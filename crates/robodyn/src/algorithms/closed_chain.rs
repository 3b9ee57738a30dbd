//! Dynamic models of robots with closed kinematic chains (§10.3.2–10.3.3): the equivalent tree's
//! Newton–Euler model projected on the actuated joints.
//!
//! - kinematic constraints: W = -Wp^-1 Wa (10.30), G = d q_tr / d q_a (rows by joint number,
//!   10.40), qd_p = W qd_a (10.29), qdd_p = W qdd_a - Wp^-1 Ψ (10.42);
//! - inverse model: Γ_cl = G^T Γ_tr (10.40), Lagrange multipliers λ = -Wp^-T Γ_p (10.37) and
//!   Γ_cl = Γ_a + Wa^T λ (10.36, upper part);
//! - direct model: A_cl (10.46), H_cl (10.47), qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.48, Cholesky).
//!
//! [`ClosedChain`] is the immutable model (built once from a [`Robot`]); [`ClosedChainWorkspace`]
//! holds the buffers and the previous closure solution (the next solve's guess).

use crate::algorithms::inertia_matrix::{inertia_matrix_into, InertiaWorkspace};
use crate::algorithms::inverse_dynamics::rnea;
use crate::algorithms::loop_closure::{ClosureSolution, LoopClosure, LoopWorkspace};
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::workspace::Workspace;
use nalgebra::{DMatrix, DVector};

/// Closed-chain dynamic model: loop closure plus the equivalent tree.
#[derive(Clone, Debug)]
pub struct ClosedChain {
    closure: LoopClosure,
}

/// Buffers of the closed-chain models.
#[derive(Clone, Debug)]
pub struct ClosedChainWorkspace {
    pub closure: LoopWorkspace,
    pub tree: Workspace<f64>,
    tau: Vec<f64>,
    zeros: Vec<f64>,
    inertia: InertiaWorkspace<f64>,
    a_tr: DMatrix<f64>,
}

/// Constraint matrices at a closed configuration (eqs 10.27–10.30, 10.40).
#[derive(Clone, Debug)]
pub struct Constraints {
    /// Wa (p x N), columns in actuated-joint order.
    pub wa: DMatrix<f64>,
    /// Wp (p x p), columns in passive-joint order.
    pub wp: DMatrix<f64>,
    /// W = -Wp^-1 Wa (p x N).
    pub w: DMatrix<f64>,
    /// G = d q_tr / d q_a (NL x N), rows by joint number (fixed frames zero).
    pub g: DMatrix<f64>,
    wp_lu: nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>,
}

impl Constraints {
    /// Wp^-1 x.
    pub fn wp_solve(&self, x: &DVector<f64>) -> DVector<f64> {
        self.wp_lu.solve(x).expect("Wp checked regular")
    }
}

/// A consistent state of the equivalent tree: q_tr, qd_tr, qdd_tr (NL entries, by joint number).
#[derive(Clone, Debug)]
pub struct ClosedState {
    pub closure: ClosureSolution,
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// Ψ of (10.28).
    pub psi: DVector<f64>,
    pub constraints: Constraints,
}

/// Result of the closed-chain inverse dynamic model.
#[derive(Clone, Debug)]
pub struct ClosedIdm {
    /// Γ_cl (N), actuated-joint order: G^T Γ_tr (10.40).
    pub gamma_cl: DVector<f64>,
    /// Γ_tr (NL, by joint number) of the equivalent tree at the consistent state.
    pub gamma_tr: DVector<f64>,
    /// Lagrange multipliers λ = -Wp^-T Γ_p (10.37): the cut-joint reactions along the kept
    /// closure equations.
    pub lambda: DVector<f64>,
    /// Γ_cl by the multiplier form Γ_a + Wa^T λ (10.36).
    pub gamma_cl_lagrange: DVector<f64>,
    pub state: ClosedState,
}

/// Result of the closed-chain direct dynamic model.
#[derive(Clone, Debug)]
pub struct ClosedDdm {
    /// qdd_a (10.48).
    pub qdd_a: DVector<f64>,
    /// qdd_p (10.42).
    pub qdd_p: DVector<f64>,
    /// A_cl (10.46) and H_cl (10.47).
    pub a_cl: DMatrix<f64>,
    pub h_cl: DVector<f64>,
    pub state: ClosedState,
}

impl ClosedChain {
    /// Build the model of a closed-chain robot (see [`LoopClosure::new`] for the checks).
    pub fn new(robot: &Robot) -> Result<ClosedChain> {
        let closure = LoopClosure::new(robot)?;
        Ok(ClosedChain { closure })
    }

    pub fn closure(&self) -> &LoopClosure {
        &self.closure
    }

    pub fn robot(&self) -> &Robot {
        self.closure.robot()
    }

    /// N, the degrees of freedom (number of actuated joints).
    pub fn dof(&self) -> usize {
        self.closure.dof()
    }

    pub fn actuated_joints(&self) -> &[usize] {
        self.closure.actuated_joints()
    }

    pub fn passive_joints(&self) -> &[usize] {
        self.closure.passive_joints()
    }

    pub fn workspace(&self) -> ClosedChainWorkspace {
        let nl = self.robot().nl();
        ClosedChainWorkspace {
            closure: self.closure.workspace(),
            tree: Workspace::new(self.robot().numeric()),
            tau: vec![0.0; nl],
            zeros: vec![0.0; nl],
            inertia: InertiaWorkspace::new(self.robot().numeric()),
            a_tr: DMatrix::zeros(nl, nl),
        }
    }

    /// q_p for q_a (damped Newton from `guess`, else the previous solution, else zeros).
    pub fn solve_positions(
        &self,
        ws: &mut ClosedChainWorkspace,
        q_a: &[f64],
        guess: Option<&[f64]>,
    ) -> Result<ClosureSolution> {
        self.closure.solve(&mut ws.closure, q_a, guess)
    }

    /// The reference configuration q_tr (NL entries): the description's `assembly`, else zeros.
    pub fn reference(&self) -> Vec<f64> {
        self.robot()
            .description()
            .assembly
            .clone()
            .unwrap_or_else(|| vec![0.0; self.robot().nl()])
    }

    /// The actuated values (q_a) of the reference configuration [`ClosedChain::reference`].
    pub fn reference_actuated(&self) -> Vec<f64> {
        let r = self.reference();
        self.actuated_joints().iter().map(|&j| r[j - 1]).collect()
    }

    /// q_p for q_a on the reference assembly branch (the default start of loop closure). With
    /// a `guess`, damped Newton from it. Without: when the loops close at the reference
    /// configuration (the file's `assembly`, else q = 0), by continuation (16 steps) from there,
    /// so that the answer lies on the reference branch; otherwise damped Newton from the
    /// reference q_p.
    pub fn solve_from_reference(
        &self,
        ws: &mut ClosedChainWorkspace,
        q_a: &[f64],
        guess: Option<&[f64]>,
    ) -> Result<ClosureSolution> {
        if guess.is_some() {
            return self.solve_positions(ws, q_a, guess);
        }
        let reference = self.reference();
        let ref_a = self.reference_actuated();
        let ref_p: Vec<f64> = self
            .passive_joints()
            .iter()
            .map(|&j| reference[j - 1])
            .collect();
        let lc = &self.closure;
        if q_a.len() == self.dof() {
            if let Ok(s0) = lc.solve(&mut ws.closure, &ref_a, Some(&ref_p)) {
                if s0.iterations == 0 {
                    return lc.solve_continuation(&mut ws.closure, q_a, &ref_a, &ref_p, 16);
                }
            }
        }
        self.solve_positions(ws, q_a, Some(&ref_p))
    }

    /// Wa, Wp, W and G at a closed configuration q_tr (error if Wp is singular).
    pub fn constraints(&self, ws: &mut ClosedChainWorkspace, q_tr: &[f64]) -> Result<Constraints> {
        let lc = &self.closure;
        let (p, nl) = (lc.n_equations(), self.robot().nl());
        lc.kinematics(&mut ws.closure, q_tr, None, None);
        let mut jac = DMatrix::zeros(p, nl);
        lc.constraint_jacobian(&ws.closure, &mut jac);
        let wa = jac.select_columns(lc.actuated_columns().iter());
        let wp = jac.select_columns(lc.passive_columns().iter());
        lc.check_wp(&wp, q_tr)?;
        let wp_lu = wp.clone().lu();
        let w = -wp_lu
            .solve(&wa)
            .ok_or_else(|| Error::Numerical(format!("Wp is singular at q_tr = {q_tr:?}")))?;
        let n = lc.dof();
        let mut g = DMatrix::zeros(nl, n);
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            g[(j - 1, c)] = 1.0;
        }
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            g.row_mut(j - 1).copy_from(&w.row(r));
        }
        Ok(Constraints {
            wa,
            wp,
            w,
            g,
            wp_lu,
        })
    }

    fn check(&self, name: &str, v: &[f64]) -> Result<()> {
        let n = self.dof();
        if v.len() != n {
            return Err(Error::Input(format!(
                "{name} has {} entries, the robot has {n} actuated joints {:?}",
                v.len(),
                self.actuated_joints()
            )));
        }
        if let Some(k) = v.iter().position(|x| !x.is_finite()) {
            return Err(Error::Input(format!(
                "{name}[{}] (joint {}) = {} is not a finite number",
                k + 1,
                self.actuated_joints()[k],
                v[k]
            )));
        }
        Ok(())
    }

    /// The consistent tree state for (q_a, qd_a, qdd_a): q_p by loop closure, qd_p = W qd_a
    /// (10.29), qdd_p = W qdd_a - Wp^-1 Ψ (10.42).
    pub fn state(
        &self,
        ws: &mut ClosedChainWorkspace,
        q_a: &[f64],
        qd_a: &[f64],
        qdd_a: &[f64],
        guess: Option<&[f64]>,
    ) -> Result<ClosedState> {
        self.check("q_a", q_a)?;
        self.check("qd_a", qd_a)?;
        self.check("qdd_a", qdd_a)?;
        let sol = self.solve_positions(ws, q_a, guess)?;
        let q = sol.q_tr.clone();
        let c = self.constraints(ws, &q)?;
        let qd_col = &c.g * DVector::from_column_slice(qd_a);
        let qd: Vec<f64> = qd_col.iter().copied().collect();
        let lc = &self.closure;
        let mut psi = DVector::zeros(lc.n_equations());
        lc.kinematics(&mut ws.closure, &q, Some(&qd), None);
        lc.psi(&ws.closure, &mut psi);
        let qdd_p0 = -c.wp_solve(&psi);
        let mut qdd: Vec<f64> = (&c.g * DVector::from_column_slice(qdd_a))
            .iter()
            .copied()
            .collect();
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            qdd[j - 1] += qdd_p0[r];
        }
        Ok(ClosedState {
            closure: sol,
            q,
            qd,
            qdd,
            psi,
            constraints: c,
        })
    }

    /// Inverse dynamic model: Γ_cl = G^T Γ_tr (10.40) with Γ_tr by Newton–Euler at the consistent
    /// tree state, and the Lagrange multipliers (10.37).
    pub fn inverse_dynamics(
        &self,
        ws: &mut ClosedChainWorkspace,
        q_a: &[f64],
        qd_a: &[f64],
        qdd_a: &[f64],
        guess: Option<&[f64]>,
    ) -> Result<ClosedIdm> {
        let state = self.state(ws, q_a, qd_a, qdd_a, guess)?;
        rnea(
            self.robot().numeric(),
            &mut ws.tree,
            &state.q,
            &state.qd,
            &state.qdd,
            &mut ws.tau,
        );
        let gamma_tr = DVector::from_column_slice(&ws.tau);
        let c = &state.constraints;
        let gamma_cl = c.g.transpose() * &gamma_tr;
        let gp = DVector::from_iterator(
            self.passive_joints().len(),
            self.passive_joints().iter().map(|j| gamma_tr[j - 1]),
        );
        let ga = DVector::from_iterator(
            self.dof(),
            self.actuated_joints().iter().map(|j| gamma_tr[j - 1]),
        );
        // (10.37): Wp^T λ = -Γ_p
        let lambda = -c
            .wp
            .transpose()
            .lu()
            .solve(&gp)
            .ok_or_else(|| Error::Numerical("Wp^T is singular".into()))?;
        let gamma_cl_lagrange = ga + c.wa.transpose() * &lambda;
        Ok(ClosedIdm {
            gamma_cl,
            gamma_tr,
            lambda,
            gamma_cl_lagrange,
            state,
        })
    }

    /// Direct dynamic model: qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.46–10.48) and qdd_p (10.42).
    pub fn direct_dynamics(
        &self,
        ws: &mut ClosedChainWorkspace,
        q_a: &[f64],
        qd_a: &[f64],
        tau_a: &[f64],
        guess: Option<&[f64]>,
    ) -> Result<ClosedDdm> {
        self.direct_dynamics_smoothed(ws, q_a, qd_a, tau_a, guess, None)
    }

    /// [`ClosedChain::direct_dynamics`] with the Coulomb friction of every tree joint (actuated
    /// and passive) taken as Fs tanh(qd / v) instead of Fs sign(qd) when `coulomb_smoothing` is
    /// `Some(v)`, v > 0 (for simulation: the exact sign makes the right-hand side discontinuous).
    pub fn direct_dynamics_smoothed(
        &self,
        ws: &mut ClosedChainWorkspace,
        q_a: &[f64],
        qd_a: &[f64],
        tau_a: &[f64],
        guess: Option<&[f64]>,
        coulomb_smoothing: Option<f64>,
    ) -> Result<ClosedDdm> {
        use crate::scalar::DynScalar;
        self.check("tau", tau_a)?;
        let n = self.dof();
        let zero_a = vec![0.0; n];
        // state with qdd_a = 0: qdd_tr = [0; -Wp^-1 Ψ]
        let mut state = self.state(ws, q_a, qd_a, &zero_a, guess)?;
        // A_tr by composite links (rows/columns of fixed frames zero, Ia_j on the diagonal)
        inertia_matrix_into(
            self.robot().numeric(),
            &mut ws.inertia,
            &state.q,
            &mut ws.a_tr,
        );
        let a_tr = &ws.a_tr;
        // H_tr = Γ_tr(q, qd, 0) (10.32)
        rnea(
            self.robot().numeric(),
            &mut ws.tree,
            &state.q,
            &state.qd,
            &ws.zeros,
            &mut ws.tau,
        );
        let mut h_tr = DVector::from_column_slice(&ws.tau);
        if let Some(v) = coulomb_smoothing.filter(|v| *v > 0.0) {
            let model = self.robot().numeric();
            for j in self.robot().movable_joints() {
                let s = state.qd[j - 1];
                h_tr[j - 1] -= model.link(j).fs * (s.sign() - (s / v).tanh());
            }
        }
        let g = &state.constraints.g;
        // (10.46): A_cl = A_aa + A_ap W + W^T A_pa + W^T A_pp W = G^T A_tr G
        let a_cl = g.transpose() * a_tr * g;
        // (10.47): H_cl = H_a + W^T H_p - (A_ap + W^T A_pp) Wp^-1 Ψ = G^T (H_tr + A_tr qdd0)
        let qdd0 = DVector::from_column_slice(&state.qdd);
        let h_cl = g.transpose() * (h_tr + a_tr * &qdd0);
        let chol = a_cl.clone().cholesky().ok_or_else(|| {
            Error::Numerical(format!(
                "the closed-chain inertia matrix A_cl is not positive definite at q_a = {q_a:?} \
                 (check masses and inertias)"
            ))
        })?;
        let qdd_a = chol.solve(&(DVector::from_column_slice(tau_a) - &h_cl));
        // (10.42)
        let qdd_p = &state.constraints.w * &qdd_a - state.constraints.wp_solve(&state.psi);
        for (r, &j) in self.passive_joints().iter().enumerate() {
            state.qdd[j - 1] = qdd_p[r];
        }
        for (c, &j) in self.actuated_joints().iter().enumerate() {
            state.qdd[j - 1] = qdd_a[c];
        }
        Ok(ClosedDdm {
            qdd_a,
            qdd_p,
            a_cl,
            h_cl,
            state,
        })
    }
}

/// A closed-chain robot seen as a system in the actuated coordinates: the loops are re-solved
/// at every call with the previous solution as guess, so they never drift. The first call
/// starts from the reference assembly ([`ClosedChain::solve_from_reference`]) unless a guess
/// was set. The simulator's [`crate::simulation::Dynamics`] implementation is
/// [`crate::simulation::ClosedChainDynamics`].
#[derive(Clone, Debug)]
pub struct ClosedDynamics {
    pub model: ClosedChain,
    pub ws: ClosedChainWorkspace,
}

impl ClosedDynamics {
    pub fn new(robot: &Robot) -> Result<ClosedDynamics> {
        let model = ClosedChain::new(robot)?;
        let ws = model.workspace();
        Ok(ClosedDynamics { model, ws })
    }

    /// N.
    pub fn dof(&self) -> usize {
        self.model.dof()
    }

    /// q_p for q_a: from the previous solution, or the reference assembly at the first call.
    pub fn solve(&mut self, q_a: &[f64]) -> Result<ClosureSolution> {
        if self.ws.closure.last_qp.is_some() {
            self.model.solve_positions(&mut self.ws, q_a, None)
        } else {
            self.model.solve_from_reference(&mut self.ws, q_a, None)
        }
    }

    /// qdd_a for (q_a, qd_a, Γ_cl).
    pub fn accel(&mut self, q_a: &[f64], qd_a: &[f64], tau: &[f64]) -> Result<DVector<f64>> {
        self.accel_smoothed(q_a, qd_a, tau, None)
    }

    /// qdd_a with the Coulomb friction smoothed ([`ClosedChain::direct_dynamics_smoothed`]).
    pub fn accel_smoothed(
        &mut self,
        q_a: &[f64],
        qd_a: &[f64],
        tau: &[f64],
        coulomb_smoothing: Option<f64>,
    ) -> Result<DVector<f64>> {
        if self.ws.closure.last_qp.is_none() {
            self.model.solve_from_reference(&mut self.ws, q_a, None)?;
        }
        // guess None: the previous solution
        Ok(self
            .model
            .direct_dynamics_smoothed(&mut self.ws, q_a, qd_a, tau, None, coulomb_smoothing)?
            .qdd_a)
    }

    /// Largest closure residual (over the loops) of q_a's solution.
    pub fn closure_residual(&mut self, q_a: &[f64]) -> Result<f64> {
        Ok(self.solve(q_a)?.residual)
    }

    /// Set the guess of q_p for the next solve (e.g. the initial assembly).
    pub fn set_guess(&mut self, q_p: &[f64]) {
        self.ws.closure.last_qp = Some(q_p.to_vec());
    }
}
