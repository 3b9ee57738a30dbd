//! Kinematics of tree robots (and of closed chains on their tracked branch): named frames,
//! placements, velocities and accelerations of frames, frame Jacobians in three references,
//! their time derivative, the centre of mass. The equations and their checks are in
//! `docs/models/kinematics.md`.
//!
//! The shape is Pinocchio's: a [`KinematicsData`] (one per thread) filled by one pass,
//! [`forward_kinematics_into`] (q, q̇, q̈) or [`placements_into`] (q only), then cheap reads for
//! any number of frames ([`frame_placement`], [`frame_velocity`], [`frame_jacobian_into`],
//! [`center_of_mass`], ...). Frames are resolved once by name ([`crate::Robot::frame_id`]).
//! Vectors and matrices are over the movable joints in frame order, as everywhere.

mod closed;
mod com;
mod forward;
mod frames;
mod jacobian;
mod newton_euler;
mod tree;

pub use closed::{closed_frame_drift, closed_frame_jacobian, ClosedDrift, ClosedJacobian};
pub use com::{
    center_of_mass, center_of_mass_jacobian_from_q_into, center_of_mass_jacobian_into,
    subtree_mass, total_mass, CenterOfMass,
};
pub use forward::{
    forward_kinematics_into, frame_acceleration, frame_classical_acceleration, frame_placement,
    frame_velocity, joint_jacobians_into, placements_into, relative_placement, KinematicsData,
};
pub use frames::{rpy, tool_transform, FrameId};
pub use jacobian::{
    frame_classical_drift, frame_jacobian, frame_jacobian_from_q_into, frame_jacobian_into,
    frame_jacobian_time_variation_into,
};
pub use newton_euler::{frame_motion_from_newton_euler, NewtonEulerFrame};

use nalgebra::{Vector3, Vector6};

/// Where a velocity, an acceleration or a Jacobian is expressed, named as Pinocchio's
/// `ReferenceFrame`. Rows are [linear; angular] in every reference.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reference {
    /// Spatial quantities in R_0: the linear part is the velocity of the body point that
    /// coincides with the origin O_0 (Pinocchio's `WORLD`).
    World,
    /// At the frame's origin, in the frame's own axes (Pinocchio's `LOCAL`; Khalil's nJ_n).
    Local,
    /// At the frame's origin, in R_0's axes (Pinocchio's `LOCAL_WORLD_ALIGNED`; Khalil's 0J_n).
    LocalWorldAligned,
}

impl Reference {
    /// Every reference.
    pub const ALL: [Reference; 3] = [
        Reference::World,
        Reference::Local,
        Reference::LocalWorldAligned,
    ];

    /// `world`, `local`, `local_world_aligned` ([`Reference::from_name`] reads it back).
    pub fn name(self) -> &'static str {
        match self {
            Reference::World => "world",
            Reference::Local => "local",
            Reference::LocalWorldAligned => "local_world_aligned",
        }
    }

    /// The reference of a name of [`Reference::name`].
    pub fn from_name(name: &str) -> Option<Reference> {
        Reference::ALL.into_iter().find(|r| r.name() == name)
    }

    /// What the reference is, in a few words.
    pub fn describe(self) -> &'static str {
        match self {
            Reference::World => "spatial, in the base frame (the body point at the base origin)",
            Reference::Local => "at the frame's origin, in the frame's axes",
            Reference::LocalWorldAligned => "at the frame's origin, in the base frame's axes",
        }
    }
}

/// A velocity or acceleration: linear (m/s, m/s²) and angular (rad/s, rad/s²) parts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Motion {
    /// Linear part.
    pub linear: Vector3<f64>,
    /// Angular part.
    pub angular: Vector3<f64>,
}

impl Motion {
    /// From its two parts.
    pub fn new(linear: Vector3<f64>, angular: Vector3<f64>) -> Motion {
        Motion { linear, angular }
    }

    /// [linear; angular] as one 6-vector (the rows of the Jacobians).
    pub fn to_vector(&self) -> Vector6<f64> {
        let l = &self.linear;
        let a = &self.angular;
        Vector6::new(l.x, l.y, l.z, a.x, a.y, a.z)
    }
}
