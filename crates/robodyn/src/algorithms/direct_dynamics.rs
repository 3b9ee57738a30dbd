//! Direct dynamic model of tree robots, qdd = f(q, qd, Gamma) (§10.2.3 with the two methods of
//! the book's §9.7):
//! - [`ddm_composite`]: qdd = A^-1 (Gamma - H), A by composite links, H by Newton–Euler with
//!   qdd = 0, solved with the sparse L'DL factorization of the tree (A = L' D L with L_ij != 0
//!   only when j is an ancestor of i; the antecedent order a(j) < j is a valid elimination
//!   order, so there is no fill-in);
//! - [`ddm_aba`]: the O(n) recursive Newton–Euler direct model (articulated bodies), written with
//!   jA_i, jP_i and the 6x6 spatial inertia about O_j.
//!
//! The checked functions [`direct_dynamics`] / [`direct_dynamics_into`] work over the movable
//! joints; [`ddm_composite`] and [`ddm_aba`] are the kernels on tree arrays (NL entries, fixed
//! frames ignored in Gamma and given qdd = 0). All are allocation-free with a [`Data`]. A
//! singular or non-positive-definite model (e.g. a massless chain end) is an
//! [`Error::Singular`] naming the joint, never a NaN.

use crate::algorithms::inertia_matrix::composite_inertia_matrix;
use crate::algorithms::inverse_dynamics::{folded_wrench, rnea_with_environment, tree_vector_map};
use crate::data::{with_data, Data};
use crate::error::{Configuration, Error, Result};
use crate::model::{DynModel, Environment, JointType, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, DVector, Matrix3, Matrix6, Vector3, Vector6};

/// Relative size under which a pivot or an articulated inertia counts as zero.
const PIVOT_TOL: f64 = 1e-12;

/// Which direct-dynamics algorithm to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Method {
    /// qdd = A^-1 (Gamma - H) with the tree L'DL factorization (§9.7, first method).
    #[default]
    Composite,
    /// O(n) recursive Newton–Euler direct model / articulated bodies (§9.7, second method).
    ArticulatedBody,
}

impl Method {
    /// Every method (what a command line or a binding offers; [`Method::name`] names each).
    pub const ALL: [Method; 2] = [Method::Composite, Method::ArticulatedBody];

    /// The method's name: `composite`, `aba` ([`Method::from_name`] reads it back).
    pub fn name(self) -> &'static str {
        match self {
            Method::Composite => "composite",
            Method::ArticulatedBody => "aba",
        }
    }

    /// The method of a name of [`Method::name`] (or `articulated` for `aba`).
    pub fn from_name(name: &str) -> Option<Method> {
        match name {
            "articulated" => Some(Method::ArticulatedBody),
            _ => Method::ALL.into_iter().find(|m| m.name() == name),
        }
    }

    /// What the method computes, in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            Method::Composite => {
                "qdd = A^-1 (tau - H), A by composite links, tree L'DL factorization"
            }
            Method::ArticulatedBody => {
                "O(n) recursive Newton-Euler direct model (articulated bodies)"
            }
        }
    }
}

/// A usable pivot: finite and above the relative tolerance (false for NaN).
#[inline]
pub(crate) fn pivot_ok(d: f64, scale: f64) -> bool {
    d.is_finite() && d > PIVOT_TOL * scale
}

pub(crate) fn singular(j: usize, what: &str, value: f64, scale: f64) -> Error {
    Error::Singular {
        what: format!("{what} of joint {j}"),
        rcond: if scale > 0.0 { value / scale } else { 0.0 },
        limit: PIVOT_TOL,
        at: Configuration::Pivot {
            joint: j,
            pivot: value,
        },
        hint: format!(
            "the direct dynamic model is singular: the links carried by joint {j} have no mass \
             or inertia along its axis (e.g. a massless chain end) or the inertial parameters \
             are not physical"
        ),
    }
}

