//! dGamma/dq and dGamma/dqd of a tree in the world frame, Carpentier–Mansard's organisation
//! (docs/models/derivatives.md, eqs W1–W12): one forward and one backward pass compute, per
//! joint, world-frame spatial quantities (motion vectors at O_0 in R_0: angular part first,
//! then the velocity of the point at O_0; forces: the moment about O_0 first, then the force),
//! and each entry of an ancestor–descendant pair is then a few dot products of 6-vectors:
//!
//! 1. `forward_geometry`: placements 0T_j, joint axes S_j, velocities V_j, the pair terms
//!    u_j = V_i x S_j (i the antecedent), each link's spatial inertia I_j, its rate
//!    dI_j = V_j x* I_j - I_j V_j x and momentum I_j V_j (W1–W5, the parts free of qdd);
//!    `forward_accelerations`: accelerations A_j (gravity as a base acceleration) and
//!    w_j = A_i x S_j + V_i x u_j (W2–W3);
//! 2. `composite_inertias`: the sums of I, dI and the momenta over each subtree;
//!    `subtree_wrenches`: the subtree's total wrench F_j from the nominal Newton–Euler pass (W6);
//! 3. `pair_rows`, for joint i and each ancestor-or-self j: dGamma_i/dq_j and
//!    dGamma_i/dqd_j (W7–W9);
//! 4. and in the same walk, for j a strict ancestor: dGamma_j/dq_i = S_j . g_i and
//!    dGamma_j/dqd_i = S_j . p_i (W10–W12).
//!
//! The cost is O(N) 6 x 6 products plus four dot products per pair, against one restricted
//! Newton–Euler pass per column for the kernel of [`super::inverse`].
//!
//! The direct model's derivatives use the steps apart ([`world_inertia_matrix`] before qdd is
//! known, [`ddm_rows`] after), on one nominal pass at qdd = 0: A comes from the composite
//! inertias of step 2 (A_ij = Ic_i S_i . S_j), and the wrenches of the accelerations qdd are
//! added to that pass's (Newton–Euler is linear in qdd), so the placements are computed once.

use crate::algorithms::inverse_dynamics::rnea_with_environment;
use crate::data::Data;
use crate::model::{DynModel, Environment, JointType};
use nalgebra::{DMatrix, Matrix3, Matrix6, Vector3, Vector6};

/// The world-frame terms per link (index j, 0 the base), made once per robot and reused.
#[derive(Clone, Debug)]
pub(crate) struct WorldTerms {
    rot: Vec<Matrix3<f64>>,
    pos: Vec<Vector3<f64>>,
    /// S_j: joint j's axis as a motion (W1).
    s: Vec<Vector6<f64>>,
    v: Vec<Vector6<f64>>,
    a: Vec<Vector6<f64>>,
    /// u_j = V_i x S_j, w_j = A_i x S_j + V_i x u_j (W3).
    u: Vec<Vector6<f64>>,
    w: Vec<Vector6<f64>>,
    /// I_j, then the composite inertia of j's subtree.
    ic: Vec<Matrix6<f64>>,
    /// I_j (the direct model's wrenches of the accelerations qdd).
    link: Vec<Matrix6<f64>>,
    /// The part of A_j due to qdd (the direct model's), then I_j times it.
    da: Vec<Vector6<f64>>,
    y: Vec<Vector6<f64>>,
    /// dI_j, then its sum over j's subtree.
    bc: Vec<Matrix6<f64>>,
    /// I_j V_j, then the subtree's momentum.
    hc: Vec<Vector6<f64>>,
    /// The total wrench on link j's subtree (moment about O_0, force).
    fc: Vec<Vector6<f64>>,
}

impl WorldTerms {
    pub(crate) fn new(nl: usize) -> Self {
        let v6 = || vec![Vector6::zeros(); nl + 1];
        let m6 = || vec![Matrix6::zeros(); nl + 1];
        WorldTerms {
            rot: vec![Matrix3::identity(); nl + 1],
            pos: vec![Vector3::zeros(); nl + 1],
            s: v6(),
            v: v6(),
            a: v6(),
            u: v6(),
            w: v6(),
            ic: m6(),
            link: m6(),
            da: v6(),
            y: v6(),
            bc: m6(),
            hc: v6(),
            fc: v6(),
        }
    }
}

fn ang(x: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(x[0], x[1], x[2])
}

fn lin(x: &Vector6<f64>) -> Vector3<f64> {
    Vector3::new(x[3], x[4], x[5])
}

fn join(a: &Vector3<f64>, b: &Vector3<f64>) -> Vector6<f64> {
    Vector6::new(a.x, a.y, a.z, b.x, b.y, b.z)
}

