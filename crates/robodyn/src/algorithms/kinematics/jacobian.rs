//! Frame Jacobians J(q) (6 x nv, rows [linear; angular], columns the movable joints in frame
//! order, after a floating base's twist) in the three references, their time derivative J̇ and the classical drift J̇ q̇,
//! read from the placements (and velocities) of a [`KinematicsData`].

use super::forward::{
    base_column, frame_state, place_support, placement_of, set_configuration, world_column,
    FrameState, KinematicsData, Level,
};
use super::frames::FrameId;
use super::tree::{form_mul, form_mul_vector};
use super::{Motion, Reference};
use crate::error::{Error, Result};
use crate::geometry::Transform;
use crate::model::{JointType, Robot};
use nalgebra::{DMatrix, Vector3};

/// Call `f(k, j, z, revolute)` for each motion axis on the path from the base to the
/// description frame `frame`: each movable joint (its moving link j and the moving links
/// before it, z its axis z_j in R_0), then a floating base's 6 (j = 0: translations along,
/// rotations about its axes through O_0); k is the axis' entry in velocity vectors.
#[inline]
pub(crate) fn for_each_support_axis(
    data: &KinematicsData,
    frame: usize,
    mut f: impl FnMut(usize, usize, Vector3<f64>, bool),
) {
    let mut j = data.tree.anchor[frame].link;
    while j != 0 {
        let fc = data.tree.frame(j);
        let z = data.rot[j].column(2).into_owned();
        f(data.nb + j - 1, j, z, fc.joint == JointType::Revolute);
        j = fc.ant;
    }
    for c in 0..data.nb {
        f(c, 0, data.rot[0].column(c % 3).into_owned(), c >= 3);
    }
}

/// Error unless `out` is rows x nv.
pub(crate) fn check_matrix(
    robot: &Robot,
    what: &str,
    out: &DMatrix<f64>,
    rows: usize,
) -> Result<()> {
    let n = robot.nv();
    if out.nrows() != rows || out.ncols() != n {
        let cols = if robot.is_floating() {
            "nv = 6 + N: base twist, movable joints"
        } else {
            "movable joints"
        };
        return Err(Error::dimension(
            what,
            rows * n,
            out.len(),
            format!(
                "a {rows} x {n} matrix ({cols}), {} x {} given",
                out.nrows(),
                out.ncols()
            ),
        ));
    }
    Ok(())
}

/// Write the 6-row column k of `out` (column-major: one slice).
#[inline(always)]
fn put(out: &mut DMatrix<f64>, k: usize, m: &Motion) {
    let c = &mut out.as_mut_slice()[6 * k..6 * k + 6];
    c[..3].copy_from_slice(m.linear.as_slice());
    c[3..].copy_from_slice(m.angular.as_slice());
}

/// Column of the LocalWorldAligned Jacobian of the point `p` (R_0) for the axis z of joint
/// j: revolute [z x (p - O_j); z], prismatic [z; 0].
#[inline]
fn lwa_column(
    data: &KinematicsData,
    j: usize,
    z: Vector3<f64>,
    revolute: bool,
    p: &Vector3<f64>,
) -> Motion {
    if revolute {
        Motion::new(z.cross(&(p - data.pos[j])), z)
    } else {
        Motion::new(z, Vector3::zeros())
    }
}

/// A motion given in LocalWorldAligned (at the frame's origin O_f, R_0 axes) in `reference`.
#[inline]
fn from_lwa(t: &Transform, m: Motion, reference: Reference) -> Motion {
    match reference {
        Reference::LocalWorldAligned => m,
        Reference::Local => Motion::new(t.rot.tr_mul(&m.linear), t.rot.tr_mul(&m.angular)),
        // the velocity of the body point at O_0: v - w x O_f
        Reference::World => Motion::new(m.linear + t.pos.cross(&m.angular), m.angular),
    }
}

