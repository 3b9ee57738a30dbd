//! Derivatives of the direct dynamic model of a tree (docs/models/derivatives.md, D15–D17a):
//! differentiating A(q) qdd + H(q, qd) = Gamma at qdd = ddm(q, qd, Gamma) gives
//! dqdd/dq = -A^-1 dGamma/dq, dqdd/dqd = -A^-1 dGamma/dqd (the inverse model's derivatives at
//! that qdd) and dqdd/dGamma = A^-1, in four named steps:
//! 1. `accelerations`: A by composite links, its L'DL factorization (the direct model's own,
//!    [`ltdl_factor`]) and qdd = A^-1 (Gamma - H);
//! 2. the inverse model's derivatives at (q, qd, qdd) (`world::idm_derivatives_world`);
//! 3. `inverse_from_factors`: A^-1 from the same factors, down the tree (D17a);
//! 4. dqdd/dq = -A^-1 dGamma/dq and dqdd/dqd = -A^-1 dGamma/dqd as two matrix products.

use super::world::idm_derivatives_world;
use super::{check_square, DerivativesData, TreeLists};
use crate::algorithms::direct_dynamics::{ltdl_factor, ltdl_solve};
use crate::algorithms::inertia_matrix::composite_inertia_matrix;
use crate::algorithms::inverse_dynamics::{check_state, rnea_with_environment};
use crate::error::{check_finite_matrix, check_finite_result, Result};
use crate::model::{DynModel, Environment, Robot};
use nalgebra::{DMatrix, DVector};

/// The derivatives of the direct dynamic model at one state, N x N each over the movable
/// joints (frame order): entry (j, k) is the derivative of qdd_j.
#[derive(Clone, Debug, PartialEq)]
pub struct DdmDerivatives {
    /// The accelerations qdd = ddm(q, qd, Gamma) at which the derivatives are taken.
    pub qdd: DVector<f64>,
    /// dqdd/dq.
    pub dqdd_dq: DMatrix<f64>,
    /// dqdd/dqd.
    pub dqdd_dqd: DMatrix<f64>,
    /// dqdd/dGamma = A(q)^-1.
    pub ainv: DMatrix<f64>,
}

impl DdmDerivatives {
    /// Zero matrices for `robot` (N x N, and qdd of N entries).
    pub fn new(robot: &Robot) -> Self {
        let n = robot.dof();
        DdmDerivatives {
            qdd: DVector::zeros(n),
            dqdd_dq: DMatrix::zeros(n, n),
            dqdd_dqd: DMatrix::zeros(n, n),
            ainv: DMatrix::zeros(n, n),
        }
    }
}

/// Step 1: A(q) into `factor`, factored in place (L'DL over the tree), and
/// qdd = A^-1 (Gamma - H(q, qd)), H by Newton–Euler with qdd = 0 into `h`.
#[allow(clippy::too_many_arguments)]
fn accelerations(
    model: &DynModel<f64>,
    data: &mut DerivativesData,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    let DerivativesData {
        data: ws,
        factor,
        h,
        zeros,
        ..
    } = data;
    composite_inertia_matrix(model, ws, q, factor);
    ltdl_factor(model, factor)?;
    rnea_with_environment(model, ws, env, q, qd, zeros, h);
    for ((x, t), hk) in qdd.iter_mut().zip(tau).zip(h.iter()) {
        *x = t - hk;
    }
    ltdl_solve(model, factor, qdd);
    check_finite_result("qdd", qdd)
}

/// Step 3: X = A^-1 from the L'DL factors (A = L'DL, L unit lower over the tree, D on the
/// diagonal of `factor`): L X = D^-1 L^-T is upper triangular with diagonal D^-1, so for i >= j
///
/// ```text
/// X_ij = delta_ij / D_j - sum over the ancestors a of i of L_ia X_aj      (D17a)
/// ```
///
/// Column j is computed down from row j; its rows above j are those of X_ja written when
/// column a < j was done (X is symmetric), and every X_ij is written at (i, j) and (j, i).
/// Rows outside the subtree of j's topmost movable ancestor are zero (`TreeLists::span`),
/// skipped. Indices here are 0-based (link k + 1).
fn inverse_from_factors(
    model: &DynModel<f64>,
    factor: &DMatrix<f64>,
    tree: &TreeLists,
    x: &mut DMatrix<f64>,
) {
    let n = model.nl;
    let h = factor.as_slice();
    let xs = x.as_mut_slice();
    xs.fill(0.0);
    for j in 0..n {
        if !model.index.movable[j + 1] {
            continue;
        }
        for i in j..tree.span[j].1 {
            if !model.index.movable[i + 1] {
                continue;
            }
            let (l_i, x_j) = (&h[i * n..(i + 1) * n], &xs[j * n..(j + 1) * n]);
            let carried: f64 = tree.ancestors[i].iter().map(|&a| l_i[a] * x_j[a]).sum();
            let s = if i == j { 1.0 / h[j * n + j] } else { 0.0 } - carried;
            xs[i + j * n] = s;
            xs[j + i * n] = s;
        }
    }
}

