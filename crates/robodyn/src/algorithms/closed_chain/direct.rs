//! The closed-chain inertia matrix and direct dynamic model (§10.3.3): A_cl = G^T A_tr G (10.46),
//! H_cl (10.47), qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.48, Cholesky).

use super::{mul_into, tr_mul_into, Branch, ClosedChain, ClosedData, ClosedState, Conditioning};
use crate::algorithms::inertia_matrix::composite_inertia_matrix;
use crate::algorithms::inverse_dynamics::rnea_with_environment;
use crate::error::{Configuration, Error, Result};
use crate::linalg::{norm1, rcond_cholesky};
use crate::model::Environment;
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, DVector};

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

impl ClosedChain {
    /// A_tr (composite links, into `d.tree.a`) at `d.q_tr` and A_cl = G^T A_tr G (10.46) into
    /// `d.a_cl`, G of the tracker's point (small products written out: nalgebra's gemm packs its
    /// operands on the heap).
    pub(super) fn a_cl_into(&self, d: &mut ClosedData) {
        let mut a_tr = std::mem::replace(&mut d.tree.a, DMatrix::zeros(0, 0));
        composite_inertia_matrix(self.robot().numeric(), &mut d.tree, &d.q_tr, &mut a_tr);
        mul_into(&a_tr, &d.g, &mut d.ag);
        tr_mul_into(&d.g, &d.ag, &mut d.a_cl);
        d.tree.a = a_tr;
    }

    /// The direct model (10.46–10.48) into `qdd_a`, in four steps: the consistent state with
    /// qdd_a = 0, H_cl, the Cholesky solve of A_cl, qdd_p.
    pub(super) fn direct_into(
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
        self.a_cl_into(d);
        self.h_cl_into(d, env, coulomb_smoothing);
        let rcond = self.solve_a_cl(d, x[2], qdd_a)?;
        self.complete_qdd(d, qdd_a);
        Ok(self.conditioning(b, Some(rcond)))
    }

    /// H_tr = Γ_tr(q, qd, 0) (10.32) in d.tau_tr (Coulomb friction smoothed as Fs tanh(qd / v)
    /// when asked) and H_cl = G^T (H_tr + A_tr qdd0) (10.47) into d.h_cl, after
    /// [`Self::a_cl_into`] (A_tr in d.tree.a).
    fn h_cl_into(&self, d: &mut ClosedData, env: &Environment, coulomb_smoothing: Option<f64>) {
        let model = self.robot().numeric();
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
        let a_tr = &d.tree.a;
        for r in 0..d.nl {
            let mut v = d.tau_tr[r];
            for c in 0..d.nl {
                v += a_tr[(r, c)] * d.qdd_tr[c];
            }
            d.v_nl[r] = v;
        }
        d.h_cl.gemv_tr(1.0, &d.g, &d.v_nl, 0.0);
    }

    /// qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.48) by Cholesky, refused below the hard conditioning
    /// limit of A_cl; returns its reciprocal condition number.
    fn solve_a_cl(&self, d: &mut ClosedData, tau: &[f64], qdd_a: &mut [f64]) -> Result<f64> {
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
            d.col_n[c] = tau[c] - d.h_cl[c];
        }
        chol.solve_mut(&mut d.col_n);
        d.chol = chol.unpack_dirty();
        qdd_a.copy_from_slice(d.col_n.as_slice());
        Ok(rcond)
    }

    /// The tree's accelerations for the computed qdd_a: qdd_p = W qdd_a - Wp^-1 Ψ (10.42; the
    /// second term already in d.qdd_tr's passive rows).
    fn complete_qdd(&self, d: &mut ClosedData, qdd_a: &[f64]) {
        let lc = &self.closure;
        for (c, &j) in lc.actuated_joints().iter().enumerate() {
            d.qdd_tr[j - 1] = qdd_a[c];
        }
        for (r, &j) in lc.passive_joints().iter().enumerate() {
            let a: f64 = (0..d.n).map(|c| d.w[(r, c)] * qdd_a[c]).sum();
            d.qdd_tr[j - 1] += a;
        }
    }

    pub(super) fn singular_a_cl(&self, rcond: f64, q_tr: &[f64]) -> Error {
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
