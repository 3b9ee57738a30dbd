//! Dynamics of floating-base robots (the base is link 0, a free body whose motion results from
//! the dynamics), in Pinocchio's free-flyer convention (docs/models/floating_base.md):
//! q = [p (3, world), quaternion x y z w (4), joints], v = [v_0 (3), w_0 (3), joint rates] with
//! the base twist in the base frame R_0, accelerations the derivative of v, generalized forces
//! [base wrench (force, moment about O_0, in R_0); joint torques].
//!
//! The checked tree functions ([`crate::inverse_dynamics_into`], [`crate::inertia_matrix_into`],
//! [`crate::h_vector_into`], [`crate::direct_dynamics_into`]) call these for a floating robot;
//! each runs the tree kernels of the fixed base with the base as the root of the recursion:
//! - inverse dynamics: Newton–Euler with the base motion [w_0, wd_0, Vd_0 - R' g] as the root's
//!   (Vd_0 = a_0 + w_0 x v_0, the classical acceleration of O_0), the base wrench the base's own
//!   Newton–Euler wrench plus its children's (eqs 10.7–10.11 at link 0);
//! - inertia matrix: composite links; the joint block is the fixed-base A, the base rows the
//!   column wrenches carried to R_0, the base block the composite inertia of the whole robot;
//! - direct dynamics: the composite route (the block factorization: the tree L'DL of the joint
//!   block and a 6 x 6 Schur complement) or the articulated bodies with the base's articulated
//!   inertia solved at the root.

use crate::algorithms::direct_dynamics::{
    aba_accelerations, aba_articulated, aba_links, body_inertia_and_bias, ltdl_factor, ltdl_solve,
    Method,
};
use crate::algorithms::inertia_matrix::{carry, composite_inertia_block, composite_records_block};
use crate::algorithms::inverse_dynamics::{
    backward_recursion, euler_moment, folded_wrench, forward_links, name3, set_base_motion,
    w_products,
};
use crate::data::Data;
use crate::error::{check_finite_matrix, check_finite_result, check_vector, Error, Result};
use crate::model::{
    inertia_transfer_inline, DynModel, Environment, FloatingBase, Robot, RotationForm,
    QUATERNION_TOLERANCE,
};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, Matrix3, Matrix6, Quaternion, UnitQuaternion, Vector3, Vector6};

/// The floating base of a robot that has one.
fn base_of(robot: &Robot) -> &FloatingBase {
    robot
        .floating_base()
        .expect("called for floating robots only")
}

/// wR_0, the orientation of the base in the world, from entries 3..7 of q (x, y, z, w),
/// normalized; an error when its norm is farther than [`QUATERNION_TOLERANCE`] from 1.
pub fn base_rotation(q: &[f64]) -> Result<UnitQuaternion<f64>> {
    let quat = Quaternion::new(q[6], q[3], q[4], q[5]);
    let norm = quat.norm();
    if (norm - 1.0).abs() > QUATERNION_TOLERANCE {
        return Err(Error::Input(format!(
            "q[3..7] = ({}, {}, {}, {}) (x, y, z, w): the base orientation quaternion has norm \
             {norm}, not 1 (accepted within {QUATERNION_TOLERANCE}, then normalized)",
            q[3], q[4], q[5], q[6]
        )));
    }
    Ok(UnitQuaternion::from_quaternion(quat))
}

/// Check a floating state: the data and the environment against the robot, `q` with nq
/// entries (and a unit quaternion), each of `vs` with nv, the output with nv. Returns wR_0.
pub(crate) fn check_state(
    robot: &Robot,
    data: &Data,
    env: Option<&crate::Environment>,
    q: &[f64],
    vs: &[(&str, &[f64])],
    out: (&str, usize),
) -> Result<Matrix3<f64>> {
    data.check(robot)?;
    if let Some(env) = env {
        env.check(robot.nl())?;
    }
    let (nv, n) = (robot.nv(), robot.dof());
    if out.1 != nv {
        return Err(Error::dimension(out.0, nv, out.1, format!("nv = 6 + {n}")));
    }
    check_floating_vectors(robot, q, vs)
}

