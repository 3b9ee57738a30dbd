//! Centre of mass of the robot or of a subtree: position, velocity, acceleration (in R_0), its
//! Jacobian (3 x N) and the mass. As in Pinocchio and in the dynamic model, the bodies are
//! those of the links a joint moves: links rigidly attached to the base (through fixed frames
//! only) carry no joint, never move, and are not counted, like the root link.

use super::forward::{KinematicsData, Level};
use super::frames::FrameId;
use super::jacobian::{check_matrix, for_each_support_joint};
use crate::error::{Error, Result};
use crate::model::{JointType, Robot};
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

/// Mark in `data.member` the links of the subtree rooted at `root`'s carrying link that a
/// joint moves (all moving links for `None` or a frame on the base); returns that link.
fn mark_subtree(robot: &Robot, data: &mut KinematicsData, root: Option<&FrameId>) -> Result<usize> {
    let r = match root {
        Some(f) => {
            f.check(robot)?;
            carrying_link(robot, f.parent())
        }
        None => 0,
    };
    moving_links(robot, &mut data.moving);
    data.member[0] = r == 0;
    for j in 1..=robot.nl() {
        data.member[j] = j == r || data.member[robot.ant(j)];
    }
    for j in 0..=robot.nl() {
        data.member[j] &= data.moving[j];
    }
    Ok(r)
}

/// Per link j in the subtree: m_j 0P_Gj = m_j 0P_j + 0A_j jMS_j into `data.sub_ms`, m_j into
/// `data.sub_m`, then summed towards the base (each link then holds its subtree's sums).
fn accumulate_first_moments(robot: &Robot, data: &mut KinematicsData) {
    let m = robot.numeric();
    for j in 0..=robot.nl() {
        let (ms, mass) = if j > 0 && data.member[j] {
            let l = m.link(j);
            (l.mass * data.pos[j] + data.rot[j] * l.ms, l.mass)
        } else {
            (Vector3::zeros(), 0.0)
        };
        data.sub_ms[j] = ms;
        data.sub_m[j] = mass;
    }
    for j in (1..=robot.nl()).rev() {
        let a = robot.ant(j);
        let (ms, mass) = (data.sub_ms[j], data.sub_m[j]);
        data.sub_ms[a] += ms;
        data.sub_m[a] += mass;
    }
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
    let r = mark_subtree(robot, data, root)?;
    let m = robot.numeric();
    let (mut mass, mut first, mut vel, mut acc) =
        (0.0, Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
    for j in 1..=robot.nl() {
        if !data.member[j] {
            continue;
        }
        let l = m.link(j);
        let c = data.rot[j] * l.ms; // m_j (G_j - O_j) in R_0
        let (w, wd) = (data.w[j], data.wd[j]);
        mass += l.mass;
        first += l.mass * data.pos[j] + c;
        vel += l.mass * data.v[j] + w.cross(&c);
        acc += l.mass * data.a[j] + wd.cross(&c) + w.cross(&w.cross(&c));
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
/// `out` (3 x N): G's velocity is `out` q̇. After [`placements_into`](super::placements_into)
/// or [`forward_kinematics_into`](super::forward_kinematics_into). Column of joint k:
/// z_k x (S_k - M_k O_k) / M (revolute), M_k z_k / M (prismatic), with M_k and S_k the mass and
/// first moment sum m_j 0P_Gj of the counted links moved by joint k (Pinocchio's
/// `jacobianCenterOfMass` for the whole robot). Allocation-free.
///
/// Errors: as [`center_of_mass`] (a `data` with placements suffices), and
/// [`Error::Dimension`] for an `out` that is not 3 x N.
pub fn center_of_mass_jacobian_into(
    robot: &Robot,
    data: &mut KinematicsData,
    root: Option<&FrameId>,
    out: &mut DMatrix<f64>,
) -> Result<()> {
    data.ready(robot, Level::Placements)?;
    check_matrix(robot, "Jcom", out, 3)?;
    let r = mark_subtree(robot, data, root)?;
    accumulate_first_moments(robot, data);
    let mass = data.sub_m[r];
    if mass <= 0.0 {
        return Err(no_mass(robot, r));
    }
    out.fill(0.0);
    let c = robot.coordinates();
    for (k, &j) in c.frames().iter().enumerate() {
        let z: Vector3<f64> = data.rot[j].column(2).into_owned();
        // the counted links moved by joint j: its subtree, cut to the root's
        let (s, mj) = if data.member[j] {
            (data.sub_ms[j], data.sub_m[j])
        } else if is_ancestor_or_self(robot, j, r) {
            (data.sub_ms[r], data.sub_m[r])
        } else {
            continue;
        };
        let col = match robot.frame(j).joint {
            JointType::Prismatic => mj * z,
            _ => z.cross(&(s - mj * data.pos[j])),
        } / mass;
        out.fixed_view_mut::<3, 1>(0, k).copy_from(&col);
    }
    Ok(())
}

/// Whether frame `j` is `r` or one of its ancestors.
fn is_ancestor_or_self(robot: &Robot, j: usize, r: usize) -> bool {
    let mut found = false;
    if r > 0 {
        for_each_support_joint(robot, r, |_, jj, _| found |= jj == j);
    }
    found
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
    let mut data = KinematicsData::new(robot);
    let r = mark_subtree(robot, &mut data, Some(root))?;
    let _ = r;
    Ok((1..=robot.nl())
        .filter(|&j| data.member[j])
        .map(|j| robot.numeric().link(j).mass)
        .sum())
}
