//! Inverse dynamic model of tree structures by the recursive Newton–Euler algorithm
//! (eqs 10.3–10.12), with gravity as a base acceleration, rotor inertia, Coulomb and viscous
//! friction and external wrenches.
//!
//! - [`inverse_dynamics`] / [`inverse_dynamics_into`]: the checked API on joint vectors over the
//!   movable joints ([`Robot::coordinates`]);
//! - [`rnea`], [`forward_recursion`], [`backward_recursion`] (and their `_sharing` forms): the
//!   generic kernel over any [`DynScalar`] on tree arrays (NL entries, joint j at index j-1),
//!   unchecked, for the customized symbolic models and automatic differentiation.

use crate::data::{with_data, Data};
use crate::error::Result;
use crate::model::{DynModel, Environment, FoldedLink, JointType, Robot};
use crate::scalar::DynScalar;
use nalgebra::{DVector, Matrix3, Vector3};

/// `z x (s v)` is needed as `w x (qd * z)`: returns `w x [0, 0, s]`.
#[inline]
fn cross_z<T: DynScalar>(w: &Vector3<T>, s: &T) -> Vector3<T> {
    Vector3::new(
        w.y.clone() * s.clone(),
        -(w.x.clone() * s.clone()),
        T::zero(),
    )
}

/// Naming hook of the customized symbolic model: component c of vector `v` of link j becomes
/// `<prefix><c><j>` (SYMORO's `WI12`, `VP32`...). A no-op for `f64` (`T::NAMED` is false).
#[inline(always)]
pub(crate) fn name3<T: DynScalar>(v: Vector3<T>, prefix: &str, j: usize) -> Vector3<T> {
    if !T::NAMED {
        return v;
    }
    let [[x, y, z]] = v.data.0;
    Vector3::new(
        x.named(|| format!("{prefix}1{j}")),
        y.named(|| format!("{prefix}2{j}")),
        z.named(|| format!("{prefix}3{j}")),
    )
}

/// Products of the components of w: (w_y w_z, w_x w_z, w_x w_y) and (w_x^2, w_y^2, w_z^2).
/// Shared by jU_j and the Euler moment; the customized model names them `T<k>` when shared.
#[inline]
pub(crate) fn w_products<T: DynScalar>(w: &Vector3<T>) -> (Vector3<T>, Vector3<T>) {
    let (x, y, z) = (w.x.clone(), w.y.clone(), w.z.clone());
    (
        Vector3::new(
            y.clone() * z.clone(),
            x.clone() * z.clone(),
            x.clone() * y.clone(),
        ),
        Vector3::new(x.clone() * x, y.clone() * y, z.clone() * z),
    )
}

/// jU_j = skew(wd) + skew(w) skew(w) (below eq 10.8), computed once per link and used both for
/// the acceleration of its successors' origins (10.6) and for its own force (10.7); entries are
/// named `U<r><c><j>` in the customized model. `p` and `sq` come from [`w_products`].
#[inline]
fn u_matrix<T: DynScalar>(
    p: &Vector3<T>,
    sq: &Vector3<T>,
    wd: &Vector3<T>,
    j: usize,
) -> Matrix3<T> {
    let (yz, xz, xy) = (p.x.clone(), p.y.clone(), p.z.clone());
    let (xx, yy, zz) = (sq.x.clone(), sq.y.clone(), sq.z.clone());
    let u = Matrix3::new(
        -(yy.clone() + zz.clone()),
        xy.clone() - wd.z.clone(),
        xz.clone() + wd.y.clone(),
        xy + wd.z.clone(),
        -(xx.clone() + zz),
        yz.clone() - wd.x.clone(),
        xz - wd.y.clone(),
        yz + wd.x.clone(),
        -(xx + yy),
    );
    if !T::NAMED {
        return u;
    }
    Matrix3::from_fn(|r, c| {
        u[(r, c)]
            .clone()
            .named(|| format!("U{}{}{j}", r + 1, c + 1))
    })
}