/// The Jacobian of frame `f` in `reference` into `out` (6 x nv, rows [linear; angular], one
/// column per movable joint, zero for joints not between the base and the frame, after the 6
/// of a floating base's twist), after
/// [`placements_into`](super::placements_into) or [`forward_kinematics_into`](super::forward_kinematics_into): J q̇ is
/// [`frame_velocity`](super::frame_velocity) in the same reference. Computing the placements
/// once and reading several frames' Jacobians is Pinocchio's `computeJointJacobians` then
/// `getFrameJacobian`. Allocation-free.
///
/// - `LocalWorldAligned`: column j = [z_j x (O_f - O_j); z_j] (revolute), [z_j; 0]
///   (prismatic), all in R_0: Khalil's basic Jacobian 0J_n (0V_n = linear velocity of O_n);
/// - `Local`: the same rows in the frame's own axes: Khalil's nJ_n;
/// - `World`: [O_j x z_j; z_j] (revolute), [z_j; 0] (prismatic), the spatial velocity in R_0.
///
/// A floating base's columns are those of joints on its axes: its linear velocity (in R_0)
/// translates along x_0, y_0, z_0, its angular velocity turns about them through O_0; R_0 is
/// then the world frame.
///
/// Errors: [`Error::Dimension`] for an `out` that is not 6 x nv or a `data` of another robot,
/// [`Error::Input`] for a `data` without placements or a frame of another robot.
pub fn frame_jacobian_into(
    robot: &Robot,
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    data.ready(robot, Level::Placements)?;
    f.check(robot)?;
    check_matrix(robot, "J", out, 6)?;
    write_jacobian(data, f, reference, out);
    Ok(())
}

/// Joint j's column of the World Jacobian: stored by `joint_jacobians_into`, else computed.
#[inline(always)]
fn column(data: &KinematicsData, j: usize) -> [f64; 6] {
    if data.columns {
        data.col[j]
    } else {
        world_column(data, j)
    }
}

/// The columns of the frame Jacobian from the World columns of its support, a floating base's
/// 6 included (a copy in `World`; moved to the frame's origin, and turned into its axes for
/// `Local`).
fn write_jacobian(
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
    out: &mut DMatrix<f64>,
) {
    // a slice's fill is a memset; DMatrix::fill walks the matrix by strides (~2 ns an entry)
    let o = out.as_mut_slice();
    o.fill(0.0);
    let nb = data.nb;
    let mut j = data.tree.anchor[f.parent()].link;
    if reference == Reference::World {
        while j != 0 {
            o[6 * (nb + j - 1)..6 * (nb + j)].copy_from_slice(&column(data, j));
            j = data.tree.parent[j];
        }
        for c in 0..nb {
            o[6 * c..6 * c + 6].copy_from_slice(&base_column(data, c));
        }
        return;
    }
    let t = placement_of(data, f);
    while j != 0 {
        let k = nb + j - 1;
        moved_column(&t, &column(data, j), reference, &mut o[6 * k..6 * k + 6]);
        j = data.tree.parent[j];
    }
    for c in 0..nb {
        moved_column(
            &t,
            &base_column(data, c),
            reference,
            &mut o[6 * c..6 * c + 6],
        );
    }
}

/// The World column `c` moved to the origin of the frame placed at `t` (LocalWorldAligned),
/// turned into its axes for `Local`, into `col`.
#[inline(always)]
fn moved_column(t: &Transform, c: &[f64; 6], reference: Reference, col: &mut [f64]) {
    let w = Vector3::new(c[3], c[4], c[5]);
    // the velocity of the body point at O_f from that at O_0: v + w x O_f
    let v = Vector3::new(c[0], c[1], c[2]) + w.cross(&t.pos);
    let (v, w) = match reference {
        Reference::Local => (t.rot.tr_mul(&v), t.rot.tr_mul(&w)),
        _ => (v, w),
    };
    col[..3].copy_from_slice(v.as_slice());
    col[3..].copy_from_slice(w.as_slice());
}

