//! Frame motion read from the [`Data`] of the last Newton–Euler pass
//! ([`inverse_dynamics_into`](crate::inverse_dynamics_into)): a controller gets the placement,
//! angular velocity and acceleration and the linear acceleration of a frame with its torques,
//! without another pass.

use super::frames::FrameId;
use super::tree::anchor_of;
use crate::data::Data;
use crate::error::Result;
use crate::geometry::Transform;
use crate::model::{Environment, Robot};
use nalgebra::{Matrix3, Vector3};

/// A frame's motion from a Newton–Euler pass, all in R_0's axes (Khalil's 0w_n, 0ẇ_n, 0V̇_n).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonEulerFrame {
    /// 0T_f.
    pub placement: Transform,
    /// Angular velocity (rad/s).
    pub angular_velocity: Vector3<f64>,
    /// Angular acceleration (rad/s²).
    pub angular_acceleration: Vector3<f64>,
    /// Acceleration of the frame's origin (m/s²), gravity taken off (the pass carries it as an
    /// upward acceleration of the base, eq 10.6).
    pub linear_acceleration: Vector3<f64>,
}

/// The motion of frame `f` read from `data` after
/// [`inverse_dynamics_into`](crate::inverse_dynamics_into) (or
/// [`inverse_dynamics_state_into`](crate::inverse_dynamics_state_into)) on `robot` under `env`
/// (the same environment: its gravity is taken off). The pass holds, per movable link h, jw_j,
/// jẇ_j, jV̇_j and iT_j; the frame is carried by its nearest movable ancestor h at the constant
/// placement hT_f, so a_f = V̇_h + ẇ_h x P + w_h x (w_h x P) + g, P = hP_f, and the
/// placement is the product of the pass's iT_j. With a moving base (`env.base`) the motion is
/// relative to R_0's origin as the pass makes it. Allocation-free; O(depth).
///
/// Errors: [`Error::Dimension`](crate::Error::Dimension) for a `data` of another robot,
/// [`Error::Input`](crate::Error::Input) for a frame of another robot.
pub fn frame_motion_from_newton_euler(
    robot: &Robot,
    data: &Data,
    env: &Environment,
    f: &FrameId,
) -> Result<NewtonEulerFrame> {
    robot.require_fixed_base("frame_motion_from_newton_euler")?;
    data.check(robot)?;
    f.check(robot)?;
    // the frame's nearest movable joint k (its link in the pass) and kT_f
    let anchor = anchor_of(robot, f.parent());
    let (k, h_t_f) = (anchor.link, anchor.t.compose(f.offset()));
    let (rots, poss) = data.local_placements();
    let dynamic = robot.dynamic();
    // 0T_h: the product of the pass's iT_j from the base
    let (mut rot, mut pos) = (Matrix3::identity(), Vector3::zeros());
    let mut i = k;
    while i != 0 {
        pos = rots[i] * pos + poss[i];
        rot = rots[i] * rot;
        i = dynamic.frame(i).ant;
    }
    let t_h = Transform { rot, pos };
    let p = h_t_f.pos;
    let (w, wd) = (
        data.angular_velocities()[k],
        data.angular_accelerations()[k],
    );
    let a = data.linear_accelerations()[k] + wd.cross(&p) + w.cross(&w.cross(&p));
    Ok(NewtonEulerFrame {
        placement: t_h.compose(&h_t_f),
        angular_velocity: rot * w,
        angular_acceleration: rot * wd,
        linear_acceleration: rot * a + env.gravity,
    })
}