/// Euler moment J wd + w x (J w) of eq 10.8 in product form, with the products of w shared with
/// jU_j (derived from first principles; the spec writes the vector form):
///
/// n_x = XX wd_x + XY (wd_y - w_x w_z) + XZ (wd_z + w_x w_y) + YZ (w_y^2 - w_z^2)
///       + (ZZ - YY) w_y w_z,
///
/// and cyclically for y and z. Here wd_y - w_x w_z = -U31, wd_z + w_x w_y = U21 and
/// w_y^2 - w_z^2 is a difference of the squares `sq`. Fifteen multiplications instead of the 24
/// of J wd + w x (J w); with base parameters (YY = 0) the differences of moments mostly vanish.
#[inline]
pub(crate) fn euler_moment<T: DynScalar>(
    inertia: &Matrix3<T>,
    diff: &Vector3<T>,
    wd: &Vector3<T>,
    p: &Vector3<T>,
    sq: &Vector3<T>,
    u: &Matrix3<T>,
) -> Vector3<T> {
    let jj = |r: usize, c: usize| inertia[(r, c)].clone();
    let uu = |r: usize, c: usize| u[(r, c)].clone();
    let (xy, xz, yz) = (jj(0, 1), jj(0, 2), jj(1, 2));
    Vector3::new(
        jj(0, 0) * wd.x.clone() - xy.clone() * uu(2, 0)
            + xz.clone() * uu(1, 0)
            + yz.clone() * (sq.y.clone() - sq.z.clone())
            + diff.x.clone() * p.x.clone(),
        jj(1, 1) * wd.y.clone() - yz.clone() * uu(0, 1)
            + xy.clone() * uu(2, 1)
            + xz.clone() * (sq.z.clone() - sq.x.clone())
            + diff.y.clone() * p.y.clone(),
        jj(2, 2) * wd.z.clone() - xz * uu(1, 2)
            + yz * uu(0, 2)
            + xy * (sq.x.clone() - sq.y.clone())
            + diff.z.clone() * p.z.clone(),
    )
}

/// Forward recursion (eqs 10.3–10.8) with the model's environment: fills the placements, link
/// velocities and accelerations of `ws` and the link wrenches jF_j + jfe_j, jM_j + jme_j for
/// links 1..NL. Tree arrays of NL entries.
pub fn forward_recursion<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
) {
    forward_pass(model, &model.env, ws, q, qd, qdd, &[]);
}

/// Orientation of link k taken from an earlier link m on a closed chain: 0R_k = 0R_m C with C
/// constant on the closure manifold (the parallel links of a parallelogram, §10.3.5).
#[derive(Clone, Debug, PartialEq)]
pub struct SharedOrientation<T: DynScalar> {
    /// The link m (computed before k by the recursion, see `sharing_order`).
    pub link: usize,
    /// C = mR_k, constant.
    pub rot: Matrix3<T>,
}

/// Order of the forward recursion: every link after its antecedent and after the link whose
/// orientation it shares (which may carry a higher number), otherwise by increasing number;
/// None for 1..NL (no shared link).
fn sharing_order<T: DynScalar>(
    model: &DynModel<T>,
    shared: &[Option<SharedOrientation<T>>],
) -> Option<Vec<usize>> {
    let nl = model.nl;
    if shared.iter().all(Option::is_none) {
        return None;
    }
    let mut done = vec![false; nl + 1];
    done[0] = true;
    let mut order = Vec::with_capacity(nl);
    while order.len() < nl {
        let j = (1..=nl)
            .find(|&j| {
                !done[j]
                    && done[model.frame(j).ant]
                    && shared
                        .get(j - 1)
                        .and_then(Option::as_ref)
                        .is_none_or(|s| done[s.link])
            })
            .expect("shared orientations form no cycle");
        done[j] = true;
        order.push(j);
    }
    Some(order)
}