/// In-place L'DL factorization of A exploiting the tree (Featherstone's LTDL), on the upper
/// triangle: on return the diagonal holds D and entry (j, i), j a movable ancestor of i, holds
/// L_ij. Only the upper triangle is read (A is symmetric; the lower one is left as it was), so
/// that the entries of joint i's ancestors are one column of the column-major storage, contiguous
/// for a serial chain. Walks the parent array of the movable joints
/// ([`crate::model::TreeIndex::movable_parent`]); rows/columns of fixed frames are skipped. Zero
/// or negative pivot -> error naming the joint.
pub fn ltdl_factor(model: &DynModel<f64>, a: &mut DMatrix<f64>) -> Result<()> {
    let n = model.nl;
    let idx = &model.index;
    let lambda = &idx.movable_parent;
    let h = a.as_mut_slice();
    // entry (r, c) of links r, c (1-based) at (r - 1) + (c - 1) n
    let at = |r: usize, c: usize| (r - 1) + (c - 1) * n;
    let scale = (1..=n)
        .filter(|&j| idx.movable[j])
        .map(|j| h[at(j, j)].abs())
        .fold(0.0, f64::max);
    for k in (1..=n).rev() {
        if !idx.movable[k] {
            continue;
        }
        let dk = h[at(k, k)];
        if !pivot_ok(dk, scale) {
            return Err(singular(k, "the inertia matrix A (L'DL pivot)", dk, scale));
        }
        if idx.serial {
            // ancestors of k: 1..k-1, column k rows 0..k-1; same for every ancestor i
            let (head, tail) = h.split_at_mut((k - 1) * n);
            let ck = &mut tail[..k - 1];
            for i in (1..k).rev() {
                let f = ck[i - 1] / dk;
                let ci = &mut head[(i - 1) * n..(i - 1) * n + i];
                for (x, y) in ci.iter_mut().zip(&ck[..i]) {
                    *x -= f * y;
                }
                ck[i - 1] = f;
            }
            continue;
        }
        let mut i = lambda[k];
        while i != 0 {
            let f = h[at(i, k)] / dk;
            let mut j = i;
            while j != 0 {
                h[at(j, i)] -= f * h[at(j, k)];
                j = lambda[j];
            }
            h[at(i, k)] = f;
            i = lambda[i];
        }
    }
    Ok(())
}

/// Solve L'DL x = b in place after [`ltdl_factor`] (entries of fixed frames set to 0).
pub fn ltdl_solve(model: &DynModel<f64>, a: &DMatrix<f64>, x: &mut [f64]) {
    let n = model.nl;
    let idx = &model.index;
    let lambda = &idx.movable_parent;
    let h = a.as_slice();
    let at = |r: usize, c: usize| (r - 1) + (c - 1) * n;
    for i in (1..=n).rev() {
        if !idx.movable[i] {
            x[i - 1] = 0.0;
            continue;
        }
        let xi = x[i - 1];
        if xi == 0.0 {
            // nothing to carry (the unit columns of A^-1 start mostly at zero)
            continue;
        }
        let mut j = lambda[i];
        while j != 0 {
            x[j - 1] -= h[at(j, i)] * xi;
            j = lambda[j];
        }
    }
    for i in 1..=n {
        if idx.movable[i] {
            x[i - 1] /= h[at(i, i)];
        }
    }
    for i in 1..=n {
        if !idx.movable[i] {
            continue;
        }
        let mut j = lambda[i];
        let mut s = x[i - 1];
        while j != 0 {
            s -= h[at(j, i)] * x[j - 1];
            j = lambda[j];
        }
        x[i - 1] = s;
    }
}

pub(crate) fn check_finite(qdd: &[f64]) -> Result<()> {
    match qdd.iter().position(|x| !x.is_finite()) {
        Some(k) => Err(Error::Numerical(format!(
            "joint {}: the direct dynamic model gives a non-finite acceleration ({})",
            k + 1,
            qdd[k]
        ))),
        None => Ok(()),
    }
}

