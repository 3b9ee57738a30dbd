//! The forward kinematic pass: placements 0T_j, velocities and accelerations of every frame of
//! the description, in R_0, into a [`KinematicsData`]; and the frame quantities read from it.

use super::frames::FrameId;
use super::tree::{mul_form, MovingTree};
use super::{Motion, Reference};
use crate::algorithms::floating_base::{check_floating_vectors, v3};
use crate::error::{Error, Result};
use crate::geometry::Transform;
use crate::model::{JointType, Robot};
use nalgebra::{Matrix3, Vector3};

/// How far the last pass of a [`KinematicsData`] went.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Level {
    /// Nothing computed yet.
    None,
    /// Placements only ([`placements_into`]).
    Placements,
    /// Placements, velocities and accelerations ([`forward_kinematics_into`]).
    Motion,
}

/// Buffers and results of the kinematic functions for one robot (Pinocchio's `Data` for
/// `forwardKinematics`, `computeJointJacobians`, `centerOfMass`). The passes run over the
/// movable joints only, as Pinocchio's model: per movable joint k (0 the base), all in R_0 (the
/// world frame for a floating base, whose pose and twist are link 0's) at the origin of its
/// frame, the placement, the angular velocity and acceleration, the linear
/// velocity and (classical) acceleration; every other frame of the description is fixed on its
/// nearest movable ancestor and read from it. Made once per thread with
/// [`KinematicsData::new`]; [`forward_kinematics_into`] or [`placements_into`] fill it, and the
/// frame functions (placements, velocities, Jacobians, centre of mass) read it without
/// allocating. Cut-joint frames (NL+1..NJ) are placed at cut variable 0 and never read (see
/// [`Robot::frame_id_of`]).
#[derive(Clone, Debug)]
pub struct KinematicsData {
    pub(crate) nf: usize,
    /// The base's entries in velocity vectors and Jacobian columns: 6 for a floating base
    /// (its twist comes first), 0 otherwise.
    pub(crate) nb: usize,
    pub(crate) level: Level,
    pub(crate) tree: MovingTree,
    /// Per moving link 0..N (0 the base).
    pub(crate) rot: Vec<Matrix3<f64>>,
    pub(crate) pos: Vec<Vector3<f64>>,
    pub(crate) w: Vec<Vector3<f64>>,
    pub(crate) v: Vec<Vector3<f64>>,
    pub(crate) wd: Vec<Vector3<f64>>,
    pub(crate) a: Vec<Vector3<f64>>,
    /// Per moving link 0..N: its joint's column of the World Jacobian, [O_k x z_k; z_k]
    /// (revolute) or [z_k; 0] (prismatic), stored by [`joint_jacobians_into`] (Pinocchio's
    /// `data.J` of `computeJointJacobians`), valid when `columns` holds; the frame Jacobians
    /// read them then, and compute them from the placements otherwise.
    pub(crate) col: Vec<[f64; 6]>,
    pub(crate) columns: bool,
    /// The q̈ of the last [`forward_kinematics_into`] (nv: the base's 6 first when it floats).
    pub(crate) qdd: Vec<f64>,
    /// The moving links from a frame to the base (scratch of the support-only pass).
    pub(crate) chain: Vec<usize>,
    /// Per moving link 0..N: the counted bodies of the last centre of mass call (mass, first
    /// moment in the link's axes), then its subtree's sums m, sum m_j 0P_Gj (in R_0).
    pub(crate) body_m: Vec<f64>,
    pub(crate) body_ms: Vec<Vector3<f64>>,
    pub(crate) sub_m: Vec<f64>,
    pub(crate) sub_ms: Vec<Vector3<f64>>,
    /// Per description link 0..NL: in the subtree of the last centre of mass call.
    pub(crate) member: Vec<bool>,
}

impl KinematicsData {
    /// The buffers of `robot`'s kinematic functions.
    pub fn new(robot: &Robot) -> KinematicsData {
        let n = robot.dof();
        let v = || vec![Vector3::zeros(); n + 1];
        let nb = robot.nv() - n;
        KinematicsData {
            nf: robot.nf(),
            nb,
            level: Level::None,
            tree: MovingTree::new(robot),
            rot: vec![Matrix3::identity(); n + 1],
            pos: v(),
            w: v(),
            v: v(),
            wd: v(),
            a: v(),
            col: vec![[0.0; 6]; n + 1],
            columns: false,
            qdd: vec![0.0; n + nb],
            chain: Vec::with_capacity(n + 1),
            body_m: vec![0.0; n + 1],
            body_ms: v(),
            sub_m: vec![0.0; n + 1],
            sub_ms: v(),
            member: vec![false; robot.nl() + 1],
        }
    }