/// [`forward_recursion`] for a closed chain whose tree state satisfies the loop constraints:
/// for link k with `shared[k - 1] = Some(m, C)`, w_k = C^T w_m, wd_k = C^T wd_m and
/// jU_k = C^T jU_m C replace eqs 10.3–10.5 (a signed permutation C costs nothing in the
/// customized model). Entries beyond `shared.len()` are computed as usual. Links run in
/// dependency order (a source may carry a higher number than the link that follows it).
///
/// # Panics
/// If the sharing is cyclic (a link would need itself before it), which
/// [`crate::codegen::parallel_links`] never produces: its source of a class is the member closest
/// to the base, never a descendant of another member.
pub fn forward_recursion_sharing<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    shared: &[Option<SharedOrientation<T>>],
) {
    forward_pass(model, &model.env, ws, q, qd, qdd, shared);
}

/// The forward recursion with an explicit environment (gravity, base motion, wrenches).
#[allow(clippy::too_many_arguments)]
pub(crate) fn forward_pass<T: DynScalar>(
    model: &DynModel<T>,
    env: &Environment<T>,
    ws: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    shared: &[Option<SharedOrientation<T>>],
) {
    let vd0 = &env.base.vp0 - &env.gravity;
    set_base_motion(ws, env.base.w0.clone(), env.base.wp0.clone(), vd0);
    forward_links(model, env, ws, q, qd, qdd, shared);
}

/// The motion of the root of the recursion, in R_0: angular velocity `w0`, angular acceleration
/// `wd0` and acceleration of O_0 minus gravity `vd0` (gravity as a base acceleration), with
/// 0U_0.
pub(crate) fn set_base_motion<T: DynScalar>(
    ws: &mut Data<T>,
    w0: Vector3<T>,
    wd0: Vector3<T>,
    vd0: Vector3<T>,
) {
    let (p0, sq0) = w_products(&w0);
    ws.u[0] = u_matrix(&p0, &sq0, &wd0, 0);
    ws.w[0] = w0;
    ws.wd[0] = wd0;
    ws.vd[0] = vd0;
}

/// The forward recursion over links 1..NL from the base motion already in `ws`
/// ([`set_base_motion`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn forward_links<T: DynScalar>(
    model: &DynModel<T>,
    env: &Environment<T>,
    ws: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    shared: &[Option<SharedOrientation<T>>],
) {
    // no allocation without shared links (the numeric rnea)
    let order = sharing_order(model, shared);
    for idx in 0..model.nl {
        let j = order.as_ref().map_or(idx + 1, |o| o[idx]);
        // names of the customized model carry the description's link number
        let n = if T::NAMED { model.wrench_link(j) } else { j };
        let fr = model.frame(j);
        let i = fr.ant;
        let (rot, pos) = fr.placement(&q[j - 1]);
        // products by jA_i = (iA_j)^T, zeros of the frame's rotation form skipped
        let jai = |v: &Vector3<T>| fr.rot_tr_mul(&rot, v);
        // iU_i iP_j (10.6)
        let up = &ws.u[i] * &pos;
        let wi = name3(jai(&ws.w[i]), "WI", n); // (10.3)
        let vsp = name3(&ws.vd[i] + up, "VSP", n);
        let mut vd = jai(&vsp); // (10.6), first part
        let share = shared.get(j - 1).and_then(Option::as_ref);
        let (w, wd) = match share {
            Some(s) => (s.rot.tr_mul(&ws.w[s.link]), s.rot.tr_mul(&ws.wd[s.link])),
            None => {
                let mut wd = jai(&ws.wd[i]);
                let mut w = wi.clone();
                if fr.joint == JointType::Revolute {
                    // (10.4), (10.5)
                    w.z += qd[j - 1].clone();
                    wd += cross_z(&wi, &qd[j - 1]);
                    wd.z += qdd[j - 1].clone();
                }
                (name3(w, "W", n), name3(wd, "WP", n))
            }
        };
        if fr.joint == JointType::Prismatic {
            // (10.6), second part: qdd a + 2 w_i x qd a
            vd += cross_z(&wi, &(qd[j - 1].clone() + qd[j - 1].clone()));
            vd.z += qdd[j - 1].clone();
        }
        let vd = name3(vd, "VP", n);
        let l = model.link(j);
        // (10.7): F = M vd + U MS
        let (p, sq) = w_products(&w);
        let u = match share {
            Some(s) => s.rot.tr_mul(&ws.u[s.link]) * &s.rot,
            None => u_matrix(&p, &sq, &wd, n),
        };
        let f = &vd * l.mass.clone() + &u * &l.ms;
        // (10.8): M = J wd + w x (J w) + MS x vd
        let m = euler_moment(&l.inertia, &l.inertia_diff, &wd, &p, &sq, &u) + l.ms.cross(&vd);
        ws.u[j] = u;
        let (f, m) = if env.has_wrenches() {
            let e = env.wrench(model.wrench_link(j));
            (f + &e.force, m + &e.moment)
        } else {
            (f, m)
        };
        ws.f[j] = name3(f, "F", n);
        ws.m[j] = name3(m, "No", n);
        ws.rot[j] = rot;
        ws.pos[j] = pos;
        ws.w[j] = w;
        ws.wd[j] = wd;
        ws.vd[j] = vd;
    }
    add_folded_wrenches(model, env, &mut ws.f, &mut ws.m);
}