/// qdd = A^-1 (Gamma - H) (§9.7 first method) with the tree L'DL factorization: the kernel on
/// tree arrays (NL entries). Allocation-free.
#[allow(clippy::too_many_arguments)]
pub fn ddm_composite(
    model: &DynModel<f64>,
    ws: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    // A in the buffer of its size: NL x NL for the full model, N x N for the model of the
    // dynamic recursions (sized here at the first call of a Data made for another model)
    let n = model.nl;
    let full = ws.a.nrows() == n;
    let slot = if full { &mut ws.a } else { &mut ws.a_dyn };
    let mut a = std::mem::replace(slot, DMatrix::zeros(0, 0));
    if a.shape() != (n, n) {
        a = DMatrix::zeros(n, n);
    }
    let mut h = std::mem::take(&mut ws.h);
    let z = std::mem::take(&mut ws.zeros);
    composite_inertia_matrix(model, ws, q, &mut a);
    rnea_with_environment(model, ws, env, q, qd, &z, &mut h);
    let r = ltdl_factor(model, &mut a);
    if r.is_ok() {
        for j in 0..model.nl {
            qdd[j] = tau[j] - h[j];
        }
        ltdl_solve(model, &a, qdd);
    }
    if full {
        ws.a = a;
    } else {
        ws.a_dyn = a;
    }
    ws.h = h;
    ws.zeros = z;
    r?;
    check_finite(qdd)
}

#[inline]
fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

// Spatial transformations between R_i = R_a(k) and R_k, with R = iA_k, p = iP_k:
// kT_i = [[R', -R' skew(p)], [0, R']] maps [linear; angular] motion from R_i to R_k; its
// transpose maps wrenches back. Written with 3x3 blocks (no 6x6 products).

/// kT_i V: the motion V of frame i seen at O_k in R_k: [R' (v + w x p); R' w].
#[inline]
fn motion_to_child(r: &Matrix3<f64>, p: &Vector3<f64>, v: &Vector6<f64>) -> Vector6<f64> {
    let lin = Vector3::new(v[0], v[1], v[2]);
    let ang = Vector3::new(v[3], v[4], v[5]);
    let l = r.tr_mul(&(lin + ang.cross(p)));
    let a = r.tr_mul(&ang);
    Vector6::new(l.x, l.y, l.z, a.x, a.y, a.z)
}

/// kT_i' F: the wrench F at O_k in R_k moved to O_i in R_i: [R f; p x R f + R m].
#[inline]
fn wrench_to_parent(r: &Matrix3<f64>, p: &Vector3<f64>, f: &Vector6<f64>) -> Vector6<f64> {
    let fi = r * Vector3::new(f[0], f[1], f[2]);
    let mi = r * Vector3::new(f[3], f[4], f[5]) + p.cross(&fi);
    Vector6::new(fi.x, fi.y, fi.z, mi.x, mi.y, mi.z)
}

/// kT_i' K kT_i for a symmetric K (an inertia in R_k about O_k moved to R_i about O_i).
/// With B = R K R' blockwise and S = skew(p):
/// [[B11, B12 - B11 S], [sym, S (B12 - B11 S) + B22 - B12' S]].
#[inline]
fn inertia_to_parent(r: &Matrix3<f64>, p: &Vector3<f64>, k: &Matrix6<f64>) -> Matrix6<f64> {
    let k11 = k.fixed_view::<3, 3>(0, 0);
    let k12 = k.fixed_view::<3, 3>(0, 3);
    let k22 = k.fixed_view::<3, 3>(3, 3);
    let b11 = r * k11 * r.transpose();
    let b12 = r * k12 * r.transpose();
    let b22 = r * k22 * r.transpose();
    let s = skew(p);
    let c = b12 - b11 * s;
    let d = s * c + b22 - b12.transpose() * s;
    let mut out = Matrix6::zeros();
    out.fixed_view_mut::<3, 3>(0, 0).copy_from(&b11);
    out.fixed_view_mut::<3, 3>(0, 3).copy_from(&c);
    out.fixed_view_mut::<3, 3>(3, 0).copy_from(&c.transpose());
    out.fixed_view_mut::<3, 3>(3, 3).copy_from(&d);
    out
}