/// The Jacobian of frame `f` in `reference` at the configuration `q` (nq) into `out` (6 x nv),
/// from the placements of the frame's support only (the movable joints between the base and
/// the frame): Pinocchio's `computeFrameJacobian`. Cheaper than [`placements_into`](super::placements_into) then
/// [`frame_jacobian_into`] for one frame of a large tree; `data` is left without a full pass
/// (the frame functions ask for one again). Allocation-free.
///
/// Errors: as [`placements_into`](super::placements_into) and [`frame_jacobian_into`].
pub fn frame_jacobian_from_q_into(
    robot: &Robot,
    data: &mut KinematicsData,
    q: &[f64],
    f: &FrameId,
    reference: Reference,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    let q = set_configuration(robot, data, q)?;
    f.check(robot)?;
    check_matrix(robot, "J", out, 6)?;
    if reference == Reference::Local {
        local_jacobian_from_q(data, q, f, out);
    } else {
        place_support(data, q, f);
        write_jacobian(data, f, reference, out);
    }
    Ok(())
}

/// The `Local` Jacobian of frame `f` at `q` by one pass from the frame towards the base
/// (Pinocchio's `computeFrameJacobian` in `LOCAL`), no placement in R_0 formed: with
/// kT_f = (R, P) the frame's placement in moving link k, joint k's column is
/// [R^T (z x P); R^T z] (revolute) or [R^T z; 0] (prismatic), z = (0, 0, 1) (R^T z is R's last
/// row), then a(k)T_f = a(k)T_k kT_f. A floating base's columns come last, from 0T_f, as
/// those of joints on its axes (they do not depend on the base pose).
fn local_jacobian_from_q(data: &KinematicsData, q: &[f64], f: &FrameId, out: &mut DMatrix<f64>) {
    let nb = data.nb;
    let o = out.as_mut_slice();
    o.fill(0.0);
    let an = &data.tree.anchor[f.parent()];
    let mut t = if an.identity {
        *f.offset()
    } else {
        an.t.compose(f.offset())
    };
    let mut k = an.link;
    while k != 0 {
        let fc = data.tree.frame(k);
        let (r, p) = (&t.rot, &t.pos);
        let z = r.row(2);
        let col = &mut o[6 * (nb + k - 1)..6 * (nb + k)];
        if fc.joint == JointType::Revolute {
            let lin = r.row(1) * p.x - r.row(0) * p.y;
            col[..3].copy_from_slice(&[lin[0], lin[1], lin[2]]);
            col[3..].copy_from_slice(&[z[0], z[1], z[2]]);
        } else {
            col[..3].copy_from_slice(&[z[0], z[1], z[2]]);
        }
        let (a, pa) = fc.placement(&q[k - 1]);
        let form = fc.form();
        t = Transform {
            pos: form_mul_vector(&a, p, form) + pa,
            rot: form_mul(&a, r, form),
        };
        k = fc.ant;
    }
    for c in 0..nb {
        let axis = Vector3::ith(c % 3, 1.0);
        let world = super::forward::axis_column(&axis, &Vector3::zeros(), c >= 3);
        moved_column(&t, &world, Reference::Local, &mut o[6 * c..6 * c + 6]);
    }
}

/// The Jacobian of frame `f` in `reference` at the configuration `q` (movable joints in frame
/// order, after a floating base's pose): 6 x nv, rows [linear; angular]. Allocates; use
/// [`frame_jacobian_into`] in loops.
///
/// Errors: as [`placements_into`](super::placements_into) and [`frame_jacobian_into`].
///
/// # Example
///
/// ```
/// use robodyn::{frame_jacobian, Reference};
/// # fn main() -> robodyn::Result<()> {
/// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
/// let rx90 = robodyn::io::load(urdf)?;
/// let wrist = rx90.frame_id("6")?;
/// let j = frame_jacobian(&rx90, &[0.1; 6], &wrist, Reference::LocalWorldAligned)?;
/// assert_eq!(j.shape(), (6, 6));
/// assert!((j[(5, 0)] - 1.0).abs() < 1e-15); // joint 1 turns about z_0
/// # Ok(())
/// # }
/// ```
pub fn frame_jacobian(
    robot: &Robot,
    q: &[f64],
    f: &FrameId,
    reference: Reference,
) -> Result<DMatrix<f64>> {
    let mut data = KinematicsData::new(robot);
    let mut out = DMatrix::zeros(6, robot.nv());
    frame_jacobian_from_q_into(robot, &mut data, q, f, reference, &mut out)?;
    Ok(out)
}