/// Step 4: `out` = -A^-1 `b`, column by column, skipping the zeros of `b` (a tree's
/// dGamma/dq has none only between ancestors and descendants) and the rows of A^-1's column k
/// outside `span[k]` (joints of another subtree of the base: zero). Allocation-free (a dense
/// product from faer or nalgebra would allocate its packing buffers).
fn neg_product(
    ainv: &DMatrix<f64>,
    span: &[(usize, usize)],
    b: &DMatrix<f64>,
    out: &mut DMatrix<f64>,
) {
    let n = ainv.nrows();
    if n == 0 {
        return;
    }
    let a = ainv.as_slice();
    for (oc, bc) in out
        .as_mut_slice()
        .chunks_exact_mut(n)
        .zip(b.as_slice().chunks_exact(n))
    {
        oc.fill(0.0);
        for ((ak, &x), &(lo, hi)) in a.chunks_exact(n).zip(bc).zip(span) {
            if x != 0.0 {
                let o = &mut oc[lo..hi];
                o.iter_mut().zip(&ak[lo..hi]).for_each(|(o, y)| *o -= y * x);
            }
        }
    }
}

/// Derivatives of the direct dynamic model into `out`: qdd = ddm(q, qd, Gamma) and dqdd/dq,
/// dqdd/dqd, dqdd/dGamma = A^-1 (N x N over the movable joints, frame order) at positions `q`,
/// velocities `qd` and joint torques/forces `tau` over the movable joints, under `env`, from
/// the one L'DL factorization of A(q) that the direct model (composite method) computes.
/// Allocation-free.
///
/// Coulomb friction is taken as in the direct model (Fs sign(qd)), with a zero derivative.
///
/// Errors: as [`super::inverse_dynamics_derivatives_into`], and [`crate::Error::Singular`]
/// when A is singular.
///
/// # Example
///
/// ```
/// use robodyn::algorithms::derivatives::{
///     direct_dynamics_derivatives_into, DdmDerivatives, DerivativesData,
/// };
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
/// let robot = robodyn::io::load(path)?;
/// let mut data = DerivativesData::new(&robot);
/// let mut d = DdmDerivatives::new(&robot);
/// let (q, qd, tau) = ([0.1; 6], [0.2; 6], [1.0; 6]);
/// let env = robot.environment();
/// direct_dynamics_derivatives_into(&robot, &mut data, env, &q, &qd, &tau, &mut d)?;
/// // dqdd/dGamma A = 1
/// let a = robodyn::inertia_matrix(&robot, &q)?;
/// assert!((&d.ainv * a - robodyn::nalgebra::DMatrix::identity(6, 6)).amax() < 1e-9);
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn direct_dynamics_derivatives_into(
    robot: &Robot,
    data: &mut DerivativesData,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    out: &mut DdmDerivatives,
) -> Result<()> {
    data.check(robot)?;
    check_state(robot, &data.data, ["q", "qd", "tau"], [q, qd, tau])?;
    env.check(robot.nl())?;
    check_square(
        robot,
        &[
            ("dqdd_dq", &out.dqdd_dq),
            ("dqdd_dqd", &out.dqdd_dqd),
            ("Ainv", &out.ainv),
        ],
    )?;
    robot
        .coordinates()
        .check_output("qdd", out.qdd.as_slice(), "movable joints")?;
    let model = robot.dynamic();
    accelerations(model, data, env, q, qd, tau, out.qdd.as_mut_slice())?;
    let DerivativesData {
        data: ws,
        world,
        dtau,
        factor,
        h,
        tree,
        ..
    } = data;
    let state = (q, qd, out.qdd.as_slice());
    let [dq, dqd] = dtau;
    idm_derivatives_world(model, ws, world, env, state, h, [dq, dqd], None);
    inverse_from_factors(model, factor, tree, &mut out.ainv);
    neg_product(&out.ainv, &tree.span, dq, &mut out.dqdd_dq);
    neg_product(&out.ainv, &tree.span, dqd, &mut out.dqdd_dqd);
    check_finite_matrix("dqdd_dq", &out.dqdd_dq)?;
    check_finite_matrix("dqdd_dqd", &out.dqdd_dqd)?;
    check_finite_matrix("Ainv", &out.ainv)
}

/// [`direct_dynamics_derivatives_into`] with the robot's own environment; allocates its
/// result (and a [`DerivativesData`]): use the `_into` form in loops.
pub fn direct_dynamics_derivatives(
    robot: &Robot,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> Result<DdmDerivatives> {
    let mut out = DdmDerivatives::new(robot);
    let mut data = DerivativesData::new(robot);
    let env = robot.environment();
    direct_dynamics_derivatives_into(robot, &mut data, env, q, qd, tau, &mut out)?;
    Ok(out)
}