/// Index of the joint axis a_j in a [linear; angular] spatial vector.
#[inline]
fn axis_index(joint: JointType) -> Option<usize> {
    match joint {
        JointType::Revolute => Some(5),
        JointType::Prismatic => Some(2),
        JointType::Fixed => None,
    }
}

/// The O(n) recursive Newton–Euler direct dynamic model (articulated bodies, §9.7 second method).
///
/// Link j's equation is F_j = J_j Vd_j + beta_j with the spatial inertia about O_j
/// J_j = [[M_j I, -skew(MS_j)], [skew(MS_j), J_j]], the classical accelerations
/// Vd_j = [jVd_j; jwd_j] = jT_i Vd_i + gamma_j + a_j qdd_j (eqs 10.4–10.6 split into the
/// qdd-free part gamma_j and a_j = [sigma_j z; sigma_bar_j z]) and
/// beta_j = [w x (w x MS) + fe; w x (J w) + me] (eqs 10.7–10.8). Backward, the articulated
/// inertia J*_j and bias beta*_j with F_j = J*_j Vd_j + beta*_j collect the children through
/// K_k = J*_k - u_k u_k' / H_k, u_k = J*_k a_k, H_k = a_k' u_k + Ia_k; forward,
/// qdd_j = (Gamma_j - friction - u_j' (jT_i Vd_i + gamma_j) - a_j' beta*_j) / H_j (eq 10.12).
#[allow(clippy::too_many_arguments)]
pub fn ddm_aba(
    model: &DynModel<f64>,
    b: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    let scale = aba_links(model, b, env, env.base.w0, q, qd, tau);
    aba_articulated(model, b, scale, false)?;
    let g = env.base.vp0 - env.gravity;
    let wp0 = env.base.wp0;
    let acc0 = Vector6::new(g.x, g.y, g.z, wp0.x, wp0.y, wp0.z);
    aba_accelerations(model, b, acc0, qdd);
    check_finite(qdd)
}

/// First pass of the articulated-body model, base to tips from the base's angular velocity
/// `w0` (in R_0): link velocities, gamma_j, link inertias J_j and biases beta_j (external
/// wrenches included), Gamma_j minus friction. Returns the scale of the pivots (the largest
/// mass, inertia trace or rotor inertia).
#[allow(clippy::too_many_arguments)]
pub(crate) fn aba_links(
    model: &DynModel<f64>,
    b: &mut Data,
    env: &Environment,
    w0: Vector3<f64>,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
) -> f64 {
    let n = model.nl;
    let mut scale: f64 = 0.0;
    b.w[0] = w0;
    for j in 1..=n {
        let fr = model.frame(j);
        let i = fr.ant;
        let (rot, pos) = fr.placement(&q[j - 1]);
        let rt = rot.transpose();
        let wi = rt * b.w[i];
        let wpos = b.w[i].cross(&b.w[i].cross(&pos));
        let mut lin = rt * wpos;
        let mut ang = Vector3::zeros();
        let mut w = wi;
        let s = qd[j - 1];
        match fr.joint {
            JointType::Revolute => {
                w.z += s;
                ang = Vector3::new(wi.y * s, -wi.x * s, 0.0);
            }
            JointType::Prismatic => {
                lin += Vector3::new(wi.y * s, -wi.x * s, 0.0) * 2.0;
            }
            JointType::Fixed => {}
        }
        b.gamma[j] = Vector6::new(lin.x, lin.y, lin.z, ang.x, ang.y, ang.z);
        let l = model.link(j);
        let e = env.wrench(model.wrench_link(j));
        let (ia, bias) = body_inertia_and_bias(l, &w, &e.force, &e.moment);
        b.art_bias[j] = bias;
        b.art_inertia[j] = ia;
        b.rot[j] = rot;
        b.pos[j] = pos;
        b.w[j] = w;
        b.art_tau[j] = match fr.joint {
            JointType::Fixed => 0.0,
            _ => tau[j - 1] - l.fs * s.sign() - l.fv * s,
        };
        scale = scale
            .max(l.mass.abs())
            .max(l.inertia.trace().abs())
            .max(l.ia.abs());
    }
    for fl in &model.folded {
        if let Some((f, m)) = folded_wrench(fl, env) {
            b.art_bias[fl.host] += Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
        }
    }
    scale
}

