//! Inertia matrix A(q) of a tree robot by the composite-link method and the vector H(q, qd) by
//! Newton–Euler with qdd = 0 (§10.2.3, which applies the two methods of the book's §9.7 to trees):
//! Gamma = A(q) qdd + H(q, qd).
//!
//! The checked functions ([`inertia_matrix`], [`h_vector`] and their `_into` forms) work over
//! the movable joints ([`Robot::coordinates`]). The kernel [`composite_inertia_matrix`] fills
//! the NL x NL matrix of the tree arrays (joint j at index j-1; rows and columns of fixed frames
//! zero). A_ij = 0 whenever neither of i, j is an ancestor of the other, and the rotor inertia
//! Ia_j is on the diagonal. Written once over [`DynScalar`]: the symbolic generator runs it on
//! expressions.

use crate::algorithms::inverse_dynamics::{rnea_with_environment, tree_vector_map};
use crate::data::{with_data, Data};
use crate::error::Result;
use crate::model::{
    form_row, inertia_transfer_inline, DynModel, Environment, JointType, Robot, RotationForm,
};
use crate::scalar::DynScalar;
use nalgebra::{DMatrix, DVector, Matrix3, Vector3};

/// Composite links (backward recursion j = NL..1): jJ^c, jMS^c, M^c of every link about its own
/// origin, and iA_j, iP_j, in the buffers of `ws` (kernel, tree array q).
///
/// Composite link k is moved to its antecedent by the parallel-axis theorem through frame k's
/// rotation form ([`crate::model::FrameConstants::inertia_to_antecedent`]).
pub fn composite_links<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, q: &[T]) {
    link_placements(model, ws, q);
    for k in (1..=model.nl).rev() {
        name_composite(model, ws, k);
        add_to_antecedent(model, ws, k);
    }
}

/// iA_j, iP_j of every link and the composite buffers initialized with the link's own inertia.
fn link_placements<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, q: &[T]) {
    for j in 1..=model.nl {
        let (rot, pos) = model.frame(j).placement(&q[j - 1]);
        ws.rot[j] = rot;
        ws.pos[j] = pos;
        let l = model.link(j);
        ws.jc[j] = l.inertia.clone();
        ws.msc[j] = l.ms.clone();
        ws.mc[j] = l.mass.clone();
    }
}

/// Composite link k is complete (its successors, numbered after it, are in): add it to its
/// antecedent's.
#[inline]
fn add_to_antecedent<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, k: usize) {
    let i = model.frame(k).ant;
    if i == 0 {
        return;
    }
    let (jk, ms) = model
        .frame(k)
        .inertia_to_antecedent(&ws.rot[k], &ws.pos[k], &ws.jc[k], &ws.msc[k], &ws.mc[k]);
    let mk = ws.mc[k].clone();
    ws.jc[i] += jk;
    ws.msc[i] += ms;
    ws.mc[i] += mk;
}

/// Inertia matrix A(q) (NL x NL, tree arrays) by the composite-link method: the generic kernel,
/// allocation-free.
///
/// Column j: the wrench on the composite link j for qdd = e_j (qd = 0, g = 0) is
/// f = z x MS^c, m = J^c z (revolute) or f = M^c z, m = MS^c x z (prismatic); A_jj is its
/// projection on the joint axis plus Ia_j, and A_ij (= A_ji) for every ancestor i of j is the
/// projection after transporting the wrench to R_i (eqs 10.10–10.12 with the link terms zero).
///
/// One backward pass k = NL..1 (as Pinocchio's CRBA): when composite link k is complete, the
/// column wrench of k joins those of its successors (all expressed in R_k), row k of A is their
/// projections on joint k, and then the whole subtree's column wrenches are carried to R_a(k)
/// together ([`crate::model::TreeIndex::subtree`]: a contiguous range), independent transports
/// rather than one dependent chain per column.
pub fn composite_inertia_matrix<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    q: &[T],
    a: &mut DMatrix<T>,
) {
    let n = model.nl;
    assert_eq!(a.shape(), (n, n), "A must be NL x NL");
    composite_inertia_block(model, ws, q, a.as_mut_slice(), n);
}