/// Check the vectors of a floating state: `q` with nq entries (and a unit quaternion), each of
/// `vs` with nv. Returns wR_0. The one check of the floating-base dynamic and kinematic
/// functions.
pub(crate) fn check_floating_vectors(
    robot: &Robot,
    q: &[f64],
    vs: &[(&str, &[f64])],
) -> Result<Matrix3<f64>> {
    let (nq, nv) = (robot.nq(), robot.nv());
    let n = robot.dof();
    check_vector("q", q, nq, || {
        format!("nq = 7 + {n}: base position, quaternion (x, y, z, w), joints")
    })?;
    for (name, v) in vs {
        check_vector(name, v, nv, || {
            format!("nv = 6 + {n}: base linear, angular (in the base frame), joints")
        })?;
    }
    Ok(base_rotation(q)?.to_rotation_matrix().into_inner())
}

pub(crate) fn v3(x: &[f64]) -> Vector3<f64> {
    Vector3::new(x[0], x[1], x[2])
}

/// Inverse dynamics of a floating robot into `tau` (nv): the base wrench (force, moment about
/// O_0, in R_0) then the joint torques, for q (nq), v (nv) and the accelerations a (nv).
#[allow(clippy::too_many_arguments)]
pub(crate) fn inverse_dynamics_into(
    robot: &Robot,
    data: &mut Data,
    env: &crate::Environment,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    tau: &mut [f64],
) -> Result<()> {
    let vs = [("qd", v), ("qdd", a)];
    let rot = check_state(robot, data, Some(env), q, &vs, ("tau", tau.len()))?;
    newton_euler(robot, data, env, &rot, q, v, a, tau);
    check_finite_result("tau", tau)
}

/// Newton–Euler with the base as the root (unchecked): tau over nv.
#[allow(clippy::too_many_arguments)]
fn newton_euler(
    robot: &Robot,
    data: &mut Data,
    env: &crate::Environment,
    rot: &Matrix3<f64>,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    tau: &mut [f64],
) {
    let (model, base) = (robot.dynamic(), base_of(robot));
    floating_rnea(model, base, env, data, rot, &q[7..], v, a, tau);
}

/// Newton–Euler of a floating robot with the base as the root, on any scalar (the numeric
/// robot's `f64`, the customized symbolic model's `Expr`), unchecked: the nv generalized forces
/// into `tau` (the base wrench, force then moment about O_0, in R_0; then the joint torques) for
/// the base orientation `rot` = wR_0, the joint positions `qj` (the N movable joints: tree
/// arrays of the folded `model`, [`DynModel::fold_fixed`]), the velocities `v` and the
/// accelerations `a` (nv each, Pinocchio's free-flyer convention). `base` is the base body of
/// the unfolded model ([`FloatingBase::new`]).
///
/// Steps: the root motion [w_0, wd_0, Vd_0 - R' g] with Vd_0 = a_0 + w_0 x v_0 (the classical
/// acceleration of O_0); the fixed base's forward and backward recursions from that root; the
/// base wrench, link 0's own Newton–Euler wrench (eqs 10.7–10.8 at link 0, with the external
/// wrenches of the links fixed on it) plus what its children transmit (eqs 10.10–10.11).
/// In the symbolic model the base's quantities are named `G<c>0` (R' g), `VP<c>0` (Vd_0 - R' g),
/// `U<r><c>0`, `F<c>0`, `No<c>0` (link 0's own wrench), `FDI<c><j>`, `NDI<c><j>` (from child j).
///
/// # Panics
/// If a slice is shorter than stated or `ws` was made for a smaller model.
#[allow(clippy::too_many_arguments)]
pub fn floating_rnea<T: DynScalar>(
    model: &DynModel<T>,
    base: &FloatingBase<T>,
    env: &Environment<T>,
    ws: &mut Data<T>,
    rot: &Matrix3<T>,
    qj: &[T],
    v: &[T],
    a: &[T],
    tau: &mut [T],
) {
    let v3 = |x: &[T]| Vector3::new(x[0].clone(), x[1].clone(), x[2].clone());
    let (lin, w) = (v3(&v[0..3]), v3(&v[3..6]));
    let (alin, wd) = (v3(&a[0..3]), v3(&a[3..6]));
    // the classical acceleration of O_0 minus gravity, in R_0
    let g0 = name3(rot.tr_mul(&env.gravity), "G", 0);
    let vd0 = name3(alin + w.cross(&lin) - g0, "VP", 0);
    set_base_motion(ws, w, wd, vd0);
    forward_links(model, env, ws, qj, &v[6..], &a[6..], &[]);
    backward_recursion(model, ws, &v[6..], &a[6..], &mut tau[6..]);
    let (f, m) = base_wrench(model, base, env, ws);
    let [[f0, f1, f2]] = f.data.0;
    let [[m0, m1, m2]] = m.data.0;
    for (t, x) in tau.iter_mut().zip([f0, f1, f2, m0, m1, m2]) {
        *t = x;
    }
}

