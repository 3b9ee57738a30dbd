//! Derivatives of the inverse dynamic model of a tree, dGamma/dq and dGamma/dqd, by the
//! Newton–Euler recursion differentiated along each joint coordinate (docs/models/derivatives.md,
//! eqs D1–D14), and A = dGamma/dqdd by composite links.
//!
//! Column k (joint k, position and velocity together) in four named steps:
//! 1. `seed`: the tangents of link k itself, the only link whose placement iA_k, iP_k moves
//!    with q_k and whose joint rate is qd_k (D4–D7 with the seed terms);
//! 2. `propagate`: the tangents of k's successors, in preorder over k's subtree (nothing
//!    outside the subtree moves in the forward recursion), and the tangents of the links'
//!    wrenches (D8–D9);
//! 3. `accumulate`: the backward recursion of the tangents over the subtree (D10), whose
//!    projections on the joint axes are the rows of k's subtree (D12);
//! 4. `transmit`: the tangent of the wrench that k exerts on its antecedent carried down to
//!    the base (D11, D13), whose projections are the rows of k's ancestors.
//!
//! Rows of joints that are neither ancestors nor successors of k are zero. The cost is that of
//! N restricted recursions: O(N d) link steps for N joints at depth at most d, O(N^2) for a
//! chain.

use super::world::idm_derivatives_world;
use super::{check_square, DerivativesData, Tangent};
use crate::algorithms::inverse_dynamics::{check_state, rnea_with_environment};
use crate::batch::{count_rows, for_each_row};
use crate::data::Data;
use crate::error::{check_finite_matrix, Error, Result};
use crate::model::{DynModel, Environment, FrameConstants, JointType, Robot};
use nalgebra::{DMatrix, DVector, Vector3};

/// The derivatives of the inverse dynamic model at one state, N x N each over the movable
/// joints (frame order): entry (j, k) is the derivative of Gamma_j.
#[derive(Clone, Debug, PartialEq)]
pub struct IdmDerivatives {
    /// Gamma at the state (N m or N), as [`crate::inverse_dynamics`] gives it.
    pub tau: DVector<f64>,
    /// dGamma/dq (N m/rad, N/m, N m/m, N/rad).
    pub dtau_dq: DMatrix<f64>,
    /// dGamma/dqd, viscous friction Fv on the diagonal.
    pub dtau_dqd: DMatrix<f64>,
    /// dGamma/dqdd = A(q), the inertia matrix (rotor inertias on the diagonal).
    pub a: DMatrix<f64>,
}

impl IdmDerivatives {
    /// Zero matrices for `robot` (N x N).
    pub fn new(robot: &Robot) -> Self {
        let n = robot.dof();
        IdmDerivatives {
            tau: DVector::zeros(n),
            dtau_dq: DMatrix::zeros(n, n),
            dtau_dqd: DMatrix::zeros(n, n),
            a: DMatrix::zeros(n, n),
        }
    }
}

/// e_z x v.
#[inline(always)]
fn z_cross(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-v.y, v.x, 0.0)
}

/// v x (s e_z).
#[inline(always)]
fn cross_z(v: &Vector3<f64>, s: f64) -> Vector3<f64> {
    Vector3::new(v.y * s, -v.x * s, 0.0)
}