/// [`composite_inertia_matrix`] into an NL x NL column-major block of a larger matrix: entry
/// (r, c) at `a[r + c ld]` (`ld` >= NL, the larger matrix's row count). A floating robot's
/// joint block is written in place in its nv x nv matrix this way (no copy). The entries of
/// `a` between the block's columns (`a[r + c ld]` for r >= NL, c < NL - 1) may be zeroed: the
/// caller writes them after.
pub(crate) fn composite_inertia_block<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    q: &[T],
    a: &mut [T],
    ld: usize,
) {
    let n = model.nl;
    let idx = &model.index;
    link_placements(model, ws, q);
    if !idx.serial {
        // entries of unrelated joints (and of fixed frames) are zero; a serial chain writes all
        // (one contiguous fill, the entries between the columns of a block included: one
        // call instead of one per column; nalgebra's `fill` walks a strided iterator, 5x slower)
        if n > 0 {
            a[..(n - 1) * ld + n].fill(T::zero());
        }
    }
    for k in (1..=n).rev() {
        let fr = model.frame(k);
        let (s, e) = idx.subtree[k];
        name_composite(model, ws, k);
        if fr.joint.is_movable() {
            // composite link k is complete: its successors were added to it; its column wrench
            // (f, m), k first of its subtree in preorder
            let ms = &ws.msc[k];
            let (f, m) = if fr.joint == JointType::Revolute {
                let jz = ws.jc[k].column(2);
                let m = [jz[0].clone(), jz[1].clone(), jz[2].clone()];
                ([-ms.y.clone(), ms.x.clone(), T::zero()], m)
            } else {
                let m = [ms.y.clone(), -ms.x.clone(), T::zero()];
                ([T::zero(), T::zero(), ws.mc[k].clone()], m)
            };
            let c = &mut ws.col;
            for (x, v) in c.iter_mut().zip(f.into_iter().chain(m)) {
                x[s] = v;
            }
            // row k of A: the projections on joint k's axis (moment z, revolute; force z,
            // prismatic) of its subtree's column wrenches
            let proj = if fr.joint == JointType::Revolute {
                &c[5]
            } else {
                &c[2]
            };
            let r = k - 1;
            a[r + r * ld] = proj[s].clone() + model.link(k).ia.clone();
            for (link, v) in idx.preorder[s + 1..e].iter().zip(&proj[s + 1..e]) {
                let col = link - 1;
                a[r + col * ld] = v.clone();
                a[col + r * ld] = v.clone();
            }
        }
        add_to_antecedent(model, ws, k);
        let i = fr.ant;
        if i == 0 || s == e {
            continue;
        }
        if T::NAMED {
            transport_named(model, ws, k, i, s, e);
        } else {
            transport(fr.form(), &ws.rot[k], &ws.pos[k], &mut ws.col, s, e);
        }
    }
}

/// [`composite_inertia_block`] for a tree of short carried subtrees
/// ([`crate::model::TreeIndex::short`], the legs of a quadruped): the same entries of `a`, the
/// column wrenches kept as records in `ws.rec` instead of `ws.col`. A separate entry point,
/// so that the component kernel stays as it is.
pub(crate) fn composite_records_block(
    model: &DynModel<f64>,
    ws: &mut Data<f64>,
    q: &[f64],
    a: &mut [f64],
    ld: usize,
) {
    let n = model.nl;
    link_placements(model, ws, q);
    if !model.index.serial && n > 0 {
        a[..(n - 1) * ld + n].fill(0.0);
    }
    records_pass(model, ws, a, ld);
}

