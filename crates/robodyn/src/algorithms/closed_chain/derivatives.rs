//! Derivatives of the closed-chain dynamic models with respect to the actuated coordinates, on
//! the tracked branch (docs/models/derivatives.md, section "Closed chains", eqs C1–C12).
//!
//! Γ_cl = G^T Γ_tr(q_tr, G qd_a, G qdd_a + b) with b = [0; b_p], Wp b_p = -Ψ (C1). The tree part
//! comes from the tree's analytical derivatives (dΓ_tr/dq, dΓ_tr/dqd, A_tr); the closure part
//! (dG/dq_a, the derivatives of b) from the directional derivatives of the closure Jacobian J
//! and of Ψ along each column g_k of G, computed EXACTLY by one pass of the loop-closure
//! kinematics on dual numbers per actuated joint (C2). Then, in five named steps:
//! 1. `tree_terms`: the tree state over the movable joints, the tree's derivatives and Γ_tr;
//! 2. `closure_tangents`: D_k J and D_k Ψ by the dual passes (C2);
//! 3. `constraint_derivatives`: dW/dq_a,k (C3), Gd and Jd (C4), b_p and db_p/dq_a,k (C6);
//! 4. `assemble`: dΓ_cl/dq_a (C7), dΓ_cl/dqd_a (C8), A_cl (C9);
//! 5. (direct model) `direct_from_inverse`: dqdd_a = -A_cl^-1 dΓ_cl from the Cholesky factor of
//!    the closed direct model (C10–C11).

use super::{mul_into, tr_mul_into, Branch, ClosedChain, ClosedData, Conditioning};
use crate::algorithms::derivatives::{
    inverse_dynamics_derivatives_into, DerivativesData, IdmDerivatives,
};
use crate::algorithms::energy::convert_model;
use crate::algorithms::inverse_dynamics::rnea_with_environment;
use crate::algorithms::loop_closure::LoopWorkspace;
use crate::error::{check_finite_matrix, check_finite_result, Error, Result};
use crate::model::{DynModel, Environment};
use nalgebra::{DMatrix, DVector};
use num_dual::Dual64;

/// The derivatives of the closed-chain inverse dynamic model at one state, N x N each over the
/// actuated joints ([`ClosedChain::coordinates`]): entry (j, k) is the derivative of Γ_cl,j
/// with respect to q_a,k (qd_a,k, qdd_a,k), the loops kept closed on the tracked branch.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedIdmDerivatives {
    /// Γ_cl = G^T Γ_tr at the state (N m or N).
    pub tau: DVector<f64>,
    /// dΓ_cl/dq_a (C7).
    pub dtau_dq: DMatrix<f64>,
    /// dΓ_cl/dqd_a (C8).
    pub dtau_dqd: DMatrix<f64>,
    /// dΓ_cl/dqdd_a = A_cl = G^T A_tr G (C9, 10.46).
    pub a: DMatrix<f64>,
}

impl ClosedIdmDerivatives {
    /// Empty matrices (no allocation): a placeholder while a buffer is taken out.
    fn empty() -> Self {
        ClosedIdmDerivatives {
            tau: DVector::zeros(0),
            dtau_dq: DMatrix::zeros(0, 0),
            dtau_dqd: DMatrix::zeros(0, 0),
            a: DMatrix::zeros(0, 0),
        }
    }

    /// Zero matrices for `chain` (N x N, and Γ_cl of N entries).
    pub fn new(chain: &ClosedChain) -> Self {
        let n = chain.dof();
        ClosedIdmDerivatives {
            tau: DVector::zeros(n),
            dtau_dq: DMatrix::zeros(n, n),
            dtau_dqd: DMatrix::zeros(n, n),
            a: DMatrix::zeros(n, n),
        }
    }
}