/// The spatial inertia about O_j J_j = [[M I, -skew(MS)], [skew(MS), J]] of a body and its
/// bias beta_j = [w x (w x MS) + fe; w x (J w) + me] at angular velocity `w`, with the
/// external wrench (fe, me) it exerts on the environment.
pub(crate) fn body_inertia_and_bias(
    l: &crate::model::LinkConstants<f64>,
    w: &Vector3<f64>,
    fe: &Vector3<f64>,
    me: &Vector3<f64>,
) -> (Matrix6<f64>, Vector6<f64>) {
    let mut ia = Matrix6::zeros();
    ia.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() * l.mass));
    let sm = skew(&l.ms);
    ia.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-sm));
    ia.fixed_view_mut::<3, 3>(3, 0).copy_from(&sm);
    ia.fixed_view_mut::<3, 3>(3, 3).copy_from(&l.inertia);
    let f = w.cross(&w.cross(&l.ms)) + fe;
    let m = w.cross(&(l.inertia * w)) + me;
    (ia, Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z))
}

/// Backward pass of the articulated-body model: articulated inertias J*_j and biases beta*_j,
/// each carried to its antecedent; with `into_base`, the children of the base are carried into
/// `art_inertia[0]`, `art_bias[0]` too (a floating base, whose own body is already there).
pub(crate) fn aba_articulated(
    model: &DynModel<f64>,
    b: &mut Data,
    scale: f64,
    into_base: bool,
) -> Result<()> {
    for k in (1..=model.nl).rev() {
        let fr = model.frame(k);
        let (kk, alpha) = match axis_index(fr.joint) {
            Some(ax) => {
                let u = b.art_inertia[k].column(ax).into_owned();
                let d = u[ax] + model.link(k).ia;
                if !pivot_ok(d, scale) {
                    return Err(singular(
                        k,
                        "the articulated inertia about the joint axis",
                        d,
                        scale,
                    ));
                }
                let kk = b.art_inertia[k] - u * u.transpose() / d;
                let alpha =
                    kk * b.gamma[k] + b.art_bias[k] + u * ((b.art_tau[k] - b.art_bias[k][ax]) / d);
                b.art_u[k] = u;
                b.art_d[k] = d;
                (kk, alpha)
            }
            None => (
                b.art_inertia[k],
                b.art_inertia[k] * b.gamma[k] + b.art_bias[k],
            ),
        };
        let i = fr.ant;
        if i != 0 || into_base {
            b.art_inertia[i] += inertia_to_parent(&b.rot[k], &b.pos[k], &kk);
            b.art_bias[i] += wrench_to_parent(&b.rot[k], &b.pos[k], &alpha);
        }
    }
    Ok(())
}

/// Last pass of the articulated-body model, base to tips from the base's classical
/// acceleration minus gravity `acc0` = [Vd_0 - g; wd_0] (in R_0): the joint accelerations.
pub(crate) fn aba_accelerations(
    model: &DynModel<f64>,
    b: &mut Data,
    acc0: Vector6<f64>,
    qdd: &mut [f64],
) {
    b.acc[0] = acc0;
    for j in 1..=model.nl {
        let fr = model.frame(j);
        let mut acc = motion_to_child(&b.rot[j], &b.pos[j], &b.acc[fr.ant]) + b.gamma[j];
        match axis_index(fr.joint) {
            Some(ax) => {
                let a = (b.art_tau[j] - b.art_u[j].dot(&acc) - b.art_bias[j][ax]) / b.art_d[j];
                acc[ax] += a;
                qdd[j - 1] = a;
            }
            None => qdd[j - 1] = 0.0,
        }
        b.acc[j] = acc;
    }
}

