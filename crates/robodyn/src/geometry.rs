//! Geometric model: iT_j and 0T_j for given joint values.

use crate::error::{check_vector, Result};
use crate::model::Robot;
use nalgebra::{Matrix3, Matrix4, Vector3};

/// A rigid transformation: orientation matrix and origin position.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Orientation (rotation matrix) of the frame.
    pub rot: Matrix3<f64>,
    /// Origin of the frame (m).
    pub pos: Vector3<f64>,
}

impl Transform {
    /// The identity transformation.
    pub fn identity() -> Self {
        Transform {
            rot: Matrix3::identity(),
            pos: Vector3::zeros(),
        }
    }

    /// self * other.
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform {
            rot: self.rot * other.rot,
            pos: self.pos + self.rot * other.pos,
        }
    }

    /// The inverse transformation.
    pub fn inverse(&self) -> Transform {
        let rt = self.rot.transpose();
        Transform {
            rot: rt,
            pos: -(rt * self.pos),
        }
    }

    /// The 4x4 homogeneous matrix.
    pub fn matrix(&self) -> Matrix4<f64> {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rot);
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.pos);
        m
    }
}

/// iT_j for frame j (1-based) and joint value q (ignored for fixed frames).
pub fn local_transform(robot: &Robot, j: usize, q: f64) -> Transform {
    let (rot, pos) = robot.numeric().frame(j).transform(&q);
    Transform { rot, pos }
}

/// 0T_j for every frame j = 1..NF (index j-1) at joint values `q` over the movable joints in
/// frame order ([`Robot::coordinates`], the vectors of every other function); fixed frames
/// keep their constant placement and the cut-joint variables of a closed chain are 0 (use
/// [`frame_transforms_with_cuts`] to give them).
///
/// Errors: [`crate::Error::Dimension`] when `q` does not have `robot.dof()` entries,
/// [`crate::Error::NotFinite`] for a NaN or infinite entry.
///
/// # Example
///
/// ```
/// # fn main() -> robodyn::Result<()> {
/// let robots = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots");
/// let rx90 = robodyn::io::load(format!("{robots}/rx90.urdf"))?;
/// let t = robodyn::geometry::frame_transforms(&rx90, &[0.0; 6])?;
/// assert_eq!(t.len(), rx90.nf());
/// assert!(robodyn::geometry::frame_transforms(&rx90, &[0.0; 5]).is_err());
/// # Ok(())
/// # }
/// ```
pub fn frame_transforms(robot: &Robot, q: &[f64]) -> Result<Vec<Transform>> {
    frame_transforms_with_cuts(robot, q, &vec![0.0; robot.n_loops()])
}

/// 0T_j for every frame j = 1..NF (index j-1) at joint values `q` over the movable joints
/// (as [`frame_transforms`]) and the cut-joint variables `q_cut` of joints NL+1..NJ (one per
/// loop, [`Robot::n_loops`] entries).
///
/// Errors: [`crate::Error::Dimension`], [`crate::Error::NotFinite`] for a bad `q` or `q_cut`.
pub fn frame_transforms_with_cuts(
    robot: &Robot,
    q: &[f64],
    q_cut: &[f64],
) -> Result<Vec<Transform>> {
    let c = robot.coordinates();
    c.check("q", q, "movable joints")?;
    check_vector("q_cut", q_cut, robot.n_loops(), || {
        format!("cut joints {}..{}", robot.nl() + 1, robot.nj())
    })?;
    let mut frames = vec![0.0; robot.nj()];
    c.scatter(q, &mut frames[..robot.nl()]);
    frames[robot.nl()..].copy_from_slice(q_cut);
    Ok(frame_transforms_per_frame(robot, &frames))
}

/// 0T_j for every frame j = 1..NF (index j-1) from per-frame values: `q` holds the values of
/// frames 1..NL (fixed frames included, their entries ignored), or 1..NJ to include the
/// cut-joint variables (missing values are taken as 0). Unchecked: the library's own layout,
/// the public entry points are [`frame_transforms`] and [`frame_transforms_with_cuts`].
pub(crate) fn frame_transforms_per_frame(robot: &Robot, q: &[f64]) -> Vec<Transform> {
    let nf = robot.nf();
    let mut out: Vec<Transform> = Vec::with_capacity(nf);
    for j in 1..=nf {
        let qj = q.get(j - 1).copied().unwrap_or(0.0);
        let local = local_transform(robot, j, if j <= robot.nj() { qj } else { 0.0 });
        let a = robot.ant(j);
        let t = if a == 0 {
            local
        } else {
            out[a - 1].compose(&local)
        };
        out.push(t);
    }
    out
}