    /// Error unless this data was made for a robot of `robot`'s size ([`Error::Dimension`]).
    pub fn check(&self, robot: &Robot) -> Result<()> {
        if self.nf != robot.nf()
            || self.qdd.len() != robot.nv()
            || self.member.len() != robot.nl() + 1
        {
            return Err(Error::dimension(
                "kinematics data",
                robot.nf(),
                self.nf,
                format!(
                    "frames: the KinematicsData was made for another robot than `{}`",
                    robot.name()
                ),
            ));
        }
        Ok(())
    }

    /// Error unless the data fits `robot` and its last pass reached `level`.
    pub(crate) fn ready(&self, robot: &Robot, level: Level) -> Result<()> {
        self.check(robot)?;
        if self.level < level {
            let what = match level {
                Level::Motion => "velocities and accelerations: run forward_kinematics_into",
                _ => "placements: run placements_into or forward_kinematics_into",
            };
            return Err(Error::Input(format!(
                "the KinematicsData holds no {what} first"
            )));
        }
        Ok(())
    }
}

/// Placements 0T_j of every frame for the configuration `q` into `data`: enough for
/// [`frame_placement`], the Jacobians and the centre of mass position. `q` holds the movable
/// joints in frame order, after the base pose (position in the world, quaternion x y z w) when
/// the base floats (nq = 7 + N entries): the placements are then in the world frame.
/// Allocation-free.
///
/// Errors: [`Error::Dimension`] for a `q` of the wrong length or a `data` of another robot,
/// [`Error::NotFinite`] for a NaN or infinite entry, [`Error::Input`] for a base quaternion
/// that is not a unit one.
pub fn placements_into(robot: &Robot, data: &mut KinematicsData, q: &[f64]) -> Result<()> {
    let q = set_configuration(robot, data, q)?;
    for k in 1..=data.tree.n() {
        place::<false>(data, k, q[k - 1]);
    }
    data.level = Level::Placements;
    Ok(())
}

/// [`placements_into`] that also stores every joint's column of the `World` Jacobian in the
/// same pass (Pinocchio's `computeJointJacobians`): the frame Jacobians
/// ([`frame_jacobian_into`](super::frame_jacobian_into)) are then copies of their support's
/// columns (`World`) or these moved to the frame. After [`placements_into`] or
/// [`forward_kinematics_into`] they compute the columns from the placements instead (same
/// numbers). Allocation-free.
///
/// Errors: as [`placements_into`].
pub fn joint_jacobians_into(robot: &Robot, data: &mut KinematicsData, q: &[f64]) -> Result<()> {
    let q = set_configuration(robot, data, q)?;
    for k in 1..=data.tree.n() {
        place::<true>(data, k, q[k - 1]);
    }
    data.columns = true;
    data.level = Level::Placements;
    Ok(())
}

/// The checked entry of every pass on a configuration: `data` fits `robot`, `q` has nq entries
/// (the one check of joint vectors for a fixed base; the base pose and a unit quaternion for a
/// floating one, whose placement wT_0 becomes link 0's). Returns the joints' part of `q`.
pub(crate) fn set_configuration<'a>(
    robot: &Robot,
    data: &mut KinematicsData,
    q: &'a [f64],
) -> Result<&'a [f64]> {
    data.check(robot)?;
    data.level = Level::None;
    data.columns = false;
    if data.nb == 0 {
        robot.coordinates().check("q", q, "movable joints")?;
        return Ok(q);
    }
    data.rot[0] = check_floating_vectors(robot, q, &[])?;
    data.pos[0] = v3(&q[..3]);
    Ok(&q[7..])
}

/// The checked velocities and accelerations (nv entries) of a pass after
/// [`set_configuration`]: q̈ kept in `data`, and for a floating base its motion in the world
/// made link 0's (w_0 = R w, v_0 = R v, wd_0 = R wd, a_0 = R (a + w x v) the classical
/// acceleration of O_0, with v, w, a, wd in R_0 as the state holds them). Returns the joints'
/// parts.
fn set_motion<'a>(
    robot: &Robot,
    data: &mut KinematicsData,
    qd: &'a [f64],
    qdd: &'a [f64],
) -> Result<(&'a [f64], &'a [f64])> {
    if data.nb == 0 {
        let c = robot.coordinates();
        c.check("qd", qd, "movable joints")?;
        c.check("qdd", qdd, "movable joints")?;
        data.qdd.copy_from_slice(qdd);
        return Ok((qd, qdd));
    }
    let n = robot.dof();
    for (name, x) in [("qd", qd), ("qdd", qdd)] {
        crate::error::check_vector(name, x, n + 6, || {
            format!("nv = 6 + {n}: base linear, angular (in the base frame), joints")
        })?;
    }
    let r = data.rot[0];
    let (lin, w) = (v3(&qd[..3]), v3(&qd[3..6]));
    data.w[0] = r * w;
    data.v[0] = r * lin;
    data.wd[0] = r * v3(&qdd[3..6]);
    data.a[0] = r * (v3(&qdd[..3]) + w.cross(&lin));
    data.qdd.copy_from_slice(qdd);
    Ok((&qd[6..], &qdd[6..]))
}