/// Run one of the two kernels on tree arrays.
#[allow(clippy::too_many_arguments)]
pub fn ddm(
    model: &DynModel<f64>,
    ws: &mut Data,
    env: &Environment,
    method: Method,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    match method {
        Method::Composite => ddm_composite(model, ws, env, q, qd, tau, qdd),
        Method::ArticulatedBody => ddm_aba(model, ws, env, q, qd, tau, qdd),
    }
}

/// Direct dynamic model into `qdd`: the accelerations (rad/s², m/s²) of the movable joints for
/// positions `q`, velocities `qd` and joint torques/forces `tau` (N m, N), all over the movable
/// joints in frame order, under `env`, by `method`. Allocation-free. With a motor–joint
/// transmission `tau` is joint-side and the motors' reflected inertia and friction are part of
/// the model ([`crate::model::MotorDrives`]); both methods then solve A + R' Ia R densely.
///
/// Errors: [`Error::Dimension`], [`Error::NotFinite`] for bad inputs; [`Error::Singular`] when
/// the inertia matrix (or an articulated inertia) is singular.
#[allow(clippy::too_many_arguments)]
pub fn direct_dynamics_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    method: Method,
    qdd: &mut [f64],
) -> Result<()> {
    if robot.is_floating() {
        return crate::algorithms::floating_base::direct_dynamics_into(
            robot, data, env, q, qd, tau, method, qdd,
        );
    }
    let names = ["q", "qd", "tau"];
    tree_vector_map(
        robot,
        data,
        env,
        names,
        [q, qd, tau],
        "qdd",
        qdd,
        // motors without inertia and friction change nothing: the recursions alone
        |m, d, q, qd, tau, a| match robot.motor_drives().filter(|d| !d.is_inert()) {
            None => ddm(m, d, env, method, q, qd, tau, a),
            Some(drives) => ddm_with_drives(m, drives, d, env, q, qd, tau, a),
        },
    )
}

/// qdd = (A + R' Ia R)^-1 (Gamma - H - R' (Fv m_d + Fs sign(m_d))) for a robot with a
/// motor–joint transmission ([`crate::model::MotorDrives`]): A and H of the links by composite
/// links and Newton–Euler on the model of the dynamic recursions (tree arrays = joint
/// vectors), the drives added, a dense Cholesky solve (the reflected inertia couples joints
/// that need not be ancestors of each other, which neither the tree L'DL nor the articulated
/// bodies carry). Both methods come here. Allocation-free.
#[allow(clippy::too_many_arguments)]
fn ddm_with_drives(
    model: &DynModel<f64>,
    drives: &crate::model::MotorDrives,
    ws: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    let n = model.nl;
    let mut a = std::mem::replace(&mut ws.a_dyn, DMatrix::zeros(0, 0));
    if a.shape() != (n, n) {
        a = DMatrix::zeros(n, n);
    }
    let mut h = std::mem::take(&mut ws.h);
    let z = std::mem::take(&mut ws.zeros);
    crate::algorithms::inertia_matrix::composite_inertia_matrix(model, ws, q, &mut a);
    drives.add_inertia(&mut a);
    rnea_with_environment(model, ws, env, q, qd, &z, &mut h);
    drives.add_torques(qd, None, &mut h);
    ws.h = h;
    ws.zeros = z;
    let scale = a.diagonal().amax();
    let solved = match nalgebra::Cholesky::new(a) {
        Some(c) => {
            for j in 0..n {
                qdd[j] = tau[j] - ws.h[j];
            }
            let mut x = nalgebra::DVectorViewMut::from_slice(qdd, n);
            c.solve_mut(&mut x);
            let l = c.unpack_dirty();
            let lo = l.diagonal().min();
            ws.a_dyn = l;
            lo * lo > PIVOT_TOL * scale
        }
        None => false,
    };
    if !solved {
        return Err(Error::Singular {
            what: "the inertia matrix A + R' Ia R (links and reflected rotor inertias)".into(),
            rcond: 0.0,
            limit: PIVOT_TOL,
            at: crate::error::Configuration::Joints {
                name: "q",
                values: q.to_vec(),
            },
            hint: "the direct dynamic model is singular: some joint has no mass or inertia \
                   along its axis or the inertial parameters are not physical"
                .into(),
        });
    }
    check_finite(qdd)
}