/// The derivatives of the closed-chain direct dynamic model at one state, N x N each over the
/// actuated joints: entry (j, k) is the derivative of qdd_a,j.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedDdmDerivatives {
    /// qdd_a = A_cl^-1 (Γ - H_cl) at which the derivatives are taken (10.48).
    pub qdd: DVector<f64>,
    /// dqdd_a/dq_a (C10).
    pub dqdd_dq: DMatrix<f64>,
    /// dqdd_a/dqd_a (C10).
    pub dqdd_dqd: DMatrix<f64>,
    /// dqdd_a/dΓ = A_cl^-1 (C11).
    pub ainv: DMatrix<f64>,
}

impl ClosedDdmDerivatives {
    /// Zero matrices for `chain` (N x N, and qdd_a of N entries).
    pub fn new(chain: &ClosedChain) -> Self {
        let n = chain.dof();
        ClosedDdmDerivatives {
            qdd: DVector::zeros(n),
            dqdd_dq: DMatrix::zeros(n, n),
            dqdd_dqd: DMatrix::zeros(n, n),
            ainv: DMatrix::zeros(n, n),
        }
    }
}

/// The loop-closure kinematics on dual numbers: the robot's numeric model in [`Dual64`], its
/// workspace and the dual state, J and Ψ.
#[derive(Clone, Debug)]
struct DualClosure {
    model: DynModel<Dual64>,
    ws: LoopWorkspace<Dual64>,
    q: Vec<Dual64>,
    qd: Vec<Dual64>,
    jac: DMatrix<Dual64>,
    psi: DVector<Dual64>,
}

/// Buffers of the closed-chain derivatives for one chain (make one per thread, reuse it): the
/// chain's [`ClosedData`], the tree's [`DerivativesData`], the dual-number closure and the
/// closure's tangents. Holds no result a later call depends on (the branch is the caller's
/// [`Branch`]).
#[derive(Clone, Debug)]
pub struct ClosedDerivativesData {
    closed: ClosedData,
    tree: DerivativesData,
    /// dΓ_tr/dq, dΓ_tr/dqd, A_tr over the movable joints of the equivalent tree.
    tree_out: IdmDerivatives,
    dual: DualClosure,
    /// The inverse derivatives of the direct model's derivatives.
    idm: ClosedIdmDerivatives,
    /// D_k J (p x NL each, columns by joint number) and D_k Ψ (p x N), k over q_a (C2).
    dj: Vec<DMatrix<f64>>,
    dpsi: DMatrix<f64>,
    /// dW/dq_a,k (p x N each) (C3), Wd = sum_k dW_k qd_a,k (p x N), Jd (p x NL) (C4).
    dw: Vec<DMatrix<f64>>,
    wdot: DMatrix<f64>,
    jdot: DMatrix<f64>,
    /// b_p (p), db_p/dq_a (p x N) (C6); b over the tree arrays (NL).
    bp: Vec<f64>,
    db: DMatrix<f64>,
    b_tr: DVector<f64>,
    /// The tree state (q, qd, qdd) and Γ_tr over the movable joints.
    x: [Vec<f64>; 3],
    tau_m: DVector<f64>,
    /// G and Gd over the movable joints (N_t x N).
    gm: DMatrix<f64>,
    gdm: DMatrix<f64>,
    /// Row of each passive joint in the movable vectors.
    passive_rows: Vec<usize>,
    /// Scratch: N_t x N products, N_t, NL and p vectors.
    prod: [DMatrix<f64>; 2],
    vt: [DVector<f64>; 4],
    vl: DVector<f64>,
}