/// The motion cross product x × y = (wx × wy, wx × vy + vx × wy).
#[inline(always)]
fn cross_m(x: &Vector6<f64>, y: &Vector6<f64>) -> Vector6<f64> {
    let (wx, vx, wy, vy) = (ang(x), lin(x), ang(y), lin(y));
    join(&wx.cross(&wy), &(wx.cross(&vy) + vx.cross(&wy)))
}

/// The force cross product x ×* f = (wx × n + vx × f, wx × f).
#[inline(always)]
fn cross_f(x: &Vector6<f64>, f: &Vector6<f64>) -> Vector6<f64> {
    let (wx, vx, n, ff) = (ang(x), lin(x), ang(f), lin(f));
    join(&(wx.cross(&n) + vx.cross(&ff)), &wx.cross(&ff))
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// The spatial inertia of link j at O_0 in R_0 (W4): [[I_O, [c]x], [[c]x^T, M 1]] with
/// c = M P + s the first moment about O_0 (s = R MS) and
/// I_O = R J R^T - M [P]x^2 - [P]x [s]x - [s]x [P]x the inertia about O_0, written with
/// [a]x [b]x = b a^T - (a . b) 1 as R J R^T + P . (c + s) 1 - c P^T - P s^T.
fn world_inertia(
    model: &DynModel<f64>,
    j: usize,
    r: &Matrix3<f64>,
    p: &Vector3<f64>,
) -> Matrix6<f64> {
    let l = model.link(j);
    let s = r * l.ms;
    let c = p * l.mass + s;
    let io = r * l.inertia * r.transpose() + Matrix3::from_diagonal_element(p.dot(&(c + s)))
        - c * p.transpose()
        - p * s.transpose();
    let cx = skew(&c);
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&io);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&cx);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&cx.transpose());
    m.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * l.mass));
    m
}

/// The rate of a spatial inertia moving with V: V x* I - I V x = X + X^T with X = (V x*) I (W5),
/// from the blocks: (V x*) = [[w x, v x], [0, w x]] and I = [[I_O, C], [C^T, M 1]].
fn inertia_rate(v: &Vector6<f64>, i: &Matrix6<f64>) -> Matrix6<f64> {
    let (w, vl) = (skew(&ang(v)), skew(&lin(v)));
    let io = i.fixed_view::<3, 3>(0, 0);
    let c = i.fixed_view::<3, 3>(0, 3);
    let m = i[(3, 3)];
    let mut x = Matrix6::zeros();
    x.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(w * io + vl * c.transpose()));
    x.fixed_view_mut::<3, 3>(0, 3).copy_from(&(w * c + vl * m));
    x.fixed_view_mut::<3, 3>(3, 0)
        .copy_from(&(w * c.transpose()));
    x.fixed_view_mut::<3, 3>(3, 3).copy_from(&(w * m));
    x + x.transpose()
}

/// Step 1 (W1, W3–W5): the world placements, axes and velocities of links 1..N from the
/// nominal pass's antecedent placements iA_j, iP_j, u_j = V_i x S_j, and the links' inertial
/// terms. With `qdd` (the inverse model), the accelerations of [`accelerate`] in the same sweep;
/// without (the direct model, whose qdd comes later), the link inertias I_j are kept instead.
fn forward_geometry(
    model: &DynModel<f64>,
    ws: &Data,
    t: &mut WorldTerms,
    env: &Environment,
    qd: &[f64],
    qdd: Option<&[f64]>,
) {
    t.v[0] = join(&env.base.w0, &Vector3::zeros());
    t.a[0] = base_acceleration(env);
    for j in 1..=model.nl {
        let fr = model.frame(j);
        let i = fr.ant;
        let r = t.rot[i] * ws.rot[j];
        let p = t.pos[i] + t.rot[i] * ws.pos[j];
        let z = Vector3::new(r[(0, 2)], r[(1, 2)], r[(2, 2)]);
        let s = match fr.joint {
            JointType::Revolute => join(&z, &p.cross(&z)),
            JointType::Prismatic => join(&Vector3::zeros(), &z),
            JointType::Fixed => Vector6::zeros(),
        };
        let vi = t.v[i];
        let u = cross_m(&vi, &s);
        let v = vi + s * qd[j - 1];
        let inertia = world_inertia(model, j, &r, &p);
        t.hc[j] = inertia * v;
        t.bc[j] = inertia_rate(&v, &inertia);
        t.ic[j] = inertia;
        (t.rot[j], t.pos[j], t.s[j], t.u[j], t.v[j]) = (r, p, s, u, v);
        match qdd {
            Some(qdd) => accelerate(t, j, i, qd[j - 1], qdd[j - 1]),
            None => t.link[j] = inertia,
        }
    }
}

/// The acceleration of the base (gravity as a base acceleration) as a motion at O_0.
fn base_acceleration(env: &Environment) -> Vector6<f64> {
    join(&env.base.wp0, &(env.base.vp0 - env.gravity))
}