/// The inputs of the direct model over the movable joints (frame order): positions `q` (rad,
/// m), velocities `qd` and joint torques/forces `tau` (N m, N). Named fields, like
/// [`crate::State`], so that a swap of the three vectors reads as one.
#[derive(Clone, Copy, Debug)]
pub struct DirectState<'a> {
    /// Joint positions (rad, m).
    pub q: &'a [f64],
    /// Joint velocities (rad/s, m/s).
    pub qd: &'a [f64],
    /// Joint torques/forces (N m, N).
    pub tau: &'a [f64],
}

/// [`direct_dynamics_into`] with the inputs as named fields: the accelerations (rad/s², m/s²)
/// of the movable joints into `qdd`. Allocation-free; the same checks and errors.
///
/// # Example
///
/// Back to the accelerations from the torques of the inverse model:
///
/// ```
/// use robodyn::{direct_dynamics_state_into, inverse_dynamics, Data, DirectState, Method};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
/// let robot = robodyn::io::load(path)?;
/// let mut data = Data::new(&robot);
/// let (q, qd, qdd) = ([0.1; 6], [0.2; 6], [0.3; 6]);
/// let tau = inverse_dynamics(&robot, &q, &qd, &qdd)?;
/// let mut back = [0.0; 6];
/// let state = DirectState { q: &q, qd: &qd, tau: tau.as_slice() };
/// let env = robot.environment();
/// direct_dynamics_state_into(&robot, &mut data, env, state, Method::Composite, &mut back)?;
/// assert!(back.iter().zip(&qdd).all(|(a, b)| (a - b).abs() < 1e-9));
/// # Ok(())
/// # }
/// ```
pub fn direct_dynamics_state_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    state: DirectState<'_>,
    method: Method,
    qdd: &mut [f64],
) -> Result<()> {
    direct_dynamics_into(robot, data, env, state.q, state.qd, state.tau, method, qdd)
}

/// Direct dynamic model with the robot's environment: qdd over the movable joints. Allocates;
/// use [`direct_dynamics_into`] in loops.
///
/// # Example
///
/// The direct model inverts the inverse one: A(q) qdd + H(q, qd) = Gamma, by either method.
///
/// ```
/// use robodyn::{direct_dynamics, h_vector, inertia_matrix, inverse_dynamics, Method};
/// # fn main() -> robodyn::Result<()> {
/// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
/// let robot = robodyn::io::load(urdf)?;
/// let q = [0.1, -0.4, 1.2, 0.3, -0.7, 0.2];
/// let qd = [0.5, 0.1, -0.3, 0.8, 0.2, -0.6];
/// let tau = [1.0, 20.0, 5.0, 0.5, 0.3, 0.1]; // N m
/// let qdd = direct_dynamics(&robot, &q, &qd, &tau, Method::ArticulatedBody)?;
/// let qdd_ldl = direct_dynamics(&robot, &q, &qd, &tau, Method::Composite)?;
/// assert!((&qdd - &qdd_ldl).amax() < 1e-9);
/// let back = inverse_dynamics(&robot, &q, &qd, qdd.as_slice())?;
/// let a_qdd_h = inertia_matrix(&robot, &q)? * &qdd + h_vector(&robot, &q, &qd)?;
/// for k in 0..6 {
///     assert!((back[k] - tau[k]).abs() < 1e-9 && (a_qdd_h[k] - tau[k]).abs() < 1e-9);
/// }
/// # Ok(())
/// # }
/// ```
pub fn direct_dynamics(
    robot: &Robot,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    method: Method,
) -> Result<DVector<f64>> {
    let mut qdd = DVector::zeros(robot.nv());
    with_data(robot, |data| {
        direct_dynamics_into(
            robot,
            data,
            robot.environment(),
            q,
            qd,
            tau,
            method,
            qdd.as_mut_slice(),
        )
    })?;
    Ok(qdd)
}
