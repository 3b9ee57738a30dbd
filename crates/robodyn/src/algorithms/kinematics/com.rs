//! Centre of mass of the robot or of a subtree: position, velocity, acceleration (in R_0), its
//! Jacobian (3 x nv) and the mass. As in Pinocchio and in the dynamic model, the bodies are
//! those of the links that move: on a fixed base, links rigidly attached to the base (through
//! fixed frames only) carry no joint, never move, and are not counted, like the root link; a
//! floating base's body (link 0 and the links fixed on it) moves and is counted, in the world
//! frame.

use super::forward::{placements_into, KinematicsData, Level};
use super::frames::FrameId;
use super::jacobian::check_matrix;
use crate::error::{Error, Result};
use crate::model::Robot;
use nalgebra::{DMatrix, Vector3};

/// The centre of mass G of a set of links, in R_0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CenterOfMass {
    /// Total mass (kg).
    pub mass: f64,
    /// 0P_G (m).
    pub position: Vector3<f64>,
    /// Velocity of G (m/s).
    pub velocity: Vector3<f64>,
    /// Acceleration of G (m/s²), without gravity.
    pub acceleration: Vector3<f64>,
}

/// For each link 0..=NL (0 the base), whether a movable joint lies between it and the base.
pub(crate) fn moving_links(robot: &Robot, out: &mut [bool]) {
    out[0] = false;
    for j in 1..=robot.nl() {
        out[j] = robot.frame(j).joint.is_movable() || out[robot.ant(j)];
    }
}

/// The link a frame is carried by: the frame itself for a link frame, the link under a chain of
/// twin frames otherwise (0 the base).
fn carrying_link(robot: &Robot, frame: usize) -> usize {
    let mut j = frame;
    while j > robot.nl() {
        j = robot.ant(j);
    }
    j
}

/// Mark in `member` (description links 0..NL) the subtree of links rooted at link `r`.
fn mark_subtree(robot: &Robot, r: usize, member: &mut [bool]) {
    member[0] = r == 0;
    for j in 1..=robot.nl() {
        member[j] = j == r || member[robot.ant(j)];
    }
}

/// The bodies counted for `root`: the whole robot (no root, or a frame carried by the base) is
/// the moving tree's own bodies; a subtree's are gathered into `data.body_m`, `data.body_ms`.
/// Returns the root's carrying link and whether it is the whole robot.
fn select_bodies(
    robot: &Robot,
    data: &mut KinematicsData,
    root: Option<&FrameId>,
) -> Result<(usize, bool)> {
    let r = match root {
        Some(f) => {
            f.check(robot)?;
            carrying_link(robot, f.parent())
        }
        None => 0,
    };
    if r == 0 {
        return Ok((0, true));
    }
    mark_subtree(robot, r, &mut data.member);
    let member = &data.member;
    data.tree
        .bodies(robot, |j| member[j], &mut data.body_m, &mut data.body_ms);
    Ok((r, false))
}

fn no_mass(robot: &Robot, r: usize) -> Error {
    Error::Input(if r == 0 {
        format!(
            "`{}` has no moving mass: its centre of mass is undefined",
            robot.name()
        )
    } else {
        format!("the links from link {r} on have no mass: their centre of mass is undefined")
    })
}