impl ClosedDerivativesData {
    /// The buffers for `chain`.
    pub fn new(chain: &ClosedChain) -> Self {
        let (n, p, nl) = (chain.dof(), chain.n_equations(), chain.robot().nl());
        let robot = chain.robot();
        let nt = robot.dof();
        let coords = robot.coordinates();
        let passive_rows = chain
            .passive
            .frames()
            .iter()
            .map(|&j| coords.frames().iter().position(|&f| f == j).unwrap_or(0))
            .collect();
        let d0 = Dual64::from_re(0.0);
        ClosedDerivativesData {
            closed: ClosedData::new(chain),
            tree: DerivativesData::new(robot),
            tree_out: IdmDerivatives::new(robot),
            dual: DualClosure {
                model: convert_model(robot.numeric()),
                ws: chain.closure.workspace_in(),
                q: vec![d0; nl],
                qd: vec![d0; nl],
                jac: DMatrix::from_element(p, nl, d0),
                psi: DVector::from_element(p, d0),
            },
            idm: ClosedIdmDerivatives::new(chain),
            dj: vec![DMatrix::zeros(p, nl); n],
            dpsi: DMatrix::zeros(p, n),
            dw: vec![DMatrix::zeros(p, n); n],
            wdot: DMatrix::zeros(p, n),
            jdot: DMatrix::zeros(p, nl),
            bp: vec![0.0; p],
            db: DMatrix::zeros(p, n),
            b_tr: DVector::zeros(nl),
            x: [vec![0.0; nt], vec![0.0; nt], vec![0.0; nt]],
            tau_m: DVector::zeros(nt),
            gm: DMatrix::zeros(nt, n),
            gdm: DMatrix::zeros(nt, n),
            passive_rows,
            prod: [DMatrix::zeros(nt, n), DMatrix::zeros(nt, n)],
            vt: [
                DVector::zeros(nt),
                DVector::zeros(nt),
                DVector::zeros(nt),
                DVector::zeros(nt),
            ],
            vl: DVector::zeros(nl),
        }
    }

    /// Error unless this data was made for `chain` (the tree's and the closed chain's buffers
    /// are checked by the calls that use them).
    fn check(&self, chain: &ClosedChain) -> Result<()> {
        let (n, p) = (chain.dof(), chain.n_equations());
        if self.dj.len() != n || self.bp.len() != p || self.gm.nrows() != chain.robot().dof() {
            return Err(Error::dimension(
                "closed derivatives data",
                n,
                self.dj.len(),
                "actuated joints: the ClosedDerivativesData was made for another closed chain",
            ));
        }
        Ok(())
    }
}

/// Error unless every matrix of `outputs` is N x N and every vector N over the actuated joints.
fn check_outputs(
    chain: &ClosedChain,
    matrices: &[(&str, &DMatrix<f64>)],
    vector: (&str, &DVector<f64>),
) -> Result<()> {
    let n = chain.dof();
    for (name, m) in matrices {
        if m.shape() != (n, n) {
            return Err(Error::dimension(
                *name,
                n * n,
                m.len(),
                format!(
                    "{n} x {n} over {}",
                    chain.coordinates().describe("actuated joints")
                ),
            ));
        }
    }
    chain
        .coordinates()
        .check_output(vector.0, vector.1.as_slice(), "actuated joints")
}

/// Step 1: the consistent tree state over the movable joints with G (rows of the movable
/// joints), the tree's derivatives dΓ_tr/dq, dΓ_tr/dqd, A_tr there, and Γ_tr (NL arrays, in
/// `closed.tau_tr`).
fn tree_terms(
    chain: &ClosedChain,
    data: &mut ClosedDerivativesData,
    env: &Environment,
) -> Result<()> {
    let robot = chain.robot();
    let d = &mut data.closed;
    for (r, &j) in robot.coordinates().frames().iter().enumerate() {
        data.x[0][r] = d.q_tr[j - 1];
        data.x[1][r] = d.qd_tr[j - 1];
        data.x[2][r] = d.qdd_tr[j - 1];
        for c in 0..d.n {
            data.gm[(r, c)] = d.g[(j - 1, c)];
        }
    }
    let [q, qd, qdd] = &data.x;
    inverse_dynamics_derivatives_into(robot, &mut data.tree, env, q, qd, qdd, &mut data.tree_out)?;
    rnea_with_environment(
        robot.numeric(),
        &mut d.tree,
        env,
        &d.q_tr,
        &d.qd_tr,
        &d.qdd_tr,
        &mut d.tau_tr,
    );
    for (r, &j) in robot.coordinates().frames().iter().enumerate() {
        data.tau_m[r] = d.tau_tr[j - 1];
    }
    Ok(())
}

