//! dGamma/dq and dGamma/dqd of a tree in the world frame, Carpentier–Mansard's organisation
//! (docs/models/derivatives.md, eqs W1–W12): one forward and one backward pass compute, per
//! joint, world-frame spatial quantities (motion vectors at O_0 in R_0: angular part first,
//! then the velocity of the point at O_0; forces: the moment about O_0 first, then the force),
//! and each entry of an ancestor–descendant pair is then a few dot products of 6-vectors:
//!
//! 1. `forward`: placements 0T_j, joint axes S_j, velocities V_j, accelerations A_j (gravity
//!    as a base acceleration), the pair terms u_j = V_i x S_j and w_j = A_i x S_j + V_i x u_j
//!    (i the antecedent), each link's spatial inertia I_j, its rate dI_j = V_j x* I_j - I_j V_j x
//!    and momentum I_j V_j (W1–W5);
//! 2. `composites`: the sums of I, dI and the momenta over each subtree, and the subtree's
//!    total wrench F_j from the nominal Newton–Euler pass (W6);
//! 3. `descendant_rows`: for joint i and each ancestor-or-self j, dGamma_i/dq_j and
//!    dGamma_i/dqd_j (W7–W9);
//! 4. `ancestor_rows`: for joint j and each strict ancestor i, dGamma_i/dq_j = S_i . g_j and
//!    dGamma_i/dqd_j = S_i . p_j (W10–W12).
//!
//! The cost is O(N) 6 x 6 products plus four dot products per pair, against one restricted
//! Newton–Euler pass per column for the kernel of [`super::inverse`].

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
/// c = M P + R MS the first moment about O_0 and I_O = R J R^T - M [P]x^2 - [P]x [s]x - [s]x [P]x
/// (s = R MS) the inertia about O_0.
fn world_inertia(
    model: &DynModel<f64>,
    j: usize,
    r: &Matrix3<f64>,
    p: &Vector3<f64>,
) -> Matrix6<f64> {
    let l = model.link(j);
    let s = r * l.ms;
    let (sp, ss) = (skew(p), skew(&s));
    let io = r * l.inertia * r.transpose() - sp * sp * l.mass - sp * ss - ss * sp;
    let c = skew(&(p * l.mass + s));
    let mut m = Matrix6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&io);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(&c);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(&c.transpose());
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

/// Step 1 (W1–W5): the world placements and motions of links 1..N from the nominal pass's
/// antecedent placements iA_j, iP_j, and the links' inertial terms.
fn forward(
    model: &DynModel<f64>,
    ws: &Data,
    t: &mut WorldTerms,
    env: &Environment,
    qd: &[f64],
    qdd: &[f64],
) {
    let b = &env.base;
    t.v[0] = join(&b.w0, &Vector3::zeros());
    t.a[0] = join(&b.wp0, &(b.vp0 - env.gravity));
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
        let (vi, ai) = (t.v[i], t.a[i]);
        let u = cross_m(&vi, &s);
        let v = vi + s * qd[j - 1];
        t.a[j] = ai + s * qdd[j - 1] + u * qd[j - 1];
        t.w[j] = cross_m(&ai, &s) + cross_m(&vi, &u);
        let inertia = world_inertia(model, j, &r, &p);
        t.hc[j] = inertia * v;
        t.bc[j] = inertia_rate(&v, &inertia);
        t.ic[j] = inertia;
        (t.rot[j], t.pos[j], t.s[j], t.u[j], t.v[j]) = (r, p, s, u, v);
    }
}

/// Step 2 (W6): the subtree sums of I, dI and the momenta (children after their antecedent in
/// frame order, so one reverse sweep), and the subtree wrenches of the nominal pass (about
/// O_j in R_j there) moved to O_0 in R_0.
fn composites(model: &DynModel<f64>, ws: &Data, t: &mut WorldTerms) {
    for j in (1..=model.nl).rev() {
        let (r, p) = (&t.rot[j], &t.pos[j]);
        let f = r * ws.f[j];
        t.fc[j] = join(&(r * ws.m[j] + p.cross(&f)), &f);
        let i = model.frame(j).ant;
        if i > 0 {
            let (ic, bc, hc) = (t.ic[j], t.bc[j], t.hc[j]);
            t.ic[i] += ic;
            t.bc[i] += bc;
            t.hc[i] += hc;
        }
    }
}