/// The centre of mass of the robot (`root` None) or of the subtree of links carried by the
/// frame `root` (its link and every link after it), after
/// [`forward_kinematics_into`](super::forward_kinematics_into): position, velocity and
/// acceleration of G in R_0, with the mass. Allocation-free.
///
/// G = sum m_j 0P_Gj / M with m_j 0P_Gj = m_j 0P_j + 0A_j jMS_j; its velocity and acceleration
/// are those of the points G_j of the links (rigid-body transport from O_j).
///
/// Errors: [`Error::Input`] for a `data` without velocities, a frame of another robot, or a
/// massless set of links.
pub fn center_of_mass(
    robot: &Robot,
    data: &mut KinematicsData,
    root: Option<&FrameId>,
) -> Result<CenterOfMass> {
    data.ready(robot, Level::Motion)?;
    let (r, whole) = select_bodies(robot, data, root)?;
    let (bm, bms) = if whole {
        (&data.tree.mass, &data.tree.ms)
    } else {
        (&data.body_m, &data.body_ms)
    };
    let (mut mass, mut first, mut vel, mut acc) =
        (0.0, Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
    // link 0 is a floating base's body (massless and at rest on a fixed base)
    for k in 0..bm.len() {
        let m = bm[k];
        let c = data.rot[k] * bms[k]; // sum m_j (G_j - O_k) in R_0
        let (w, wd) = (data.w[k], data.wd[k]);
        mass += m;
        first += m * data.pos[k] + c;
        vel += m * data.v[k] + w.cross(&c);
        acc += m * data.a[k] + wd.cross(&c) + w.cross(&w.cross(&c));
    }
    if mass <= 0.0 {
        return Err(no_mass(robot, r));
    }
    Ok(CenterOfMass {
        mass,
        position: first / mass,
        velocity: vel / mass,
        acceleration: acc / mass,
    })
}

/// The Jacobian of the centre of mass (of the robot, or of the subtree carried by `root`) into
/// `out` (3 x nv): G's velocity is `out` q̇ (a floating base's 6 columns first: R_0 along its
/// translations, z x (G - O_0) about its axes z). After [`placements_into`](super::placements_into)
/// or [`forward_kinematics_into`](super::forward_kinematics_into). Column of joint k:
/// z_k x (S_k - M_k O_k) / M (revolute), M_k z_k / M (prismatic), with M_k and S_k the mass and
/// first moment sum m_j 0P_Gj of the counted links moved by joint k (Pinocchio's
/// `jacobianCenterOfMass` for the whole robot). Allocation-free.
/// [`center_of_mass_jacobian_from_q_into`] places the links first.
///
/// Errors: as [`center_of_mass`] (a `data` with placements suffices), and
/// [`Error::Dimension`] for an `out` that is not 3 x nv.
pub fn center_of_mass_jacobian_into(
    robot: &Robot,
    data: &mut KinematicsData,
    root: Option<&FrameId>,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    data.ready(robot, Level::Placements)?;
    check_matrix(robot, "Jcom", out, 3)?;
    com_jacobian(robot, data, root, out).map(|_| ())
}

/// The Jacobian of the centre of mass at the configuration `q` (nq) into `out` (3 x nv): the
/// placements of [`placements_into`](super::placements_into) (`data` holds them afterwards),
/// then [`center_of_mass_jacobian_into`] (Pinocchio's `jacobianCenterOfMass(model, data, q)`,
/// which gives G too). Returns G (0P_G, m). Allocation-free.
///
/// The passes: placements (base to tips), each link's own first moment, then one pass from
/// the tips to the base that completes each link's subtree sums, writes its joint's column
/// and adds the sums to its antecedent's. Measured against the other orders (the first moment
/// taken in the placement pass, the columns in a pass of their own), this one was the fastest.
///
/// Errors: as [`placements_into`](super::placements_into) and [`center_of_mass_jacobian_into`].
pub fn center_of_mass_jacobian_from_q_into(
    robot: &Robot,
    data: &mut KinematicsData,
    q: &[f64],
    root: Option<&FrameId>,
    out: &mut DMatrix<f64>,
) -> Result<Vector3<f64>> {
    check_matrix(robot, "Jcom", out, 3)?;
    placements_into(robot, data, q)?;
    com_jacobian(robot, data, root, out)
}

/// The checked body of [`center_of_mass_jacobian_into`] on placed links: G.
fn com_jacobian(
    robot: &Robot,
    data: &mut KinematicsData,
    root: Option<&FrameId>,
    out: &mut DMatrix<f64>,
) -> Result<Vector3<f64>> {
    let (r, whole) = select_bodies(robot, data, root)?;
    let mut mass = 0.0;
    // link 0: a floating base's body (none on a fixed base: its sums start at zero)
    for k in 0..=data.tree.n() {
        mass += own_moment(data, k, whole);
    }
    if mass <= 0.0 {
        return Err(no_mass(robot, r));
    }
    Ok(subtree_columns(data, mass, out.as_mut_slice()))
}

/// Moving link k's counted bodies (the whole robot's, or the subtree's of `select_bodies`):
/// their mass and first moment sum m_j 0P_Gj = m O_k + 0A_k kMS (R_0) start link k's subtree
/// sums. Returns the mass.
#[inline(always)]
fn own_moment(data: &mut KinematicsData, k: usize, whole: bool) -> f64 {
    let (m, ms) = if whole {
        (data.tree.mass[k], data.tree.ms[k])
    } else {
        (data.body_m[k], data.body_ms[k])
    };
    data.sub_m[k] = m;
    data.sub_ms[k] = m * data.pos[k] + data.rot[k] * ms;
    m
}

/// From the last moving link to the first: link k's subtree sums are complete (its children
/// come after it), so joint k's column is written, z_k x (S_k - M_k O_k) / M (revolute) or
/// M_k z_k / M (prismatic), and the sums are added to its antecedent's. A floating base's
/// columns are those of joints on its axes through O_0, with the sums of the whole set.
/// Returns G = S_0 / M.
#[inline(always)]
fn subtree_columns(data: &mut KinematicsData, mass: f64, out: &mut [f64]) -> Vector3<f64> {
    let inv = 1.0 / mass;
    let nb = data.nb;
    for k in (1..=data.tree.n()).rev() {
        let (mk, sk) = (data.sub_m[k], data.sub_ms[k]);
        let z: Vector3<f64> = data.rot[k].column(2).into_owned();
        let col = if data.tree.revolute[k] {
            z.cross(&(sk - mk * data.pos[k])) * inv
        } else {
            z * (mk * inv)
        };
        out[3 * (nb + k - 1)..3 * (nb + k)].copy_from_slice(col.as_slice());
        let a = data.tree.parent[k];
        data.sub_m[a] += mk;
        data.sub_ms[a] += sk;
    }
    let (m0, s0, o0) = (data.sub_m[0], data.sub_ms[0], data.pos[0]);
    for c in 0..nb {
        let z: Vector3<f64> = data.rot[0].column(c % 3).into_owned();
        let col = if c >= 3 {
            z.cross(&(s0 - m0 * o0)) * inv
        } else {
            z * (m0 * inv)
        };
        out[3 * c..3 * c + 3].copy_from_slice(col.as_slice());
    }
    s0 * inv
}

/// The mass of the links a joint moves (kg): what [`center_of_mass`] weighs.
pub fn total_mass(robot: &Robot) -> f64 {
    let mut moving = vec![false; robot.nl() + 1];
    moving_links(robot, &mut moving);
    // a floating base's body (link 0 and the links fixed on it) moves too
    let base = robot.floating_base().map_or(0.0, |b| b.body.mass);
    base + (1..=robot.nl())
        .filter(|&j| moving[j])
        .map(|j| robot.numeric().link(j).mass)
        .sum::<f64>()
}

/// The mass of the subtree of links carried by frame `root` (its link and every link after it
/// that a joint moves), kg.
///
/// Errors: [`Error::Input`] for a frame of another robot.
pub fn subtree_mass(robot: &Robot, root: &FrameId) -> Result<f64> {
    root.check(robot)?;
    let mut moving = vec![false; robot.nl() + 1];
    let mut member = vec![false; robot.nl() + 1];
    moving_links(robot, &mut moving);
    mark_subtree(robot, carrying_link(robot, root.parent()), &mut member);
    // every link of a floating robot moves
    let floating = robot.is_floating();
    Ok((1..=robot.nl())
        .filter(|&j| member[j] && (moving[j] || floating))
        .map(|j| robot.numeric().link(j).mass)
        .sum())
}