/// dst += a src (same shapes).
fn add_scaled(dst: &mut DMatrix<f64>, a: f64, src: &DMatrix<f64>) {
    for (x, y) in dst.as_mut_slice().iter_mut().zip(src.as_slice()) {
        *x += a * y;
    }
}

/// Step 2 (C2): for each actuated joint k, one pass of the loop-closure kinematics on dual
/// numbers at q_tr + eps g_k with the velocities qd_tr (qdd = 0): the eps parts of the closure
/// Jacobian and of Ψ are D_k J and D_k Ψ, exact (no step size).
fn closure_tangents(chain: &ClosedChain, data: &mut ClosedDerivativesData) {
    let lc = &chain.closure;
    let d = &data.closed;
    let u = &mut data.dual;
    for k in 0..d.n {
        for r in 0..d.nl {
            u.q[r] = Dual64::new(d.q_tr[r], d.g[(r, k)]);
            u.qd[r] = Dual64::from_re(d.qd_tr[r]);
        }
        lc.kinematics_in(&u.model, &mut u.ws, &u.q, Some(&u.qd), None);
        lc.constraint_jacobian(&mut u.ws, &mut u.jac);
        lc.psi(&u.ws, &mut u.psi);
        for (x, y) in data.dj[k].iter_mut().zip(u.jac.iter()) {
            *x = y.eps;
        }
        for r in 0..d.p {
            data.dpsi[(r, k)] = u.psi[r].eps;
        }
    }
}

/// Step 3: dW/dq_a,k = -Wp^-1 (D_k J) G (C3), Wd and Jd (C4), b_p = -Wp^-1 Ψ and
/// db_p/dq_a,k = -Wp^-1 (D_k Ψ + (D_k J) b + 2 Jd dG_k qd_a) (C6), dG_k = [0; dW_k].
fn constraint_derivatives(chain: &ClosedChain, data: &mut ClosedDerivativesData, qd_a: &[f64]) {
    let d = &mut data.closed;
    let passive = chain.closure.passive_joints();
    data.wdot.fill(0.0);
    data.jdot.fill(0.0);
    for k in 0..d.n {
        mul_into(&data.dj[k], &d.g, &mut data.dw[k]);
        data.dw[k].neg_mut();
        d.lu.solve_matrix(&mut data.dw[k]);
        add_scaled(&mut data.wdot, qd_a[k], &data.dw[k]);
        add_scaled(&mut data.jdot, qd_a[k], &data.dj[k]);
    }
    for (x, p) in data.bp.iter_mut().zip(d.psi.iter()) {
        *x = -p;
    }
    d.lu.solve(&mut data.bp);
    data.b_tr.fill(0.0);
    for (r, &j) in passive.iter().enumerate() {
        data.b_tr[j - 1] = data.bp[r];
    }
    for k in 0..d.n {
        // dG_k qd_a over the tree arrays (passive rows only)
        data.vl.fill(0.0);
        for (r, &j) in passive.iter().enumerate() {
            data.vl[j - 1] = (0..d.n).map(|c| data.dw[k][(r, c)] * qd_a[c]).sum();
        }
        let mut rhs = data.db.column_mut(k);
        rhs.copy_from(&data.dpsi.column(k));
        rhs.gemv(1.0, &data.dj[k], &data.b_tr, 1.0);
        rhs.gemv(2.0, &data.jdot, &data.vl, 1.0);
        rhs.neg_mut();
    }
    d.lu.solve_matrix(&mut data.db);
}