/// Carry the external wrenches of the links folded into movable links ([`DynModel::folded`])
/// onto their host, into the force and moment buffers `f`, `m` (indexed by link).
pub(crate) fn add_folded_wrenches<T: DynScalar>(
    model: &DynModel<T>,
    env: &Environment<T>,
    f: &mut [Vector3<T>],
    m: &mut [Vector3<T>],
) {
    for fl in &model.folded {
        if let Some((fh, mh)) = folded_wrench(fl, env) {
            f[fl.host] += fh;
            m[fl.host] += mh;
        }
    }
}

/// The external wrench of a folded link moved onto its host (about O_h, in R_h):
/// hA_k f_k and hA_k m_k + hP_k x (hA_k f_k) (eqs 10.10–10.11 for a rigid attachment); None for
/// a zero wrench.
#[inline]
pub(crate) fn folded_wrench<T: DynScalar>(
    fl: &FoldedLink<T>,
    env: &Environment<T>,
) -> Option<(Vector3<T>, Vector3<T>)> {
    let e = env.wrench(fl.link);
    if !env.has_wrenches() || e.is_zero() {
        return None;
    }
    let fh = &fl.rot * &e.force;
    let mh = &fl.rot * &e.moment + fl.pos.cross(&fh);
    Some((fh, mh))
}

/// Backward recursion (eqs 10.9–10.12) after [`forward_recursion`]: accumulates the wrenches
/// towards the base and writes the joint torques of the tree joints 1..NL into `tau`
/// (0 for fixed frames).
pub fn backward_recursion<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    qd: &[T],
    qdd: &[T],
    tau: &mut [T],
) {
    backward_recursion_sharing(model, ws, qd, qdd, tau, &[]);
}

