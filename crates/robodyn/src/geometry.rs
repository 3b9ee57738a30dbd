//! Geometric model: iT_j and 0T_j for given joint values.

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

/// 0T_j for every frame j = 1..NF (index j-1). `q` holds the joint values of frames 1..NL, or
/// 1..NJ to include the cut-joint variables (missing cut-joint values are taken as 0).
pub fn frame_transforms(robot: &Robot, q: &[f64]) -> Vec<Transform> {
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