/// `out` (over the movable joints) = dG_k x: the passive rows (`rows`) dW_k x, zero elsewhere.
fn dg_times(dw_k: &DMatrix<f64>, rows: &[usize], x: &[f64], out: &mut DVector<f64>) {
    out.fill(0.0);
    for (r, &row) in rows.iter().enumerate() {
        out[row] = (0..x.len()).map(|c| dw_k[(r, c)] * x[c]).sum();
    }
}

/// Step 4: Γ_cl = G^T Γ_tr, A_cl = G^T A_tr G (C9), dΓ_cl/dqd_a = G^T (K_v G + 2 A_tr Gd) (C8)
/// and column k of dΓ_cl/dq_a = dW_k^T Γ_p + G^T (K_q g_k + K_v dG_k qd_a +
/// A_tr (dG_k qdd_a + db_k)) (C7), over the movable joints (K_q, K_v the tree's dΓ_tr/dq,
/// dΓ_tr/dqd).
fn assemble(
    data: &mut ClosedDerivativesData,
    qd_a: &[f64],
    qdd_a: &[f64],
    out: &mut ClosedIdmDerivatives,
) {
    let ClosedDerivativesData {
        tree_out: t,
        gm,
        gdm,
        wdot,
        dw,
        db,
        tau_m,
        passive_rows: rows,
        prod: [p0, p1],
        vt: [g_k, dv, da, tk],
        ..
    } = data;
    gdm.fill(0.0);
    for (r, &row) in rows.iter().enumerate() {
        gdm.row_mut(row).copy_from(&wdot.row(r));
    }
    out.tau.gemv_tr(1.0, gm, tau_m, 0.0);
    mul_into(&t.a, gm, p0);
    tr_mul_into(gm, p0, &mut out.a);
    mul_into(&t.dtau_dqd, gm, p0);
    mul_into(&t.a, gdm, p1);
    add_scaled(p0, 2.0, p1);
    tr_mul_into(gm, p0, &mut out.dtau_dqd);
    for (k, dw_k) in dw.iter().enumerate() {
        g_k.copy_from(&gm.column(k));
        dg_times(dw_k, rows, qd_a, dv);
        dg_times(dw_k, rows, qdd_a, da);
        for (r, &row) in rows.iter().enumerate() {
            da[row] += db[(r, k)];
        }
        tk.gemv(1.0, &t.dtau_dq, g_k, 0.0);
        tk.gemv(1.0, &t.dtau_dqd, dv, 1.0);
        tk.gemv(1.0, &t.a, da, 1.0);
        let mut col = out.dtau_dq.column_mut(k);
        col.gemv_tr(1.0, gm, tk, 0.0);
        for (r, &row) in rows.iter().enumerate() {
            for (c, x) in col.iter_mut().enumerate() {
                *x += dw_k[(r, c)] * tau_m[row];
            }
        }
    }
}

/// The inverse derivatives into `out` after the inputs' checks: steps 1–4 at the consistent
/// state of (q_a, qd_a, qdd_a) on the tracker's branch.
#[allow(clippy::too_many_arguments)]
fn inverse_into(
    chain: &ClosedChain,
    data: &mut ClosedDerivativesData,
    branch: &mut Branch,
    env: &Environment,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
    out: &mut ClosedIdmDerivatives,
) -> Result<()> {
    chain.state_into(
        &mut data.closed,
        branch,
        [("q_a", q_a), ("qd_a", qd_a), ("qdd_a", qdd_a)],
    )?;
    tree_terms(chain, data, env)?;
    closure_tangents(chain, data);
    constraint_derivatives(chain, data, qd_a);
    assemble(data, qd_a, qdd_a, out);
    check_finite_result("tau", out.tau.as_slice())?;
    check_finite_matrix("dtau_dq", &out.dtau_dq)?;
    check_finite_matrix("dtau_dqd", &out.dtau_dqd)?;
    check_finite_matrix("A_cl", &out.a)
}