/// [`backward_recursion`] after [`forward_recursion_sharing`], for the closed-chain torques
/// G^T Gamma_tr only: the pure moment jm_j accumulated on a link k that shares the orientation
/// of link m (w_k = C^T w_m on the closure manifold) is moved, as C jm_k, onto link m instead of
/// being transmitted through joint k to a(k); the force and its moment P x f still go to a(k).
/// A pure moment on a body does the virtual power m . w, and m . w_k = (C m) . w_m for every
/// motion that keeps the loops closed, so G^T Gamma_tr is unchanged while the individual tree
/// torques of the joints between the two links are not those of the tree.
pub fn backward_recursion_sharing<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    qd: &[T],
    qdd: &[T],
    tau: &mut [T],
    shared: &[Option<SharedOrientation<T>>],
) {
    let order = sharing_order(model, shared);
    for idx in (0..model.nl).rev() {
        let j = order.as_ref().map_or(idx + 1, |o| o[idx]);
        let n = if T::NAMED { model.wrench_link(j) } else { j };
        let fr = model.frame(j);
        let l = model.link(j);
        if T::NAMED {
            // total wrench on link j, complete once its children are processed
            ws.f[j] = name3(ws.f[j].clone(), "E", n);
            ws.m[j] = name3(ws.m[j].clone(), "N", n);
        }
        if let Some(s) = shared.get(j - 1).and_then(Option::as_ref) {
            let moved = &s.rot * &ws.m[j];
            ws.m[s.link] += moved;
            ws.m[j] = Vector3::zeros();
        }
        tau[j - 1] = match fr.joint {
            JointType::Revolute | JointType::Prismatic => {
                let proj = if fr.joint == JointType::Revolute {
                    ws.m[j].z.clone()
                } else {
                    ws.f[j].z.clone()
                };
                // (10.12)
                proj + l.fs.clone() * qd[j - 1].sign()
                    + l.fv.clone() * qd[j - 1].clone()
                    + l.ia.clone() * qdd[j - 1].clone()
            }
            JointType::Fixed => T::zero(),
        };
        let i = fr.ant;
        if i > 0 {
            // (10.10), (10.11)
            let fi = name3(fr.rot_mul(&ws.rot[j], &ws.f[j]), "FDI", n);
            let mi = name3(
                fr.rot_mul(&ws.rot[j], &ws.m[j]) + ws.pos[j].cross(&fi),
                "NDI",
                n,
            );
            ws.f[i] += fi;
            ws.m[i] += mi;
        }
    }
}

/// Torques of the tree joints 1..NL (tree arrays of NL entries) by recursive Newton–Euler with
/// the model's environment: the generic kernel. Allocation-free; entries of fixed frames are
/// ignored in the inputs and zero in the output.
///
/// # Panics
/// If a slice has fewer than NL entries or `ws` was made for a smaller model.
pub fn rnea<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    tau: &mut [T],
) {
    rnea_with_environment(model, ws, &model.env, q, qd, qdd, tau);
}

/// [`rnea`] with an explicit environment (gravity, base motion, external wrenches).
pub fn rnea_with_environment<T: DynScalar>(
    model: &DynModel<T>,
    ws: &mut Data<T>,
    env: &Environment<T>,
    q: &[T],
    qd: &[T],
    qdd: &[T],
    tau: &mut [T],
) {
    forward_pass(model, env, ws, q, qd, qdd, &[]);
    backward_recursion(model, ws, qd, qdd, tau);
}

/// Check a tree state (q, qd, and qdd or tau) against the robot's coordinates and the data
/// against the robot: the entry check of the checked tree functions.
pub(crate) fn check_state(
    robot: &Robot,
    data: &Data,
    names: [&str; 3],
    x: [&[f64]; 3],
) -> Result<()> {
    data.check(robot)?;
    let c = robot.coordinates();
    for (name, v) in names.iter().zip(x) {
        c.check(name, v, "movable joints")?;
    }
    Ok(())
}