/// The wrench the base needs after the recursion: its own body's Newton–Euler wrench
/// (eqs 10.7–10.8 at link 0 in the product form of the links, with the external wrenches of the
/// links fixed on it) plus the wrenches its children exert on it (eqs 10.10–10.11).
fn base_wrench<T: DynScalar>(
    model: &DynModel<T>,
    base: &FloatingBase<T>,
    env: &Environment<T>,
    ws: &Data<T>,
) -> (Vector3<T>, Vector3<T>) {
    let l = &base.body;
    let (w, wd, vd, u) = (&ws.w[0], &ws.wd[0], &ws.vd[0], &ws.u[0]);
    let (p, sq) = w_products(w);
    let f = vd * l.mass.clone() + u * &l.ms;
    let m = euler_moment(&l.inertia, &l.inertia_diff, wd, &p, &sq, u) + l.ms.cross(vd);
    let (mut f, mut m) = (name3(f, "F", 0), name3(m, "No", 0));
    for fl in &base.attached {
        if let Some((fh, mh)) = folded_wrench(fl, env) {
            f += fh;
            m += mh;
        }
    }
    for j in 1..=model.nl {
        let fr = model.frame(j);
        if fr.ant != 0 {
            continue;
        }
        let n = if T::NAMED { model.wrench_link(j) } else { j };
        let fi = name3(fr.rot_mul(&ws.rot[j], &ws.f[j]), "FDI", n);
        let mi = name3(
            fr.rot_mul(&ws.rot[j], &ws.m[j]) + ws.pos[j].cross(&fi),
            "NDI",
            n,
        );
        f += fi;
        m += mi;
    }
    (f, m)
}

/// H(q, v) of a floating robot into `h` (nv): the inverse dynamics at zero acceleration.
pub(crate) fn h_vector_into(
    robot: &Robot,
    data: &mut Data,
    env: &crate::Environment,
    q: &[f64],
    v: &[f64],
    h: &mut [f64],
) -> Result<()> {
    let rot = check_state(robot, data, Some(env), q, &[("qd", v)], ("H", h.len()))?;
    let z = std::mem::take(&mut data.zeros_v);
    newton_euler(robot, data, env, &rot, q, v, &z[..robot.nv()], h);
    data.zeros_v = z;
    check_finite_result("H", h)
}

/// The composite links and the base rows of A: the joint block A_jj into `data.a_dyn` (N x N),
/// the base rows over the joints into `data.base_rows` (row c, c = 0..6, at `c N..(c + 1) N`,
/// joint-vector order), and the base block (the 6 x 6 composite inertia of the whole robot
/// about O_0 in R_0) returned.
pub(crate) fn composite_blocks(robot: &Robot, data: &mut Data, q: &[f64]) -> Matrix6<f64> {
    let n = robot.dof();
    let mut ajj = std::mem::replace(&mut data.a_dyn, DMatrix::zeros(0, 0));
    if ajj.shape() != (n, n) {
        ajj = DMatrix::zeros(n, n);
    }
    joint_block(robot.dynamic(), data, &q[7..], ajj.as_mut_slice(), n);
    data.a_dyn = ajj;
    let mut rows = std::mem::take(&mut data.base_rows);
    let abb = base_pass(robot, data, |link, w| {
        for (c, x) in w.iter().enumerate() {
            rows[c * n + link - 1] = *x;
        }
    });
    data.base_rows = rows;
    abb
}

/// The joint block of A (the fixed-base kernel) into `a` (leading dimension `ld`): column
/// wrenches as records for a tree of short carried subtrees (`data.rec` allocated by
/// [`Data::new`] then), else by component.
fn joint_block(model: &DynModel<f64>, data: &mut Data, qj: &[f64], a: &mut [f64], ld: usize) {
    if records(model, data) {
        composite_records_block(model, data, qj, a, ld);
    } else {
        composite_inertia_block(model, data, qj, a, ld);
    }
}

/// The joint kernel keeps the column wrenches as records ([`joint_block`]).
fn records(model: &DynModel<f64>, data: &Data) -> bool {
    model.index.short && data.rec.len() > model.nl
}