/// Derivatives of the closed-chain inverse dynamic model into `out`: Γ_cl and dΓ_cl/dq_a,
/// dΓ_cl/dqd_a, dΓ_cl/dqdd_a = A_cl (N x N over the actuated joints) at q_a, qd_a, qdd_a
/// (actuated joints) under `env`, the loops closed on the tracker's branch (which moves to
/// q_a, as for [`super::closed_inverse_dynamics_into`]). Exact: the tree's analytical
/// derivatives and dual numbers through the loop-closure equations (docs/models/derivatives.md,
/// C1–C9). Allocation-free on the branch. Returns the conditioning of Wp.
///
/// Coulomb friction contributes nothing (zero derivative off qd = 0), viscous friction of every
/// tree joint enters through dΓ_tr/dqd.
///
/// Errors: [`Error::Dimension`] / [`Error::NotFinite`] for bad inputs, outputs or a data of
/// another chain; [`Error::BranchLost`] when q_a cannot be reached on the branch;
/// [`Error::Singular`] when Wp is singular at q_a.
///
/// # Example
///
/// The five-bar linkage (`robots/fivebar.toml`, actuated joints 1 and 3): the derivatives at a
/// state, and dΓ_cl/dqdd_a = A_cl, the closed chain's inertia matrix.
///
/// ```
/// use robodyn::{closed_inverse_dynamics_derivatives_into, ClosedChain};
/// use robodyn::{ClosedDerivativesData, ClosedIdmDerivatives};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/fivebar.toml");
/// let robot = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&robot)?;
/// let mut data = ClosedDerivativesData::new(&chain);
/// let mut d = ClosedIdmDerivatives::new(&chain);
/// let mut branch = chain.assembly_branch()?;
/// let env = robot.environment();
/// let (q_a, qd_a, qdd_a) = ([1.9, 1.2], [0.3, -0.2], [1.0, 0.5]);
/// let cond = closed_inverse_dynamics_derivatives_into(
///     &chain, &mut data, &mut branch, env, &q_a, &qd_a, &qdd_a, &mut d,
/// )?;
/// assert!(!cond.warning);
/// let a_cl = robodyn::closed_direct_dynamics(&chain, &mut branch, &q_a, &qd_a, &[0.0; 2])?.a_cl;
/// assert!((&d.a - a_cl).amax() < 1e-12);
/// println!("dGamma/dq_a = {}", d.dtau_dq);
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn closed_inverse_dynamics_derivatives_into(
    chain: &ClosedChain,
    data: &mut ClosedDerivativesData,
    branch: &mut Branch,
    env: &Environment,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
    out: &mut ClosedIdmDerivatives,
) -> Result<Conditioning> {
    data.check(chain)?;
    env.check(chain.robot().nl())?;
    check_outputs(
        chain,
        &[
            ("dtau_dq", &out.dtau_dq),
            ("dtau_dqd", &out.dtau_dqd),
            ("A_cl", &out.a),
        ],
        ("tau", &out.tau),
    )?;
    inverse_into(chain, data, branch, env, q_a, qd_a, qdd_a, out)?;
    Ok(chain.conditioning(branch, None))
}

/// [`closed_inverse_dynamics_derivatives_into`] with the robot's environment; allocates its
/// result and buffers: use the `_into` form in loops.
pub fn closed_inverse_dynamics_derivatives(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
) -> Result<ClosedIdmDerivatives> {
    let mut data = ClosedDerivativesData::new(chain);
    let mut out = ClosedIdmDerivatives::new(chain);
    let env = chain.robot().environment();
    closed_inverse_dynamics_derivatives_into(
        chain, &mut data, branch, env, q_a, qd_a, qdd_a, &mut out,
    )?;
    Ok(out)
}