/// Step 1 (W2–W3) for link j of antecedent i: the acceleration A_j = A_i + S_j qdd_j + u_j qd_j
/// and the pair term w_j = A_i x S_j + V_i x u_j.
#[inline(always)]
fn accelerate(t: &mut WorldTerms, j: usize, i: usize, qd: f64, qdd: f64) {
    let (s, u, vi, ai) = (t.s[j], t.u[j], t.v[i], t.a[i]);
    t.a[j] = ai + s * qdd + u * qd;
    t.w[j] = cross_m(&ai, &s) + cross_m(&vi, &u);
}

/// Step 1 (W2–W3) after [`forward_geometry`] without qdd: [`accelerate`] over links 1..N.
fn forward_accelerations(model: &DynModel<f64>, t: &mut WorldTerms, qd: &[f64], qdd: &[f64]) {
    for j in 1..=model.nl {
        accelerate(t, j, model.frame(j).ant, qd[j - 1], qdd[j - 1]);
    }
}

/// The wrenches I_j dA_j of the accelerations qdd alone (dA_j = dA_i + S_j qdd_j), into `y`:
/// what a nominal pass at qdd = 0 lacks of the pass at qdd.
fn acceleration_wrenches(model: &DynModel<f64>, t: &mut WorldTerms, qdd: &[f64]) {
    for j in 1..=model.nl {
        let i = model.frame(j).ant;
        let da = t.da[i] + t.s[j] * qdd[j - 1];
        t.y[j] = t.link[j] * da;
        t.da[j] = da;
    }
}

/// Step 2 (W6): the subtree sums of I, dI and the momenta (children after their antecedent in
/// frame order, so one reverse sweep).
fn composite_inertias(model: &DynModel<f64>, t: &mut WorldTerms) {
    for j in (1..=model.nl).rev() {
        let i = model.frame(j).ant;
        if i > 0 {
            let (ic, bc, hc) = (t.ic[j], t.bc[j], t.hc[j]);
            t.ic[i] += ic;
            t.bc[i] += bc;
            t.hc[i] += hc;
        }
    }
}

/// Step 2 (W6): the subtree wrenches of the nominal pass (about O_j in R_j there) moved to O_0
/// in R_0; with `add_y`, plus the subtree sums of `y` ([`acceleration_wrenches`]).
fn subtree_wrenches(model: &DynModel<f64>, ws: &Data, t: &mut WorldTerms, add_y: bool) {
    for j in (1..=model.nl).rev() {
        let (r, p) = (&t.rot[j], &t.pos[j]);
        let f = r * ws.f[j];
        t.fc[j] = join(&(r * ws.m[j] + p.cross(&f)), &f);
        if add_y {
            let y = t.y[j];
            t.fc[j] += y;
            let i = model.frame(j).ant;
            if i > 0 {
                t.y[i] += y;
            }
        }
    }
}

/// A(q) from the composite inertias (composite links in the world frame): A_ji = Ic_i S_i . S_j
/// for j an ancestor of i or i itself, Ia_i on the diagonal; the upper triangle (as
/// [`crate::algorithms::direct_dynamics::ltdl_factor`] reads it), and with `mirror` the lower
/// one too.
fn inertia_entries(model: &DynModel<f64>, t: &WorldTerms, a: &mut DMatrix<f64>, mirror: bool) {
    for i in 1..=model.nl {
        let r1 = t.ic[i] * t.s[i];
        let mut j = i;
        while j > 0 {
            let x = r1.dot(&t.s[j]);
            a[(j - 1, i - 1)] = x;
            if mirror {
                a[(i - 1, j - 1)] = x;
            }
            j = model.frame(j).ant;
        }
        a[(i - 1, i - 1)] += model.link(i).ia;
    }
}

/// The per-joint vectors of steps 3–4 for joint i: r1 = Ic_i S_i, r2 = dIc_i^T S_i - S_i x* H_i
/// (W9–W10), g = S_i x* F_i + Ic_i w_i + dIc_i u_i + u_i x* H_i and
/// p = 2 Ic_i u_i + dIc_i S_i + S_i x* H_i (W11–W12); dIc is symmetric (X + X^T, W5), so
/// dIc^T S = dIc S serves r2 and p.
#[inline(always)]
fn joint_vectors(t: &WorldTerms, i: usize) -> [Vector6<f64>; 4] {
    let (ic, bc, s, u, h) = (&t.ic[i], &t.bc[i], &t.s[i], &t.u[i], &t.hc[i]);
    let (bs, sh) = (bc * s, cross_f(s, h));
    let r1 = ic * s;
    let g = cross_f(s, &t.fc[i]) + ic * t.w[i] + bc * u + cross_f(u, h);
    let p = ic * u * 2.0 + bs + sh;
    [r1, bs - sh, g, p]
}