/// Run `f` on tree arrays holding the joint vectors (x1, x2, x3) over the movable joints: the
/// vectors themselves when every tree joint is movable, else copies scattered into the data's
/// tree arrays (zeros at fixed frames). Allocation-free.
pub(crate) fn on_tree_arrays<R>(
    robot: &Robot,
    data: &mut Data,
    x: [&[f64]; 3],
    f: impl FnOnce(&mut Data, &[f64], &[f64], &[f64]) -> R,
) -> R {
    let c = robot.coordinates();
    if c.is_identity() {
        return f(data, x[0], x[1], x[2]);
    }
    let mut a = std::mem::take(&mut data.q);
    let mut b = std::mem::take(&mut data.qd);
    let mut d = std::mem::take(&mut data.qdd);
    c.scatter(x[0], &mut a);
    c.scatter(x[1], &mut b);
    c.scatter(x[2], &mut d);
    let r = f(data, &a, &b, &d);
    data.q = a;
    data.qd = b;
    data.qdd = d;
    r
}

/// The frame of the checked tree functions that map joint vectors to a joint vector: check the
/// inputs `x` (named `names`), the data, the environment and the output's length; run `kernel`
/// on the model of the dynamic recursions ([`Robot::dynamic`], fixed frames folded out), whose
/// tree arrays are the joint vectors themselves; check that the output is finite (finite
/// inputs can overflow: [`crate::error::check_finite_result`]). Allocation-free.
#[allow(clippy::too_many_arguments)]
pub(crate) fn tree_vector_map(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    names: [&str; 3],
    x: [&[f64]; 3],
    out_name: &str,
    out: &mut [f64],
    kernel: impl FnOnce(&DynModel<f64>, &mut Data, &[f64], &[f64], &[f64], &mut [f64]) -> Result<()>,
) -> Result<()> {
    check_state(robot, data, names, x)?;
    env.check(robot.nl())?;
    robot
        .coordinates()
        .check_output(out_name, out, "movable joints")?;
    kernel(robot.dynamic(), data, x[0], x[1], x[2], out)?;
    crate::error::check_finite_result(out_name, out)
}

/// Inverse dynamic model (eqs 10.3–10.12) into `tau`: the joint torques (N m) / forces (N) of the
/// movable joints for positions `q` (rad, m), velocities `qd` and accelerations `qdd`, all with
/// `robot.coordinates().len()` entries in frame order, under the per-call inputs `env`
/// (gravity, base motion, external wrenches). Allocation-free. With a motor–joint transmission
/// the motors' reflected inertia and friction are added and the torques are joint-side
/// ([`crate::model::MotorDrives`]).
///
/// Errors: [`crate::Error::Dimension`] for a vector of the wrong length or a `data` of another
/// robot, [`crate::Error::NotFinite`] for a NaN or infinite entry.
///
/// # Example
///
/// A control loop: one [`Data`] and one output buffer made before the loop, a contact force that
/// changes at every step set in the [`Environment`] (no new robot, no allocation).
///
/// ```
/// use robodyn::{inverse_dynamics, inverse_dynamics_into, Data};
/// # fn main() -> robodyn::Result<()> {
/// let robot = robodyn::io::toml_format::parse_robot(
///     r#"
///     name = "planar 2R"
///     gravity = [0, -9.81, 0]
///     [[frame]]
///     j = 1
///     ant = 0
///     [[frame]]
///     j = 2
///     ant = 1
///     d = 0.5
///     [[link]]
///     j = 1
///     ZZ = 0.1
///     MX = 0.25
///     M = 1.0
///     [[link]]
///     j = 2
///     ZZ = 0.05
///     MX = 0.2
///     M = 0.8
///     "#,
///     None,
/// )?;
/// let mut data = Data::new(&robot);
/// let mut env = robot.environment().clone(); // gravity [0, -9.81, 0] of the file
/// let mut tau = vec![0.0; robot.dof()];
/// for k in 0..1000 {
///     let t = k as f64 * 1e-3;
///     let (q, qd, qdd) = ([t.sin(), 0.3], [t.cos(), 0.0], [-t.sin(), 0.0]);
///     // 2 N along x_2 pushing ON link 2 at O_2 (Pinocchio's `fext` convention)
///     env.set_wrench_on_link(2, [2.0, 0.0, 0.0].into(), [0.0; 3].into())?;
///     inverse_dynamics_into(&robot, &mut data, &env, &q, &qd, &qdd, &mut tau)?;
/// }
/// // the allocating form uses the file's environment (no contact force)
/// let at_rest = inverse_dynamics(&robot, &[0.0, 0.0], &[0.0; 2], &[0.0; 2])?;
/// // holding both links horizontal: joint 1 carries g (MX1 + M2 d2 + MX2) = 9.81 * 0.85
/// assert!((at_rest[0] - 9.81 * 0.85).abs() < 1e-12);
/// // a vector of the wrong length is an error, not a panic
/// assert!(inverse_dynamics(&robot, &[0.0], &[0.0; 2], &[0.0; 2]).is_err());
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn inverse_dynamics_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    tau: &mut [f64],
) -> Result<()> {
    if robot.is_floating() {
        return crate::algorithms::floating_base::inverse_dynamics_into(
            robot, data, env, q, qd, qdd, tau,
        );
    }
    let names = ["q", "qd", "qdd"];
    tree_vector_map(
        robot,
        data,
        env,
        names,
        [q, qd, qdd],
        "tau",
        tau,
        |m, d, q, qd, qdd, t| {
            rnea_with_environment(m, d, env, q, qd, qdd, t);
            if let Some(drives) = robot.motor_drives() {
                drives.add_torques(qd, Some(qdd), t);
            }
            Ok(())
        },
    )
}