/// The backward pass of [`composite_inertia_block`] for a tree of short carried subtrees
/// ([`crate::model::TreeIndex::short`]): the column wrenches as records (`ws.rec`), each
/// carried in registers ([`carry`]).
#[inline(never)]
fn records_pass<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, a: &mut [T], ld: usize) {
    for k in (1..=model.nl).rev() {
        let fr = model.frame(k);
        let (s, e) = model.index.subtree[k];
        if fr.joint.is_movable() {
            record_row(model, ws, k, a, ld);
        }
        let i = fr.ant;
        if i == 0 {
            continue;
        }
        // composite link k into its antecedent's (add_to_antecedent, always inlined)
        let (rot, pos) = (&ws.rot[k], &ws.pos[k]);
        let (jk, ms) =
            inertia_transfer_inline(fr.form(), rot, pos, &ws.jc[k], &ws.msc[k], &ws.mc[k]);
        let mk = ws.mc[k].clone();
        ws.jc[i] += jk;
        ws.msc[i] += ms;
        ws.mc[i] += mk;
        if s == e {
            continue;
        }
        let (rot, pos, cols) = (&ws.rot[k], &ws.pos[k], &mut ws.rec[s..e]);
        match fr.form() {
            RotationForm::General => cols
                .iter_mut()
                .for_each(|w| *w = carry::<T, 3>(rot, pos, w)),
            RotationForm::Axis(0) => cols
                .iter_mut()
                .for_each(|w| *w = carry::<T, 0>(rot, pos, w)),
            RotationForm::Axis(1) => cols
                .iter_mut()
                .for_each(|w| *w = carry::<T, 1>(rot, pos, w)),
            RotationForm::Axis(_) => cols
                .iter_mut()
                .for_each(|w| *w = carry::<T, 2>(rot, pos, w)),
        }
    }
}

/// Movable joint k in [`records_pass`], its composite link complete: its column wrench (f, m),
/// first of its subtree in preorder, then row k of A, the projections on joint k's axis
/// (moment z, revolute; force z, prismatic) of its subtree's column wrenches.
#[inline(always)]
fn record_row<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    k: usize,
    a: &mut [T],
    ld: usize,
) {
    let (s, e) = model.index.subtree[k];
    let revolute = model.frame(k).joint == JointType::Revolute;
    let ms = &ws.msc[k];
    let w = if revolute {
        let jz = ws.jc[k].column(2);
        let (f0, f1) = (-ms.y.clone(), ms.x.clone());
        [
            f0,
            f1,
            T::zero(),
            jz[0].clone(),
            jz[1].clone(),
            jz[2].clone(),
        ]
    } else {
        let (m0, m1) = (ms.y.clone(), -ms.x.clone());
        [T::zero(), T::zero(), ws.mc[k].clone(), m0, m1, T::zero()]
    };
    let c = if revolute { 5 } else { 2 };
    let r = k - 1;
    a[r + r * ld] = w[c].clone() + model.link(k).ia.clone();
    let cols = &mut ws.rec[s..e];
    cols[0] = w;
    for (link, w) in model.index.preorder[s + 1..e].iter().zip(&cols[1..]) {
        let col = link - 1;
        a[r + col * ld] = w[c].clone();
        a[col + r * ld] = w[c].clone();
    }
}

/// Carry the column wrenches at preorder positions s..e from R_k to R_a(k) (rotation `rot` =
/// a(k)A_k of rotation form `form`, origin `pos` = a(k)P_k): f' = R f, m' = R m + P x f'. One
/// loop over the six component arrays, the form's zeros skipped at compile time
/// ([`form_row`]): independent iterations, vectorized for f64.
#[inline]
pub(crate) fn transport<T: DynScalar>(
    form: RotationForm,
    rot: &Matrix3<T>,
    pos: &Vector3<T>,
    col: &mut [Vec<T>; 6],
    s: usize,
    e: usize,
) {
    match form {
        RotationForm::General => transport_loop::<T, 3>(rot, pos, col, s, e),
        RotationForm::Axis(0) => transport_loop::<T, 0>(rot, pos, col, s, e),
        RotationForm::Axis(1) => transport_loop::<T, 1>(rot, pos, col, s, e),
        RotationForm::Axis(_) => transport_loop::<T, 2>(rot, pos, col, s, e),
    }
}