/// Step 1 (D4–D7 seeded): the tangents of link k along q_k (`dir[0]`) and qd_k (`dir[1]`).
/// With w_i' = kA_i w_i = w_k - qd_k e_z (revolute): d(kA_i v)/dq_k = (kA_i v) x e_z, and for a
/// prismatic joint d(iP_k)/dq_k = iA_k e_z.
fn seed(model: &DynModel<f64>, ws: &Data, dir: &mut [Tangent; 2], k: usize, qd: f64, qdd: f64) {
    let fr = model.frame(k);
    let i = fr.ant;
    let [tq, tv] = dir;
    match fr.joint {
        JointType::Revolute => {
            let mut wi = ws.w[k];
            wi.z -= qd;
            let dw = cross_z(&wi, 1.0);
            // kA_i wd_i = wd_k - wi x qd e_z - qdd e_z (10.4)
            let mut awd = ws.wd[k] - cross_z(&wi, qd);
            awd.z -= qdd;
            tq.w[k] = dw;
            tq.wd[k] = cross_z(&awd, 1.0) + cross_z(&dw, qd);
            // vd_k = kA_i (vd_i + U_i P_k) for a revolute joint (10.6)
            tq.vd[k] = cross_z(&ws.vd[k], 1.0);
            tv.w[k] = Vector3::z();
            tv.wd[k] = dw;
            tv.vd[k] = Vector3::zeros();
        }
        JointType::Prismatic => {
            let r = &ws.rot[k];
            let axis = Vector3::new(r[(0, 2)], r[(1, 2)], r[(2, 2)]);
            let wi = ws.w[k];
            tq.w[k] = Vector3::zeros();
            tq.wd[k] = Vector3::zeros();
            tq.vd[k] = fr.rot_tr_mul(r, &(ws.u[i] * axis));
            tv.w[k] = Vector3::zeros();
            tv.wd[k] = Vector3::zeros();
            tv.vd[k] = cross_z(&wi, 2.0);
        }
        JointType::Fixed => {
            for t in [tq, tv] {
                t.w[k] = Vector3::zeros();
                t.wd[k] = Vector3::zeros();
                t.vd[k] = Vector3::zeros();
            }
        }
    }
}

/// (D4)–(D7) for a successor j of the seeded joint (antecedent i in the subtree): the
/// tangents of i carried through the constant iA_j, iP_j.
#[inline(always)]
fn link_step(t: &mut Tangent, fr: &FrameConstants<f64>, ws: &Data, j: usize, qd: f64) {
    let i = fr.ant;
    let (r, p) = (&ws.rot[j], &ws.pos[j]);
    let (w, dw, dwd) = (&ws.w[i], &t.w[i], &t.wd[i]);
    let dwi = fr.rot_tr_mul(r, dw);
    // d(U_i P_j) = dwd_i x P + dw_i x (w_i x P) + w_i x (dw_i x P)
    let dup = dwd.cross(p) + dw.cross(&w.cross(p)) + w.cross(&dw.cross(p));
    let mut dvd = fr.rot_tr_mul(r, &(t.vd[i] + dup));
    let mut dwdj = fr.rot_tr_mul(r, dwd);
    match fr.joint {
        JointType::Revolute => dwdj += cross_z(&dwi, qd),
        JointType::Prismatic => dvd += cross_z(&dwi, 2.0 * qd),
        JointType::Fixed => {}
    }
    t.w[j] = dwi;
    t.wd[j] = dwdj;
    t.vd[j] = dvd;
}

/// (D8)–(D9): the tangent of link j's own wrench from its kinematic tangents,
/// dF = M dvd + dwd x MS + dw x (w x MS) + w x (dw x MS),
/// dN = J dwd + dw x (J w) + w x (J dw) + MS x dvd.
#[inline(always)]
fn wrench_step(t: &mut Tangent, model: &DynModel<f64>, ws: &Data, j: usize) {
    let l = model.link(j);
    let (w, dw, dwd, dvd) = (&ws.w[j], &t.w[j], &t.wd[j], &t.vd[j]);
    let ms = &l.ms;
    t.f[j] = dvd * l.mass + dwd.cross(ms) + dw.cross(&w.cross(ms)) + w.cross(&dw.cross(ms));
    t.m[j] =
        l.inertia * dwd + dw.cross(&(l.inertia * w)) + w.cross(&(l.inertia * dw)) + ms.cross(dvd);
}