/// After the joint kernel ([`composite_inertia_block`]): each child k of the base moved into
/// the base's composite link, and the column wrenches of its subtree (still in R_k) carried
/// to R_0, each handed to `put` with its link (the base rows and columns of A, written
/// where the caller keeps them). Returns the base block: the composite inertia of the whole
/// robot about O_0 in R_0.
fn base_pass(robot: &Robot, data: &Data, put: impl FnMut(usize, &[f64; 6])) -> Matrix6<f64> {
    // the layout the kernel chose
    if records(robot.dynamic(), data) {
        base_pass_in(robot, data, |p| data.rec[p], put)
    } else {
        let c = &data.col;
        base_pass_in(
            robot,
            data,
            |p| [c[0][p], c[1][p], c[2][p], c[3][p], c[4][p], c[5][p]],
            put,
        )
    }
}

/// [`base_pass`] with the column wrench at preorder position p from `cols(p)`.
#[inline(always)]
fn base_pass_in(
    robot: &Robot,
    data: &Data,
    cols: impl Fn(usize) -> [f64; 6],
    mut put: impl FnMut(usize, &[f64; 6]),
) -> Matrix6<f64> {
    let model = robot.dynamic();
    let body = &base_of(robot).body;
    let (mut jc, mut msc, mut mc) = (body.inertia, body.ms, body.mass);
    for k in 1..=model.nl {
        let fr = model.frame(k);
        if fr.ant != 0 {
            continue;
        }
        let (rot, pos) = (&data.rot[k], &data.pos[k]);
        let (jk, ms) =
            inertia_transfer_inline(fr.form(), rot, pos, &data.jc[k], &data.msc[k], &data.mc[k]);
        jc += jk;
        msc += ms;
        mc += data.mc[k];
        let (s, e) = model.index.subtree[k];
        let links = &model.index.preorder[s..e];
        match fr.form() {
            RotationForm::General => base_columns::<_, 3>(rot, pos, &cols, s, links, &mut put),
            RotationForm::Axis(0) => base_columns::<_, 0>(rot, pos, &cols, s, links, &mut put),
            RotationForm::Axis(1) => base_columns::<_, 1>(rot, pos, &cols, s, links, &mut put),
            RotationForm::Axis(_) => base_columns::<_, 2>(rot, pos, &cols, s, links, &mut put),
        }
    }
    base_block(&jc, &msc, mc)
}

/// The column wrenches at positions s.. (of `links`, in R_k) carried to R_0 through a
/// rotation of form `Axis(K)` ([`carry`]), one by one into `put`: no write back.
#[inline(always)]
fn base_columns<C: Fn(usize) -> [f64; 6], const K: usize>(
    r: &Matrix3<f64>,
    p: &Vector3<f64>,
    cols: &C,
    s: usize,
    links: &[usize],
    put: &mut impl FnMut(usize, &[f64; 6]),
) {
    for (q, &link) in links.iter().enumerate() {
        put(link, &carry::<f64, K>(r, p, &cols(s + q)));
    }
}

/// The 6 x 6 spatial inertia [M I, -skew(MS); skew(MS), J] of a composite link.
fn base_block(jc: &Matrix3<f64>, msc: &Vector3<f64>, mc: f64) -> Matrix6<f64> {
    let mut abb = Matrix6::zeros();
    let sm = skew(msc);
    abb.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() * mc));
    abb.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-sm));
    abb.fixed_view_mut::<3, 3>(3, 0).copy_from(&sm);
    abb.fixed_view_mut::<3, 3>(3, 3).copy_from(jc);
    abb
}

pub(crate) fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The inertia matrix of a floating robot into `a` (nv x nv): the joint block in place by the
/// joint kernel, then the base block and the base rows and columns by [`base_pass`], written
/// straight into A (column v = 5 + link of A: its 6 first rows, and row c's entry v).
pub(crate) fn inertia_matrix_into(
    robot: &Robot,
    data: &mut Data,
    q: &[f64],
    a: &mut DMatrix<f64>,
) -> Result<()> {
    let nv = robot.nv();
    check_state(robot, data, None, q, &[], ("A", nv))?;
    if a.shape() != (nv, nv) {
        return Err(Error::dimension(
            "A",
            nv * nv,
            a.len(),
            format!("{nv} x {nv}: nv = 6 + {}", robot.dof()),
        ));
    }
    let s = a.as_mut_slice();
    joint_block(robot.dynamic(), data, &q[7..], &mut s[6 + 6 * nv..], nv);
    let abb = base_pass(robot, data, |link, w| {
        let v = 5 + link;
        s[v * nv..v * nv + 6].copy_from_slice(w);
        for (c, x) in w.iter().enumerate() {
            s[c * nv + v] = *x;
        }
    });
    a.fixed_view_mut::<6, 6>(0, 0).copy_from(&abb);
    check_finite_matrix("A", a)
}