/// Joint k's column of the `World` Jacobian from its placement: [O_k x z_k; z_k] (revolute),
/// [z_k; 0] (prismatic).
#[inline(always)]
pub(crate) fn world_column(data: &KinematicsData, k: usize) -> [f64; 6] {
    column_of(&data.rot[k], &data.pos[k], data.tree.revolute[k])
}

/// The World column of a joint placed at (`rot`, `pos`).
#[inline(always)]
fn column_of(rot: &Matrix3<f64>, pos: &Vector3<f64>, revolute: bool) -> [f64; 6] {
    axis_column(&rot.column(2).into_owned(), pos, revolute)
}

/// The World column of a motion about (revolute) or along (prismatic) the axis `z` through
/// `pos`: [pos x z; z] or [z; 0].
#[inline(always)]
pub(crate) fn axis_column(z: &Vector3<f64>, pos: &Vector3<f64>, revolute: bool) -> [f64; 6] {
    if revolute {
        let l = pos.cross(z);
        [l.x, l.y, l.z, z.x, z.y, z.z]
    } else {
        [z.x, z.y, z.z, 0.0, 0.0, 0.0]
    }
}

/// Base column c (0..6) of a floating robot's `World` Jacobian: the base twist's entries are
/// translations along (c < 3) and rotations about (c >= 3) the base axes x, y, z through O_0,
/// so each is the column of a prismatic or revolute joint on that axis.
#[inline]
pub(crate) fn base_column(data: &KinematicsData, c: usize) -> [f64; 6] {
    let z = data.rot[0].column(c % 3).into_owned();
    axis_column(&z, &data.pos[0], c >= 3)
}

/// The placements of the moving links from the base to the one frame `f` is fixed on (its
/// support: Pinocchio's `computeFrameJacobian` pass), into `data`, `q` the joints' part after
/// [`set_configuration`]. The other links keep older values, so `data` holds no full pass
/// afterwards (its level is reset).
pub(crate) fn place_support(data: &mut KinematicsData, q: &[f64], f: &FrameId) {
    data.level = Level::None;
    data.columns = false;
    data.chain.clear();
    let mut k = data.tree.anchor[f.parent()].link;
    while k != 0 {
        data.chain.push(k);
        k = data.tree.frame(k).ant;
    }
    for i in (0..data.chain.len()).rev() {
        let k = data.chain[i];
        place::<false>(data, k, q[k - 1]);
    }
}

/// 0T_k = 0T_a(k) a(k)T_k for moving link k at joint value `qk`, and with `COLUMN` its World
/// column from the placement still in registers (read back from memory it cost a third more).
#[inline(always)]
fn place<const COLUMN: bool>(data: &mut KinematicsData, k: usize, qk: f64) {
    let fc = data.tree.frame(k);
    let (r, p) = fc.placement(&qk);
    let a = fc.ant;
    let ra = data.rot[a];
    let pos = data.pos[a] + ra * p;
    let rot = mul_form(&ra, &r, fc.form());
    if COLUMN {
        data.col[k] = column_of(&rot, &pos, fc.joint == JointType::Revolute);
    }
    data.pos[k] = pos;
    data.rot[k] = rot;
}