/// Step 2: the tangents of every link of k's subtree (`preorder[s..e]`, k first) and of their
/// own wrenches, both directions.
fn propagate(
    model: &DynModel<f64>,
    ws: &Data,
    dir: &mut [Tangent; 2],
    qd: &[f64],
    s: usize,
    e: usize,
) {
    let pre = &model.index.preorder;
    for t in dir.iter_mut() {
        wrench_step(t, model, ws, pre[s]);
    }
    for &j in &pre[s + 1..e] {
        let fr = model.frame(j);
        for t in dir.iter_mut() {
            link_step(t, fr, ws, j, qd[j - 1]);
            wrench_step(t, model, ws, j);
        }
    }
}

/// The projection of a wrench on joint j's axis (10.12): the moment's z for a revolute joint,
/// the force's z for a prismatic one, 0 for a fixed frame.
#[inline(always)]
fn project(fr: &FrameConstants<f64>, f: &Vector3<f64>, m: &Vector3<f64>) -> f64 {
    match fr.joint {
        JointType::Revolute => m.z,
        JointType::Prismatic => f.z,
        JointType::Fixed => 0.0,
    }
}

/// (iA_j f, iA_j m + iP_j x iA_j f): a wrench on link j about O_j carried to O_i in R_i
/// (10.10)–(10.11).
#[inline(always)]
fn to_antecedent(
    fr: &FrameConstants<f64>,
    ws: &Data,
    j: usize,
    f: &Vector3<f64>,
    m: &Vector3<f64>,
) -> (Vector3<f64>, Vector3<f64>) {
    let fi = fr.rot_mul(&ws.rot[j], f);
    let mi = fr.rot_mul(&ws.rot[j], m) + ws.pos[j].cross(&fi);
    (fi, mi)
}

/// Step 3 (D10, D12): the backward recursion of both tangents over the successors of k
/// (`preorder[s + 1..e]` in reverse), each row of the subtree written once complete (k's own
/// row included) into column `col` of `dq` and `dqd`.
fn accumulate(
    model: &DynModel<f64>,
    ws: &Data,
    dir: &mut [Tangent; 2],
    (s, e): (usize, usize),
    dq: &mut [f64],
    dqd: &mut [f64],
) {
    let pre = &model.index.preorder;
    for &j in pre[s + 1..e].iter().rev() {
        let fr = model.frame(j);
        let i = fr.ant;
        for (t, out) in dir.iter_mut().zip([&mut *dq, &mut *dqd]) {
            out[j - 1] = project(fr, &t.f[j], &t.m[j]);
            let (fi, mi) = to_antecedent(fr, ws, j, &t.f[j], &t.m[j]);
            t.f[i] += fi;
            t.m[i] += mi;
        }
    }
    let k = pre[s];
    let fr = model.frame(k);
    for (t, out) in dir.iter().zip([dq, dqd]) {
        out[k - 1] = project(fr, &t.f[k], &t.m[k]);
    }
}

/// Step 4 (D11, D13): the tangent of the wrench link k exerts on its antecedent, with the
/// terms of the moving placement along q_k (d(iA_k)/dq_k = iA_k [e_z]x for a revolute joint,
/// d(iP_k)/dq_k = iA_k e_z for a prismatic one), carried down to the base, projected on each
/// ancestor's axis into column `col` of `dq`, `dqd`.
fn transmit(
    model: &DynModel<f64>,
    ws: &Data,
    dir: &[Tangent; 2],
    k: usize,
    dq: &mut [f64],
    dqd: &mut [f64],
) {
    let fr = model.frame(k);
    let (f, m) = (&ws.f[k], &ws.m[k]);
    let [tq, tv] = dir;
    let (mut fq, mut mq) = match fr.joint {
        JointType::Revolute => (tq.f[k] + z_cross(f), tq.m[k] + z_cross(m)),
        JointType::Prismatic => (tq.f[k], tq.m[k] + z_cross(f)),
        JointType::Fixed => (tq.f[k], tq.m[k]),
    };
    let (mut fv, mut mv) = (tv.f[k], tv.m[k]);
    let mut j = k;
    loop {
        let frj = model.frame(j);
        (fq, mq) = to_antecedent(frj, ws, j, &fq, &mq);
        (fv, mv) = to_antecedent(frj, ws, j, &fv, &mv);
        let i = frj.ant;
        if i == 0 {
            break;
        }
        let fri = model.frame(i);
        dq[i - 1] = project(fri, &fq, &mq);
        dqd[i - 1] = project(fri, &fv, &mv);
        j = i;
    }
}