/// Direct dynamics of a floating robot into `qdd` (nv): the base acceleration (derivative of
/// its twist in R_0) then the joint accelerations, for q (nq), v (nv) and tau (nv: the wrench
/// applied on the base, zero for a free robot, then the joint torques).
#[allow(clippy::too_many_arguments)]
pub(crate) fn direct_dynamics_into(
    robot: &Robot,
    data: &mut Data,
    env: &crate::Environment,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    method: Method,
    qdd: &mut [f64],
) -> Result<()> {
    let vs = [("qd", v), ("tau", tau)];
    let rot = check_state(robot, data, Some(env), q, &vs, ("qdd", qdd.len()))?;
    match method {
        Method::Composite => composite_ddm(robot, data, env, &rot, q, v, tau, qdd)?,
        Method::ArticulatedBody => aba(robot, data, env, &rot, q, v, tau, qdd)?,
    }
    // one check over nv entries, named qdd[k] (the base's 6 first: not "joint k + 1")
    check_finite_result("qdd", qdd)
}

/// A a = tau - H by blocks: A_jj = L'DL (the tree factorization), X = A_jj^-1 B' (B the base
/// rows), the Schur complement S = A_bb - B X (6 x 6, Cholesky), then
/// a_b = S^-1 (r_b - B A_jj^-1 r_j) and a_j = A_jj^-1 r_j - X a_b.
#[allow(clippy::too_many_arguments)]
fn composite_ddm(
    robot: &Robot,
    data: &mut Data,
    env: &crate::Environment,
    rot: &Matrix3<f64>,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    let model = robot.dynamic();
    let n = model.nl;
    let mut h = std::mem::take(&mut data.h_v);
    let z = std::mem::take(&mut data.zeros_v);
    newton_euler(robot, data, env, rot, q, v, &z[..n + 6], &mut h[..n + 6]);
    data.zeros_v = z;
    for (x, (t, hh)) in qdd.iter_mut().zip(tau.iter().zip(&h)) {
        *x = t - hh;
    }
    data.h_v = h;
    let abb = composite_blocks(robot, data, q);
    let mut ajj = std::mem::replace(&mut data.a_dyn, DMatrix::zeros(0, 0));
    let r = ltdl_factor(model, &mut ajj).and_then(|()| {
        let (b, x) = data.base_rows.split_at_mut(6 * n);
        let x = &mut x[..6 * n];
        x.copy_from_slice(b);
        for d in 0..6 {
            ltdl_solve(model, &ajj, &mut x[d * n..(d + 1) * n]);
        }
        let (rb, rj) = qdd.split_at_mut(6);
        ltdl_solve(model, &ajj, rj);
        let s = Matrix6::from_fn(|c, d| {
            abb[(c, d)] - dot(&b[c * n..(c + 1) * n], &x[d * n..(d + 1) * n])
        });
        let rhs = Vector6::from_fn(|c, _| rb[c] - dot(&b[c * n..(c + 1) * n], rj));
        let ab = s.cholesky().ok_or_else(|| singular_base(&s))?.solve(&rhs);
        rb.copy_from_slice(ab.as_slice());
        for (d, xd) in x.chunks_exact(n).enumerate() {
            for (y, xx) in rj.iter_mut().zip(xd) {
                *y -= xx * ab[d];
            }
        }
        Ok(())
    });
    data.a_dyn = ajj;
    r
}

/// The error of a singular base block (a robot without mass, or inertial parameters that are
/// not physical).
fn singular_base(s: &Matrix6<f64>) -> Error {
    let ev = s.symmetric_eigenvalues();
    let (lo, hi) = (ev.min(), ev.amax());
    Error::Singular {
        what: "the floating base's articulated inertia (6 x 6 Schur complement of A)".into(),
        rcond: if hi > 0.0 { lo / hi } else { 0.0 },
        limit: 0.0,
        at: crate::error::Configuration::Pivot {
            joint: 0,
            pivot: lo,
        },
        hint: "the floating robot has no mass or inertia in some direction, or its inertial \
               parameters are not physical"
            .into(),
    }
}