/// The forward kinematic model of every frame for a state over the movable joints (frame
/// order): positions `q` (rad, m), velocities `qd`, accelerations `qdd`, into `data`. Fills the
/// placements 0T_j and, in R_0 at O_j, the angular velocity w_j, linear velocity v_j, angular
/// acceleration wd_j and linear (classical) acceleration a_j, from the base (no gravity). A
/// floating base's state comes first (q: nq = 7 + N entries; qd, qdd: nv = 6 + N, the base
/// twist in R_0 and its derivative): R_0 is then the world frame and the base moves as link 0:
///
/// w_j = w_i + qd_j z_j (revolute), v_j = v_i + w_i x P + qd_j z_j (prismatic),
/// wd_j = wd_i + w_i x qd_j z_j + qdd_j z_j (revolute),
/// a_j = a_i + wd_i x P + w_i x (w_i x P) + 2 w_i x qd_j z_j + qdd_j z_j (prismatic),
///
/// with i = a(j), P = O_i O_j and z_j in R_0. Allocation-free.
///
/// Errors: [`Error::Dimension`], [`Error::NotFinite`] for a bad input; [`Error::Numerical`]
/// when finite inputs overflow.
///
/// # Example
///
/// ```
/// use robodyn::{forward_kinematics_into, frame_classical_acceleration, KinematicsData, Reference};
/// # fn main() -> robodyn::Result<()> {
/// let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
/// let rx90 = robodyn::io::load(urdf)?;
/// let tool = rx90.frame_id("6")?; // frame 6
/// let mut data = KinematicsData::new(&rx90);
/// forward_kinematics_into(&rx90, &mut data, &[0.1; 6], &[0.2; 6], &[0.0; 6])?;
/// let a = frame_classical_acceleration(&rx90, &data, &tool, Reference::LocalWorldAligned)?;
/// assert!(a.linear.norm() > 0.0); // centripetal at constant joint speeds
/// # Ok(())
/// # }
/// ```
pub fn forward_kinematics_into(
    robot: &Robot,
    data: &mut KinematicsData,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Result<()> {
    let q = set_configuration(robot, data, q)?;
    let (qd, qdd) = set_motion(robot, data, qd, qdd)?;
    for k in 1..=data.tree.n() {
        place::<false>(data, k, q[k - 1]);
        propagate(data, k, qd[k - 1], qdd[k - 1]);
    }
    let finite = |v: &[Vector3<f64>]| v.iter().all(|x| x.iter().all(|e| e.is_finite()));
    if !(finite(&data.w) && finite(&data.v) && finite(&data.wd) && finite(&data.a)) {
        return Err(Error::Numerical(
            "the frame velocities or accelerations overflow (finite inputs too large)".into(),
        ));
    }
    data.level = Level::Motion;
    Ok(())
}

/// Velocity and acceleration of moving link k from its antecedent's (after [`place`]).
#[inline]
fn propagate(data: &mut KinematicsData, k: usize, qd: f64, qdd: f64) {
    let fc = data.tree.frame(k);
    let i = fc.ant;
    let p = data.pos[k] - data.pos[i];
    let z: Vector3<f64> = data.rot[k].column(2).into_owned();
    let (wi, wdi) = (data.w[i], data.wd[i]);
    let mut w = wi;
    let mut v = data.v[i] + wi.cross(&p);
    let mut wd = wdi;
    let mut a = data.a[i] + wdi.cross(&p) + wi.cross(&wi.cross(&p));
    match fc.joint {
        JointType::Revolute => {
            w += qd * z;
            wd += wi.cross(&(qd * z)) + qdd * z;
        }
        JointType::Prismatic => {
            v += qd * z;
            a += 2.0 * wi.cross(&(qd * z)) + qdd * z;
        }
        JointType::Fixed => {}
    }
    data.w[k] = w;
    data.v[k] = v;
    data.wd[k] = wd;
    data.a[k] = a;
}

/// 0T_f, the placement of frame `f` (its anchor's placement, its offsets composed).
#[inline]
pub(crate) fn placement_of(data: &KinematicsData, f: &FrameId) -> Transform {
    let an = &data.tree.anchor[f.parent()];
    let mut t = Transform {
        rot: data.rot[an.link],
        pos: data.pos[an.link],
    };
    if !an.identity {
        t = t.compose(&an.t);
    }
    if !f.is_identity() {
        t = t.compose(f.offset());
    }
    t
}

/// The frame's placement 0T_f and, in R_0 at its origin, w, v, wd, a (a the classical
/// acceleration of the origin).
pub(crate) struct FrameState {
    pub t: Transform,
    pub w: Vector3<f64>,
    pub v: Vector3<f64>,
    pub wd: Vector3<f64>,
    pub a: Vector3<f64>,
}

/// The state of frame `f` from its anchor's (a rigid offset: same w, wd; v and a of the point).
pub(crate) fn frame_state(data: &KinematicsData, f: &FrameId) -> FrameState {
    let k = data.tree.anchor[f.parent()].link;
    let t = placement_of(data, f);
    let r = t.pos - data.pos[k];
    let (w, wd) = (data.w[k], data.wd[k]);
    FrameState {
        t,
        w,
        v: data.v[k] + w.cross(&r),
        wd,
        a: data.a[k] + wd.cross(&r) + w.cross(&w.cross(&r)),
    }
}

/// 0T_f, the placement of frame `f` in R_0, after [`placements_into`] or
/// [`forward_kinematics_into`].
///
/// Errors: [`Error::Input`] when `data` holds no placements or `f` belongs to another robot,
/// [`Error::Dimension`] for a `data` of another robot.
pub fn frame_placement(robot: &Robot, data: &KinematicsData, f: &FrameId) -> Result<Transform> {
    data.ready(robot, Level::Placements)?;
    f.check(robot)?;
    Ok(placement_of(data, f))
}

/// jT_k = (0T_j)^-1 0T_k, the placement of frame `k` in frame `j`.
///
/// Errors: as [`frame_placement`].
pub fn relative_placement(
    robot: &Robot,
    data: &KinematicsData,
    j: &FrameId,
    k: &FrameId,
) -> Result<Transform> {
    let tj = frame_placement(robot, data, j)?;
    let tk = frame_placement(robot, data, k)?;
    Ok(tj.inverse().compose(&tk))
}

/// The velocity of frame `f` ([`Motion`], [linear; angular]) expressed in `reference`, after
/// [`forward_kinematics_into`]: in [`Reference::LocalWorldAligned`] the velocity of its origin
/// and its angular velocity in R_0 (Khalil's 0V_n, 0w_n); in [`Reference::Local`] the same in
/// the frame's own axes (nV_n, nw_n); in [`Reference::World`] the spatial velocity in R_0 (the
/// linear part is the velocity of the body point at O_0).
///
/// Errors: [`Error::Input`] when `data` holds no velocities or `f` belongs to another robot.
pub fn frame_velocity(
    robot: &Robot,
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
) -> Result<Motion> {
    data.ready(robot, Level::Motion)?;
    f.check(robot)?;
    let s = frame_state(data, f);
    Ok(velocity_in(&s, reference))
}

fn velocity_in(s: &FrameState, reference: Reference) -> Motion {
    match reference {
        Reference::LocalWorldAligned => Motion::new(s.v, s.w),
        Reference::Local => Motion::new(s.t.rot.tr_mul(&s.v), s.t.rot.tr_mul(&s.w)),
        Reference::World => Motion::new(s.v + s.t.pos.cross(&s.w), s.w),
    }
}

/// The spatial acceleration of frame `f` in `reference` (Pinocchio's `getFrameAcceleration`),
/// after [`forward_kinematics_into`]: the time derivative of the spatial velocity in the
/// reference's axes. In `Local` and `LocalWorldAligned` its linear part is the classical
/// acceleration of the origin minus w x v; in `World`, d/dt (v + O_f x w) = a + v x w + O_f x wd.
/// J q̈ + J̇ q̇ of the same reference ([`frame_jacobian_into`](super::frame_jacobian_into),
/// [`frame_jacobian_time_variation_into`](super::frame_jacobian_time_variation_into)).
///
/// Errors: as [`frame_velocity`].
pub fn frame_acceleration(
    robot: &Robot,
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
) -> Result<Motion> {
    data.ready(robot, Level::Motion)?;
    f.check(robot)?;
    let s = frame_state(data, f);
    Ok(match reference {
        Reference::LocalWorldAligned => Motion::new(s.a - s.w.cross(&s.v), s.wd),
        Reference::Local => {
            let lin = s.a - s.w.cross(&s.v);
            Motion::new(s.t.rot.tr_mul(&lin), s.t.rot.tr_mul(&s.wd))
        }
        Reference::World => Motion::new(s.a + s.v.cross(&s.w) + s.t.pos.cross(&s.wd), s.wd),
    })
}

/// The classical acceleration of frame `f` in `reference` (Pinocchio's
/// `getFrameClassicalAcceleration`): the spatial acceleration plus w x v (both in the
/// reference). In `LocalWorldAligned`, the acceleration of the frame's origin and the angular
/// acceleration in R_0 (Khalil's 0V̇_n, 0ẇ_n); in `Local` the same in the frame's axes; in
/// `World` Pinocchio's definition applied to the spatial velocity at O_0 (not the acceleration
/// of a material point).
///
/// Errors: as [`frame_velocity`].
pub fn frame_classical_acceleration(
    robot: &Robot,
    data: &KinematicsData,
    f: &FrameId,
    reference: Reference,
) -> Result<Motion> {
    let acc = frame_acceleration(robot, data, f, reference)?;
    let vel = frame_velocity(robot, data, f, reference)?;
    Ok(Motion::new(
        acc.linear + vel.angular.cross(&vel.linear),
        acc.angular,
    ))
}