#[inline(always)]
fn transport_loop<T: DynScalar, const K: usize>(
    r: &Matrix3<T>,
    p: &Vector3<T>,
    col: &mut [Vec<T>; 6],
    s: usize,
    e: usize,
) {
    let [fx, fy, fz, mx, my, mz] = col;
    let (fx, fy, fz) = (&mut fx[s..e], &mut fy[s..e], &mut fz[s..e]);
    let (mx, my, mz) = (&mut mx[s..e], &mut my[s..e], &mut mz[s..e]);
    let len = fx.len();
    // equal lengths, stated once: no bounds check in the loop
    assert!(fy.len() == len && fz.len() == len && mx.len() == len);
    assert!(my.len() == len && mz.len() == len);
    let (px, py, pz) = (&p.x, &p.y, &p.z);
    for q in 0..len {
        let f = [&fx[q], &fy[q], &fz[q]];
        let (g0, g1, g2) = (
            form_row::<T, K>(r, 0, f),
            form_row::<T, K>(r, 1, f),
            form_row::<T, K>(r, 2, f),
        );
        let m = [&mx[q], &my[q], &mz[q]];
        let (n0, n1, n2) = (
            form_row::<T, K>(r, 0, m),
            form_row::<T, K>(r, 1, m),
            form_row::<T, K>(r, 2, m),
        );
        mx[q] = n0 + py.clone() * g2.clone() - pz.clone() * g1.clone();
        my[q] = n1 + pz.clone() * g0.clone() - px.clone() * g2.clone();
        mz[q] = n2 + px.clone() * g1.clone() - py.clone() * g0.clone();
        fx[q] = g0;
        fy[q] = g1;
        fz[q] = g2;
    }
}

/// One wrench (f, m) carried from R_k to R_a(k) through a rotation `r` of form `Axis(K)` (K = 3:
/// general) and the origin `p`: [R f, R m + p x R f].
#[inline(always)]
pub(crate) fn carry<T: DynScalar, const K: usize>(
    r: &Matrix3<T>,
    p: &Vector3<T>,
    w: &[T; 6],
) -> [T; 6] {
    let (f, m) = ([&w[0], &w[1], &w[2]], [&w[3], &w[4], &w[5]]);
    let (g0, g1, g2) = (
        form_row::<T, K>(r, 0, f),
        form_row::<T, K>(r, 1, f),
        form_row::<T, K>(r, 2, f),
    );
    let (n0, n1, n2) = (
        form_row::<T, K>(r, 0, m),
        form_row::<T, K>(r, 1, m),
        form_row::<T, K>(r, 2, m),
    );
    let (px, py, pz) = (&p.x, &p.y, &p.z);
    let m0 = n0 + py.clone() * g2.clone() - pz.clone() * g1.clone();
    let m1 = n1 + pz.clone() * g0.clone() - px.clone() * g2.clone();
    let m2 = n2 + px.clone() * g1.clone() - py.clone() * g0.clone();
    [g0, g1, g2, m0, m1, m2]
}

/// [`transport`] for the customized symbolic model: the wrench of column j carried to link i
/// is named (`AF<c>_<i>_<j>`, `AN<c>_<i>_<j>`, by the description's link numbers), or it would
/// grow with the depth of the tree.
fn transport_named<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    k: usize,
    i: usize,
    s: usize,
    e: usize,
) {
    let form = model.frame(k).form();
    transport(form, &ws.rot[k], &ws.pos[k], &mut ws.col, s, e);
    let li = model.wrench_link(i);
    for p in s..e {
        let lj = model.wrench_link(model.index.preorder[p]);
        for (c, x) in ws.col.iter_mut().enumerate() {
            let (tag, comp) = if c < 3 { ("AF", c + 1) } else { ("AN", c - 2) };
            x[p] = x[p].clone().named(|| format!("{tag}{comp}_{li}_{lj}"));
        }
    }
}