/// The kernel on tree arrays of the model of the dynamic recursions ([`Robot::dynamic`]: every
/// link movable, the subtrees of [`crate::model::TreeIndex`] hold every successor;
/// `tau`, `q`, `qd`, `qdd` of N entries): the nominal Newton–Euler pass into `tau`, then
/// dGamma/dq and dGamma/dqd column by column (steps 1–4). Allocation-free.
#[allow(clippy::too_many_arguments)]
pub(crate) fn idm_derivative_columns(
    model: &DynModel<f64>,
    ws: &mut Data,
    dir: &mut [Tangent; 2],
    env: &Environment,
    (q, qd, qdd): (&[f64], &[f64], &[f64]),
    tau: &mut [f64],
    dtau_dq: &mut DMatrix<f64>,
    dtau_dqd: &mut DMatrix<f64>,
) {
    let n = model.nl;
    rnea_with_environment(model, ws, env, q, qd, qdd, tau);
    if n == 0 {
        return;
    }
    let idx = &model.index;
    if !idx.serial {
        dtau_dq.as_mut_slice().fill(0.0);
        dtau_dqd.as_mut_slice().fill(0.0);
    }
    let cq = dtau_dq.as_mut_slice().chunks_exact_mut(n);
    let cv = dtau_dqd.as_mut_slice().chunks_exact_mut(n);
    for ((k, dq), dqd) in (1..=n).zip(cq).zip(cv) {
        let (s, e) = idx.subtree[k];
        debug_assert!(idx.movable[k] && idx.preorder[s] == k, "a folded model");
        seed(model, ws, dir, k, qd[k - 1], qdd[k - 1]);
        propagate(model, ws, dir, qd, s, e);
        accumulate(model, ws, dir, (s, e), dq, dqd);
        transmit(model, ws, dir, k, dq, dqd);
        // viscous friction Fv qd_k (10.12); Fs sign(qd_k) has a zero derivative off qd_k = 0
        dqd[k - 1] += model.link(k).fv;
    }
}

