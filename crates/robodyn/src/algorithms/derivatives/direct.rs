//! Derivatives of the direct dynamic model of a tree (docs/models/derivatives.md, D15–D17a):
//! differentiating A(q) qdd + H(q, qd) = Gamma at qdd = ddm(q, qd, Gamma) gives
//! dqdd/dq = -A^-1 dGamma/dq, dqdd/dqd = -A^-1 dGamma/dqd (the inverse model's derivatives at
//! that qdd) and dqdd/dGamma = A^-1, in four named steps:
//! 1. `accelerations`: H by Newton–Euler with qdd = 0, A from the world-frame composite
//!    inertias of that pass's placements (`world::world_inertia_matrix`), its L'DL
//!    factorization (the direct model's own, [`ltdl_factor`]) and qdd = A^-1 (Gamma - H);
//! 2. the inverse model's derivatives at (q, qd, qdd) (`world::ddm_rows`): the same world
//!    terms, with the wrenches of the accelerations qdd added to the pass at qdd = 0;
//! 3. `inverse_from_factors`: A^-1 from the same factors, down the tree (D17a);
//! 4. dqdd/dq = -A^-1 dGamma/dq and dqdd/dqd = -A^-1 dGamma/dqd, the two products together.

use super::world::{ddm_rows, world_inertia_matrix};
use super::{check_square, DerivativesData, TreeLists};
use crate::algorithms::direct_dynamics::{ltdl_factor, ltdl_solve};
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

/// Step 1: H(q, qd) by Newton–Euler with qdd = 0 into `h`, A(q) from the world terms of that
/// pass into `factor`, factored in place (L'DL over the tree), and qdd = A^-1 (Gamma - H).
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
        world,
        factor,
        h,
        zeros,
        ..
    } = data;
    rnea_with_environment(model, ws, env, q, qd, zeros, h);
    world_inertia_matrix(model, ws, world, env, qd, factor);
    ltdl_factor(model, factor)?;
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
/// Row i is computed for the columns j < i as one combination of the rows of its ancestors
/// (each stored as its column, X being symmetric: contiguous), then X_ii, and copied into
/// column i. Rows before i are complete then (their entries beyond the diagonal copied from the
/// later rows as each was done). Columns outside the subtree of i's topmost movable ancestor
/// are zero (`TreeLists::span`), skipped. Indices here are 0-based (link k + 1).
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
    for i in 0..n {
        if !model.index.movable[i + 1] {
            continue;
        }
        let lo = tree.span[i].0;
        let (done, rest) = xs.split_at_mut(i * n);
        let xi = &mut rest[lo..i];
        let l_i = &h[i * n..(i + 1) * n];
        for &a in &tree.ancestors[i] {
            let xa = &done[a * n + lo..a * n + i];
            xi.iter_mut().zip(xa).for_each(|(y, v)| *y -= l_i[a] * v);
        }
        let carried: f64 = tree.ancestors[i].iter().map(|&a| l_i[a] * xi[a - lo]).sum();
        rest[i] = 1.0 / h[i * n + i] - carried;
        for (j, &v) in (lo..i).zip(&rest[lo..i]) {
            done[i + j * n] = v;
        }
    }
}

/// Step 4: `out` = -A^-1 `b` for the two matrices b = dGamma/dq, dGamma/dqd together (one
/// read of A^-1 for both), column by column, skipping the zeros of `b` (a tree's dGamma/dq and
/// dGamma/dqd have none only between ancestors and descendants, the same entries) and the
/// rows of A^-1's column k outside `span[k]` (joints of another subtree of the base: zero).
/// Allocation-free (a dense product from faer or nalgebra would allocate its packing buffers).
fn neg_products(
    ainv: &DMatrix<f64>,
    span: &[(usize, usize)],
    [b1, b2]: [&DMatrix<f64>; 2],
    [o1, o2]: [&mut DMatrix<f64>; 2],
) {
    let n = ainv.nrows();
    if n == 0 {
        return;
    }
    let a = ainv.as_slice();
    let outs = o1
        .as_mut_slice()
        .chunks_exact_mut(n)
        .zip(o2.as_mut_slice().chunks_exact_mut(n));
    let bs = b1
        .as_slice()
        .chunks_exact(n)
        .zip(b2.as_slice().chunks_exact(n));
    for ((c1, c2), (bc1, bc2)) in outs.zip(bs) {
        c1.fill(0.0);
        c2.fill(0.0);
        for (((ak, &x1), &x2), &(lo, hi)) in a.chunks_exact(n).zip(bc1).zip(bc2).zip(span) {
            if x1 != 0.0 || x2 != 0.0 {
                let rows = c1[lo..hi].iter_mut().zip(&mut c2[lo..hi]).zip(&ak[lo..hi]);
                rows.for_each(|((y1, y2), a)| {
                    *y1 -= a * x1;
                    *y2 -= a * x2;
                });
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
        tree,
        ..
    } = data;
    let [dq, dqd] = dtau;
    ddm_rows(model, ws, world, (qd, out.qdd.as_slice()), [dq, dqd]);
    inverse_from_factors(model, factor, tree, &mut out.ainv);
    let outs = [&mut out.dqdd_dq, &mut out.dqdd_dqd];
    neg_products(&out.ainv, &tree.span, [dq, dqd], outs);
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