/// Step 5 (C10–C11): A_cl^-1 from the Cholesky factor the direct model left in
/// `closed.chol`, and dqdd_a/dq_a = -A_cl^-1 dΓ_cl/dq_a, dqdd_a/dqd_a = -A_cl^-1 dΓ_cl/dqd_a.
fn direct_from_inverse(data: &mut ClosedDerivativesData, out: &mut ClosedDdmDerivatives) {
    let d = &mut data.closed;
    let factor = std::mem::replace(&mut d.chol, DMatrix::zeros(0, 0));
    let chol = nalgebra::Cholesky::pack_dirty(factor);
    out.ainv.fill(0.0);
    out.ainv.fill_diagonal(1.0);
    chol.solve_mut(&mut out.ainv);
    d.chol = chol.unpack_dirty();
    mul_into(&out.ainv, &data.idm.dtau_dq, &mut out.dqdd_dq);
    out.dqdd_dq.neg_mut();
    mul_into(&out.ainv, &data.idm.dtau_dqd, &mut out.dqdd_dqd);
    out.dqdd_dqd.neg_mut();
}

/// Derivatives of the closed-chain direct dynamic model into `out`: qdd_a = A_cl^-1 (Γ - H_cl)
/// (10.48) and dqdd_a/dq_a, dqdd_a/dqd_a, dqdd_a/dΓ = A_cl^-1 (N x N over the actuated joints)
/// at q_a, qd_a and the actuated torques `tau_a` under `env`, on the tracker's branch:
/// -A_cl^-1 dΓ_cl/d(q_a, qd_a) at that qdd_a (C10), A_cl^-1 from the Cholesky factor of the
/// closed direct model (no other factorization). Allocation-free on the branch. Returns the
/// conditioning of Wp and A_cl.
///
/// Errors: as [`closed_inverse_dynamics_derivatives_into`], and [`Error::Singular`] when A_cl
/// is singular.
#[allow(clippy::too_many_arguments)]
pub fn closed_direct_dynamics_derivatives_into(
    chain: &ClosedChain,
    data: &mut ClosedDerivativesData,
    branch: &mut Branch,
    env: &Environment,
    q_a: &[f64],
    qd_a: &[f64],
    tau_a: &[f64],
    out: &mut ClosedDdmDerivatives,
) -> Result<Conditioning> {
    data.check(chain)?;
    check_outputs(
        chain,
        &[
            ("dqdd_dq", &out.dqdd_dq),
            ("dqdd_dqd", &out.dqdd_dqd),
            ("Ainv", &out.ainv),
        ],
        ("qdd", &out.qdd),
    )?;
    let x = [q_a, qd_a, tau_a];
    let cond = chain.direct_into(
        &mut data.closed,
        branch,
        env,
        x,
        None,
        out.qdd.as_mut_slice(),
    )?;
    let mut idm = std::mem::replace(&mut data.idm, ClosedIdmDerivatives::empty());
    let r = inverse_into(
        chain,
        data,
        branch,
        env,
        q_a,
        qd_a,
        out.qdd.as_slice(),
        &mut idm,
    );
    data.idm = idm;
    r?;
    direct_from_inverse(data, out);
    check_finite_matrix("dqdd_dq", &out.dqdd_dq)?;
    check_finite_matrix("dqdd_dqd", &out.dqdd_dqd)?;
    check_finite_matrix("Ainv", &out.ainv)?;
    Ok(cond)
}

/// [`closed_direct_dynamics_derivatives_into`] with the robot's environment; allocates its
/// result and buffers: use the `_into` form in loops.
pub fn closed_direct_dynamics_derivatives(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    tau_a: &[f64],
) -> Result<ClosedDdmDerivatives> {
    let mut data = ClosedDerivativesData::new(chain);
    let mut out = ClosedDdmDerivatives::new(chain);
    let env = chain.robot().environment();
    closed_direct_dynamics_derivatives_into(
        chain, &mut data, branch, env, q_a, qd_a, tau_a, &mut out,
    )?;
    Ok(out)
}