/// Naming hook of the customized symbolic model: the composite inertia of link k (`JP<r><c><k>`,
/// `MSP<c><k>`, `MP<k>`), so that its expression does not grow with the size of the subtree. A
/// no-op for `f64`.
#[inline(always)]
fn name_composite<T: DynScalar>(model: &DynModel<T>, ws: &mut Data<T>, k: usize) {
    if !T::NAMED {
        return;
    }
    // names carry the description's link number
    let n = model.wrench_link(k);
    let j = ws.jc[k].clone();
    ws.jc[k] = Matrix3::from_fn(|r, c| {
        let (r, c) = (r.min(c), r.max(c));
        j[(r, c)]
            .clone()
            .named(|| format!("JP{}{}{n}", r + 1, c + 1))
    });
    let ms = ws.msc[k].clone();
    ws.msc[k] = Vector3::from_fn(|c, _| ms[c].clone().named(|| format!("MSP{}{n}", c + 1)));
    ws.mc[k] = ws.mc[k].clone().named(|| format!("MP{n}"));
}

/// Inertia matrix A(q) into `a` (N x N over the movable joints, frame order; kg m², kg, and
/// kg m for the coupling of a revolute and a prismatic joint) by composite links, rotor inertias
/// on the diagonal (with a motor–joint transmission, the motors' R' Ia R,
/// [`crate::model::MotorDrives`]). `q` over the movable joints (rad, m). Allocation-free.
pub fn inertia_matrix_into(
    robot: &Robot,
    data: &mut Data,
    q: &[f64],
    a: &mut DMatrix<f64>,
) -> Result<()> {
    if robot.is_floating() {
        return crate::algorithms::floating_base::inertia_matrix_into(robot, data, q, a);
    }
    data.check(robot)?;
    let c = robot.coordinates();
    c.check("q", q, "movable joints")?;
    let n = c.len();
    if a.shape() != (n, n) {
        return Err(crate::Error::dimension(
            "A",
            n * n,
            a.len(),
            format!("{n} x {n} over {}", c.describe("movable joints")),
        ));
    }
    // the model of the dynamic recursions: its A is the matrix over the movable joints
    composite_inertia_matrix(robot.dynamic(), data, q, a);
    if let Some(drives) = robot.motor_drives() {
        drives.add_inertia(a);
    }
    crate::error::check_finite_matrix("A", a)
}

/// A(q) (N x N over the movable joints); checks its input and allocates.
pub fn inertia_matrix(robot: &Robot, q: &[f64]) -> Result<DMatrix<f64>> {
    let n = robot.nv();
    let mut a = DMatrix::zeros(n, n);
    with_data(robot, |data| inertia_matrix_into(robot, data, q, &mut a))?;
    Ok(a)
}

/// H(q, qd) into `h` (movable joints): centrifugal, Coriolis, gravity, friction and
/// external-wrench torques under `env`, i.e. the Newton–Euler torques with qdd = 0 (§9.7 method
/// 1), so that Gamma = A(q) qdd + H(q, qd). Allocation-free.
pub fn h_vector_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    h: &mut [f64],
) -> Result<()> {
    if robot.is_floating() {
        return crate::algorithms::floating_base::h_vector_into(robot, data, env, q, qd, h);
    }
    let names = ["q", "qd", "qd"];
    tree_vector_map(
        robot,
        data,
        env,
        names,
        [q, qd, qd],
        "H",
        h,
        |m, d, q, qd, _, t| {
            let z = std::mem::take(&mut d.zeros);
            rnea_with_environment(m, d, env, q, qd, &z, t);
            d.zeros = z;
            if let Some(drives) = robot.motor_drives() {
                drives.add_torques(qd, None, t);
            }
            Ok(())
        },
    )
}

/// H(q, qd) over the movable joints with the robot's environment; allocates.
pub fn h_vector(robot: &Robot, q: &[f64], qd: &[f64]) -> Result<DVector<f64>> {
    let mut h = DVector::zeros(robot.nv());
    with_data(robot, |data| {
        h_vector_into(robot, data, robot.environment(), q, qd, h.as_mut_slice())
    })?;
    Ok(h)
}