/// Derivatives of the inverse dynamic model into `out`: Gamma itself, dGamma/dq, dGamma/dqd and
/// A = dGamma/dqdd (N x N over the movable joints, frame order) at positions `q` (rad, m),
/// velocities `qd` and accelerations `qdd` over the movable joints, under `env` (gravity, base
/// motion, external wrenches, constant in the link frames). Allocation-free.
///
/// Coulomb friction contributes nothing to dGamma/dqd (zero derivative off qd = 0); viscous
/// friction adds Fv on its diagonal; rotor inertias are on A's diagonal.
///
/// Errors: [`crate::Error::Dimension`] for a vector or matrix of the wrong size or a `data` of
/// another robot, [`crate::Error::NotFinite`] for a NaN or infinite input,
/// [`crate::Error::Numerical`] for a result that overflows.
///
/// # Example
///
/// ```
/// use robodyn::algorithms::derivatives::{
///     inverse_dynamics_derivatives_into, DerivativesData, IdmDerivatives,
/// };
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
/// let robot = robodyn::io::load(path)?;
/// let mut data = DerivativesData::new(&robot);
/// let mut d = IdmDerivatives::new(&robot);
/// let (q, qd, qdd) = ([0.1; 6], [0.2; 6], [0.3; 6]);
/// let env = robot.environment();
/// inverse_dynamics_derivatives_into(&robot, &mut data, env, &q, &qd, &qdd, &mut d)?;
/// // A = dGamma/dqdd is the inertia matrix, tau the inverse model's torques
/// assert!((&d.a - robodyn::inertia_matrix(&robot, &q)?).amax() < 1e-12);
/// let tau = robodyn::inverse_dynamics(&robot, &q, &qd, &qdd)?;
/// assert!((&d.tau - tau).amax() < 1e-12);
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn inverse_dynamics_derivatives_into(
    robot: &Robot,
    data: &mut DerivativesData,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    out: &mut IdmDerivatives,
) -> Result<()> {
    data.check(robot)?;
    check_state(robot, &data.data, ["q", "qd", "qdd"], [q, qd, qdd])?;
    env.check(robot.nl())?;
    check_square(
        robot,
        &[
            ("dtau_dq", &out.dtau_dq),
            ("dtau_dqd", &out.dtau_dqd),
            ("A", &out.a),
        ],
    )?;
    if out.tau.len() != robot.dof() {
        let n = robot.dof();
        let what = robot.coordinates().describe("movable joints");
        return Err(Error::dimension("tau", n, out.tau.len(), what));
    }
    let model = robot.dynamic();
    let DerivativesData {
        data: ws, world, h, ..
    } = data;
    idm_derivatives_world(
        model,
        ws,
        world,
        env,
        (q, qd, qdd),
        h,
        [&mut out.dtau_dq, &mut out.dtau_dqd],
        Some(&mut out.a),
    );
    out.tau.as_mut_slice().copy_from_slice(h);
    check_finite_matrix("dtau_dq", &out.dtau_dq)?;
    check_finite_matrix("dtau_dqd", &out.dtau_dqd)?;
    check_finite_matrix("A", &out.a)
}

/// [`inverse_dynamics_derivatives_into`] with the robot's own environment; allocates its
/// result (and a [`DerivativesData`]): use the `_into` form in loops.
pub fn inverse_dynamics_derivatives(
    robot: &Robot,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Result<IdmDerivatives> {
    let mut out = IdmDerivatives::new(robot);
    let mut data = DerivativesData::new(robot);
    let env = robot.environment();
    inverse_dynamics_derivatives_into(robot, &mut data, env, q, qd, qdd, &mut out)?;
    Ok(out)
}

/// [`inverse_dynamics_derivatives_into`] over a batch of states spread over the cores
/// ([`crate::batch`]): `q`, `qd`, `qdd` row-major (state s at `s * N .. (s + 1) * N`), `out`
/// receives per state the three N x N matrices dGamma/dq, dGamma/dqd, A one after the other,
/// each column-major (3 N^2 entries per state). Returns the number of states.
///
/// Errors: as the `_into` form, the failing state as [`crate::Error::Row`];
/// [`crate::Error::Dimension`] when `out` is not 3 N^2 per state.
pub fn inverse_dynamics_derivatives_batch(
    robot: &Robot,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    out: &mut [f64],
) -> Result<usize> {
    let n = robot.dof();
    let rows = count_rows(n, &[("q", q), ("qd", qd), ("qdd", qdd)])?;
    let r = |s: usize| s * n..(s + 1) * n;
    let scratch = || (DerivativesData::new(robot), IdmDerivatives::new(robot));
    for_each_row(rows, out, 3 * n * n, scratch, |(data, d), s, o| {
        inverse_dynamics_derivatives_into(robot, data, env, &q[r(s)], &qd[r(s)], &qdd[r(s)], d)?;
        let (a, rest) = o.split_at_mut(n * n);
        let (b, c) = rest.split_at_mut(n * n);
        a.copy_from_slice(d.dtau_dq.as_slice());
        b.copy_from_slice(d.dtau_dqd.as_slice());
        c.copy_from_slice(d.a.as_slice());
        Ok(())
    })?;
    Ok(rows)
}