/// Articulated bodies with a floating root: the base body's inertia and bias at the root, the
/// children's articulated inertias carried into it, its classical acceleration minus gravity
/// J*_0^-1 (tau_b - beta*_0), then the joints as on a fixed base.
#[allow(clippy::too_many_arguments)]
fn aba(
    robot: &Robot,
    data: &mut Data,
    env: &crate::Environment,
    rot: &Matrix3<f64>,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    qdd: &mut [f64],
) -> Result<()> {
    let model = robot.dynamic();
    let base = base_of(robot);
    let (lin, w) = (v3(&v[0..3]), v3(&v[3..6]));
    let scale = aba_links(model, data, env, w, &q[7..], &v[6..], &tau[6..]);
    let (ia, mut bias) =
        body_inertia_and_bias(&base.body, &w, &Vector3::zeros(), &Vector3::zeros());
    for fl in &base.attached {
        if let Some((f, m)) = folded_wrench(fl, env) {
            bias += Vector6::new(f.x, f.y, f.z, m.x, m.y, m.z);
        }
    }
    data.art_inertia[0] = ia;
    data.art_bias[0] = bias;
    aba_articulated(model, data, scale, true)?;
    let s = data.art_inertia[0];
    let rhs = Vector6::from_column_slice(&tau[..6]) - data.art_bias[0];
    let acc0 = s.cholesky().ok_or_else(|| singular_base(&s))?.solve(&rhs);
    aba_accelerations(model, data, acc0, &mut qdd[6..]);
    // back from [Vd_0 - g; wd_0] to the derivative of the twist: a = Vd_0 - w x v
    let g = rot.tr_mul(&env.gravity);
    let alin = v3(&acc0.as_slice()[0..3]) + g - w.cross(&lin);
    qdd[..3].copy_from_slice(alin.as_slice());
    qdd[3..6].copy_from_slice(&acc0.as_slice()[3..6]);
    Ok(())
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// q ⊕ v dt into `out` (nq): the configuration reached from `q` (nq) moving at the constant
/// velocity `v` (nv) for `dt` seconds. A floating base moves on SE(3), as Pinocchio's
/// `integrate`: its placement becomes M exp(v dt), the twist (v_0, w_0) being in the base
/// frame, so the quaternion stays a unit quaternion (never q + v dt); the joints move by v dt.
/// For a fixed or mobile base, q + v dt.
pub fn integrate_into(robot: &Robot, q: &[f64], v: &[f64], dt: f64, out: &mut [f64]) -> Result<()> {
    let (nq, nv, n) = (robot.nq(), robot.nv(), robot.dof());
    check_vector("q", q, nq, || format!("nq = {nq}"))?;
    check_vector("v", v, nv, || format!("nv = {nv}"))?;
    check_vector("dt", &[dt], 1, || "a time step".into())?;
    if out.len() != nq {
        return Err(Error::dimension(
            "q_next",
            nq,
            out.len(),
            format!("nq = {nq}"),
        ));
    }
    let (qb, vb) = (nq - n, nv - n);
    for k in 0..n {
        out[qb + k] = q[qb + k] + v[vb + k] * dt;
    }
    if robot.is_floating() {
        let rot = base_rotation(q)?;
        let (lin, w) = (v3(&v[0..3]) * dt, v3(&v[3..6]) * dt);
        let p = v3(&q[0..3]) + rot * (exp3_left_jacobian(&w) * lin);
        let next = rot * UnitQuaternion::from_scaled_axis(w);
        out[..3].copy_from_slice(p.as_slice());
        out[3..7].copy_from_slice(&[next.i, next.j, next.k, next.w]);
    }
    check_finite_result("q_next", out)
}

/// [`integrate_into`], allocating its result.
pub fn integrate(robot: &Robot, q: &[f64], v: &[f64], dt: f64) -> Result<nalgebra::DVector<f64>> {
    let mut out = nalgebra::DVector::zeros(robot.nq());
    integrate_into(robot, q, v, dt, out.as_mut_slice())?;
    Ok(out)
}

/// V(w) = I + (1 - cos t)/t² [w]x + (t - sin t)/t³ [w]x², t = |w|: the translation of
/// exp([v; w]) is V(w) v (series below t = 1e-4).
fn exp3_left_jacobian(w: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = w.norm_squared();
    let t = t2.sqrt();
    let (a, b) = if t < 1e-4 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    let k = skew(w);
    Matrix3::identity() + k * a + k * k * b
}