/// Steps 3–4 (W9–W12), one walk per joint i over its ancestors j (and i itself):
/// dGamma_i/dq_j = r1_i . w_j + r2_i . u_j and dGamma_i/dqd_j = 2 r1_i . u_j + r2_i . S_j
/// (row i: j and the joints it carries move with q_j, qd_j), and for j != i
/// dGamma_j/dq_i = S_j . g_i and dGamma_j/dqd_i = S_j . p_i (column i: only i's subtree moves
/// with q_i, qd_i).
fn pair_rows(model: &DynModel<f64>, t: &WorldTerms, dq: &mut DMatrix<f64>, dqd: &mut DMatrix<f64>) {
    for i in 1..=model.nl {
        let [r1, r2, g, p] = joint_vectors(t, i);
        let mut j = i;
        while j > 0 {
            let sj = &t.s[j];
            let (wj, uj) = (&t.w[j], &t.u[j]);
            dq[(i - 1, j - 1)] = r1.dot(wj) + r2.dot(uj);
            dqd[(i - 1, j - 1)] = 2.0 * r1.dot(uj) + r2.dot(sj);
            if j != i {
                dq[(j - 1, i - 1)] = sj.dot(&g);
                dqd[(j - 1, i - 1)] = sj.dot(&p);
            }
            j = model.frame(j).ant;
        }
    }
}

/// The kernel on tree arrays of the model of the dynamic recursions (every link movable;
/// `tau`, `q`, `qd`, `qdd` of N entries): the nominal Newton–Euler pass into `tau`, then
/// dGamma/dq and dGamma/dqd by steps 1–4, viscous friction Fv on dGamma/dqd's diagonal
/// (Coulomb friction has a zero derivative off qd = 0), and A = dGamma/dqdd into `a` when given.
/// Allocation-free.
#[allow(clippy::too_many_arguments)]
pub(crate) fn idm_derivatives_world(
    model: &DynModel<f64>,
    ws: &mut Data,
    t: &mut WorldTerms,
    env: &Environment,
    (q, qd, qdd): (&[f64], &[f64], &[f64]),
    tau: &mut [f64],
    [dtau_dq, dtau_dqd]: [&mut DMatrix<f64>; 2],
    a: Option<&mut DMatrix<f64>>,
) {
    rnea_with_environment(model, ws, env, q, qd, qdd, tau);
    forward_geometry(model, ws, t, env, qd, Some(qdd));
    composite_inertias(model, t);
    subtree_wrenches(model, ws, t, false);
    rows(model, t, [dtau_dq, dtau_dqd]);
    if let Some(a) = a {
        if !model.index.serial {
            a.as_mut_slice().fill(0.0);
        }
        inertia_entries(model, t, a, true);
    }
}

/// Steps 3–4 and the viscous friction Fv on dGamma/dqd's diagonal (zeros first unless every
/// entry is written: a serial chain).
fn rows(model: &DynModel<f64>, t: &WorldTerms, [dtau_dq, dtau_dqd]: [&mut DMatrix<f64>; 2]) {
    if !model.index.serial {
        dtau_dq.as_mut_slice().fill(0.0);
        dtau_dqd.as_mut_slice().fill(0.0);
    }
    pair_rows(model, t, dtau_dq, dtau_dqd);
    for k in 1..=model.nl {
        dtau_dqd[(k - 1, k - 1)] += model.link(k).fv;
    }
}

/// The direct model's first half: after a nominal pass at (q, qd, qdd = 0) in `ws`, steps 1–2
/// without the accelerations and A(q) from the composite inertias into `a` (its upper
/// triangle; zeros elsewhere unless a serial chain), for the factorization that gives qdd.
pub(crate) fn world_inertia_matrix(
    model: &DynModel<f64>,
    ws: &Data,
    t: &mut WorldTerms,
    env: &Environment,
    qd: &[f64],
    a: &mut DMatrix<f64>,
) {
    if !model.index.serial {
        a.as_mut_slice().fill(0.0);
    }
    forward_geometry(model, ws, t, env, qd, None);
    composite_inertias(model, t);
    inertia_entries(model, t, a, false);
}

/// The direct model's second half, after [`world_inertia_matrix`] on the same nominal pass
/// (qdd = 0): the accelerations at `qdd` and their wrenches added to the pass's, then
/// dGamma/dq and dGamma/dqd at (q, qd, qdd) by steps 3–4.
pub(crate) fn ddm_rows(
    model: &DynModel<f64>,
    ws: &Data,
    t: &mut WorldTerms,
    (qd, qdd): (&[f64], &[f64]),
    dtau: [&mut DMatrix<f64>; 2],
) {
    forward_accelerations(model, t, qd, qdd);
    acceleration_wrenches(model, t, qdd);
    subtree_wrenches(model, ws, t, true);
    rows(model, t, dtau);
}