/// J̇ = dJ/dt of frame `f` in `reference` into `out` (6 x nv) at the state of the last
/// [`forward_kinematics_into`](super::forward_kinematics_into) (Pinocchio's
/// `getFrameJacobianTimeVariation`): J̇ q̇ + J q̈ is
/// [`frame_acceleration`](super::frame_acceleration) in the same reference. With ż_j = w_j x z_j:
///
/// - `LocalWorldAligned`: [ż_j x (O_f - O_j) + z_j x (v_f - v_j); ż_j] (revolute), [ż_j; 0];
/// - `Local`: nA_0 (J̇_lwa - [w x] J_lwa) row block by row block;
/// - `World`: [v_j x z_j + O_j x ż_j; ż_j] (revolute), [ż_j; 0] (prismatic).
///
/// A floating base's 6 columns follow the same rules for its axes (j = 0, w_0 and v_0 the
/// base's angular velocity and the velocity of O_0).
///
/// Errors: as [`frame_jacobian_into`], and [`Error::Input`] for a `data` without velocities.
pub fn frame_jacobian_time_variation_into(
    robot: &Robot,
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    data.ready(robot, Level::Motion)?;
    f.check(robot)?;
    check_matrix(robot, "dJ", out, 6)?;
    out.as_mut_slice().fill(0.0);
    let s = frame_state(data, f);
    for_each_support_axis(data, f.parent(), |k, j, z, revolute| {
        let zd = data.w[j].cross(&z);
        let col = match (reference, revolute) {
            (_, false) => {
                let lwa = Motion::new(zd, Vector3::zeros());
                let jl = Motion::new(z, Vector3::zeros());
                local_derivative(&s, lwa, jl, reference)
            }
            (Reference::World, true) => {
                Motion::new(data.v[j].cross(&z) + data.pos[j].cross(&zd), zd)
            }
            (_, true) => {
                let r = s.t.pos - data.pos[j];
                let lwa = Motion::new(zd.cross(&r) + z.cross(&(s.v - data.v[j])), zd);
                local_derivative(&s, lwa, Motion::new(z.cross(&r), z), reference)
            }
        };
        put(out, k, &col);
    });
    Ok(())
}

/// The column of J̇ in `reference` from the LocalWorldAligned column `lwa` of J̇ and `jl` of J:
/// d/dt (nA_0 x) = nA_0 (ẋ - w x x) for `Local`; `World` prismatic columns are those of
/// LocalWorldAligned.
#[inline]
fn local_derivative(s: &FrameState, lwa: Motion, jl: Motion, reference: Reference) -> Motion {
    match reference {
        Reference::Local => {
            let lin = lwa.linear - s.w.cross(&jl.linear);
            let ang = lwa.angular - s.w.cross(&jl.angular);
            Motion::new(s.t.rot.tr_mul(&lin), s.t.rot.tr_mul(&ang))
        }
        _ => lwa,
    }
}

/// The classical drift of frame `f` in `reference`: its classical acceleration
/// ([`frame_classical_acceleration`](super::frame_classical_acceleration)) at the data's q, q̇
/// with q̈ = 0, the term a controller adds to J q̈ (in `LocalWorldAligned`, J̇ q̇ of that
/// reference). Read after [`forward_kinematics_into`](super::forward_kinematics_into) with any
/// q̈ (its J q̈ is taken off). Allocation-free.
///
/// Errors: as [`frame_jacobian_time_variation_into`].
pub fn frame_classical_drift(
    robot: &Robot,
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
) -> Result<Motion> {
    let acc = super::frame_classical_acceleration(robot, data, f, reference)?;
    let s = frame_state(data, f);
    let mut jqdd = Motion::new(Vector3::zeros(), Vector3::zeros());
    for_each_support_axis(data, f.parent(), |k, j, z, revolute| {
        let col = from_lwa(&s.t, lwa_column(data, j, z, revolute, &s.t.pos), reference);
        let qdd = data.qdd[k];
        jqdd.linear += qdd * col.linear;
        jqdd.angular += qdd * col.angular;
    });
    Ok(Motion::new(
        acc.linear - jqdd.linear,
        acc.angular - jqdd.angular,
    ))
}