/// A state of a tree robot over its movable joints (frame order): positions `q` (rad, m),
/// velocities `qd` and accelerations `qdd`. Named fields, so that a swap of the three vectors
/// reads as one (`State { q: &qd, .. }`) where three positional `&[f64]` would compile silently.
#[derive(Clone, Copy, Debug)]
pub struct State<'a> {
    /// Joint positions (rad, m).
    pub q: &'a [f64],
    /// Joint velocities (rad/s, m/s).
    pub qd: &'a [f64],
    /// Joint accelerations (rad/s², m/s²).
    pub qdd: &'a [f64],
}

/// [`inverse_dynamics_into`] with the state as named fields: Gamma (N m, N) of the movable
/// joints into `tau`. Allocation-free; the same checks and errors.
///
/// # Example
///
/// ```
/// use robodyn::{inverse_dynamics_state_into, Data, State};
/// # fn main() -> robodyn::Result<()> {
/// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
/// let robot = robodyn::io::load(urdf)?;
/// let mut data = Data::new(&robot);
/// let (q, qd, qdd) = ([0.1; 6], [0.2; 6], [0.3; 6]);
/// let mut tau = [0.0; 6];
/// let state = State { q: &q, qd: &qd, qdd: &qdd };
/// inverse_dynamics_state_into(&robot, &mut data, robot.environment(), state, &mut tau)?;
/// let w = data.angular_velocities()[6]; // jw_j of the last link (R_6), after Newton–Euler
/// assert!(w.norm() > 0.0);
/// # Ok(())
/// # }
/// ```
pub fn inverse_dynamics_state_into(
    robot: &Robot,
    data: &mut Data,
    env: &Environment,
    state: State<'_>,
    tau: &mut [f64],
) -> Result<()> {
    inverse_dynamics_into(robot, data, env, state.q, state.qd, state.qdd, tau)
}

/// Inverse dynamic model with the robot's own environment: Gamma (N m, N) of the movable joints
/// (frame order) for q, qd, qdd over the movable joints. Allocates; use
/// [`inverse_dynamics_into`] in loops (this form allocates only its result: its buffers are
/// the thread's kept [`Data`]).
pub fn inverse_dynamics(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> Result<DVector<f64>> {
    let mut tau = DVector::zeros(robot.nv());
    with_data(robot, |data| {
        inverse_dynamics_into(
            robot,
            data,
            robot.environment(),
            q,
            qd,
            qdd,
            tau.as_mut_slice(),
        )
    })?;
    Ok(tau)
}