/// Step 3 (W9–W10): for j an ancestor of i or i itself,
/// dGamma_i/dq_j = r1_i . w_j + r2_i . u_j and dGamma_i/dqd_j = 2 r1_i . u_j + r2_i . S_j with
/// r1_i = Ic_i S_i and r2_i = dIc_i^T S_i - S_i x* H_i; and, when asked, the inertia matrix
/// A_ij = A_ji = r1_i . S_j (composite links in the world frame), Ia_i on its diagonal.
fn descendant_rows(
    model: &DynModel<f64>,
    t: &WorldTerms,
    dq: &mut DMatrix<f64>,
    dqd: &mut DMatrix<f64>,
    mut a: Option<&mut DMatrix<f64>>,
) {
    for i in 1..=model.nl {
        let si = &t.s[i];
        let r1 = t.ic[i] * si;
        let r2 = t.bc[i].tr_mul(si) - cross_f(si, &t.hc[i]);
        let mut j = i;
        while j > 0 {
            dq[(i - 1, j - 1)] = r1.dot(&t.w[j]) + r2.dot(&t.u[j]);
            dqd[(i - 1, j - 1)] = 2.0 * r1.dot(&t.u[j]) + r2.dot(&t.s[j]);
            if let Some(a) = a.as_deref_mut() {
                let x = r1.dot(&t.s[j]);
                a[(i - 1, j - 1)] = x;
                a[(j - 1, i - 1)] = x;
            }
            j = model.frame(j).ant;
        }
        if let Some(a) = a.as_deref_mut() {
            a[(i - 1, i - 1)] += model.link(i).ia;
        }
    }
}

/// Step 4 (W11–W12): for i a strict ancestor of j, only j's subtree moves with q_j, qd_j:
/// dGamma_i/dq_j = S_i . g_j, g_j = S_j x* F_j + Ic_j w_j + dIc_j u_j + u_j x* H_j, and
/// dGamma_i/dqd_j = S_i . p_j, p_j = 2 Ic_j u_j + dIc_j S_j + S_j x* H_j.
fn ancestor_rows(
    model: &DynModel<f64>,
    t: &WorldTerms,
    dq: &mut DMatrix<f64>,
    dqd: &mut DMatrix<f64>,
) {
    for j in 1..=model.nl {
        let (s, u, h) = (&t.s[j], &t.u[j], &t.hc[j]);
        let g = cross_f(s, &t.fc[j]) + t.ic[j] * t.w[j] + t.bc[j] * u + cross_f(u, h);
        let p = t.ic[j] * u * 2.0 + t.bc[j] * s + cross_f(s, h);
        let mut i = model.frame(j).ant;
        while i > 0 {
            dq[(i - 1, j - 1)] = t.s[i].dot(&g);
            dqd[(i - 1, j - 1)] = t.s[i].dot(&p);
            i = model.frame(i).ant;
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
    mut a: Option<&mut DMatrix<f64>>,
) {
    rnea_with_environment(model, ws, env, q, qd, qdd, tau);
    if !model.index.serial {
        dtau_dq.as_mut_slice().fill(0.0);
        dtau_dqd.as_mut_slice().fill(0.0);
        if let Some(a) = a.as_deref_mut() {
            a.as_mut_slice().fill(0.0);
        }
    }
    forward(model, ws, t, env, qd, qdd);
    composites(model, ws, t);
    descendant_rows(model, t, dtau_dq, dtau_dqd, a);
    ancestor_rows(model, t, dtau_dq, dtau_dqd);
    for k in 1..=model.nl {
        dtau_dqd[(k - 1, k - 1)] += model.link(k).fv;
    }
}
