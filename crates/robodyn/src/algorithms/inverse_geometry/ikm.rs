//! Inverse kinematic model: joint velocities for a twist of a frame, by the damped
//! pseudo-inverse of the frame Jacobian (Khalil & Dombre ch. 6; damping after Nakamura and
//! Maciejewski).
//!
//! With J = U S V^T (SVD, singular values s_i) and s_min the smallest of the min(6, n):
//! qd = sum_i s_i / (s_i^2 + lambda^2) v_i (u_i . twist), lambda^2 = 0 when s_min >=
//! `threshold`, else lambda_max^2 (1 - (s_min / threshold)^2): the exact least-norm solution
//! away from singularities, bounded joint velocities near them.

use crate::algorithms::kinematics::{
    frame_jacobian_into, placements_into, FrameId, KinematicsData, Reference,
};
use crate::error::{check_finite_result, check_vector, Error, Result};
use crate::model::Robot;
use nalgebra::{DMatrix, DVector};

/// The damping of [`inverse_kinematics`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkmOptions {
    /// Smallest singular value below which damping acts. Default 1e-2.
    pub threshold: f64,
    /// The damping lambda at a singularity (s_min = 0). Default 1e-1.
    pub max_damping: f64,
}

impl Default for IkmOptions {
    fn default() -> Self {
        IkmOptions {
            threshold: 1e-2,
            max_damping: 1e-1,
        }
    }
}

/// Joint velocities and the conditioning of the Jacobian they came from.
#[derive(Clone, Debug, PartialEq)]
pub struct IkmSolution {
    /// Joint velocities (movable joints, frame order).
    pub qd: DVector<f64>,
    /// The smallest of the min(6, n) singular values of J.
    pub sigma_min: f64,
    /// s_max / s_min (infinite at a singularity).
    pub condition: f64,
    /// The damping lambda used (0: the exact least-norm solution).
    pub damping: f64,
}

/// The joint velocities giving frame `frame` the twist `twist` = [v; w] (rows [linear;
/// angular], in `reference`, as [`crate::algorithms::kinematics::frame_jacobian_into`]) at
/// joint positions `q`. Redundant robots get the least-norm solution; a robot of fewer than 6
/// joints the least-squares one.
///
/// Errors: [`Error::Dimension`], [`Error::NotFinite`] for `q` or `twist`; [`Error::Setting`]
/// for a non-positive threshold or a negative damping.
pub fn inverse_kinematics(
    robot: &Robot,
    q: &[f64],
    frame: &FrameId,
    reference: Reference,
    twist: &[f64],
    options: &IkmOptions,
) -> Result<IkmSolution> {
    if !(options.threshold > 0.0 && options.max_damping >= 0.0 && options.max_damping.is_finite()) {
        return Err(Error::Setting {
            option: "inverse_geometry::IkmOptions::threshold",
            reason: "the inverse kinematic model needs a positive threshold and a finite, \
                     non-negative damping"
                .into(),
        });
    }
    super::refuse_floating(robot, "the inverse kinematic model")?;
    check_vector("twist", twist, 6, || "[vx, vy, vz, wx, wy, wz]".into())?;
    let mut data = KinematicsData::new(robot);
    placements_into(robot, &mut data, q)?;
    let mut j = DMatrix::zeros(6, robot.dof());
    frame_jacobian_into(robot, &data, frame, reference, &mut j)?;
    let out = damped_solve(&j, twist, options);
    check_finite_result("qd", out.qd.as_slice())?;
    Ok(out)
}

/// The damped least-norm solution of J qd = twist (the module's rule).
fn damped_solve(j: &DMatrix<f64>, twist: &[f64], o: &IkmOptions) -> IkmSolution {
    let n = j.ncols();
    let svd = j.clone().svd(true, true);
    let (u, vt) = (svd.u.as_ref(), svd.v_t.as_ref());
    let s = &svd.singular_values;
    let k = s.len();
    let (s_max, s_min) = if k == 0 {
        (0.0, 0.0)
    } else {
        (s.max(), s.min())
    };
    let lambda2 = if s_min >= o.threshold {
        0.0
    } else {
        o.max_damping.powi(2) * (1.0 - (s_min / o.threshold).powi(2))
    };
    let mut qd = DVector::zeros(n);
    if let (Some(u), Some(vt)) = (u, vt) {
        let t = DVector::from_column_slice(twist);
        for i in 0..k {
            let den = s[i] * s[i] + lambda2;
            if den > 0.0 {
                let c = s[i] / den * u.column(i).dot(&t);
                qd += vt.row(i).transpose() * c;
            }
        }
    }
    IkmSolution {
        qd,
        sigma_min: s_min,
        condition: if s_min > 0.0 {
            s_max / s_min
        } else {
            f64::INFINITY
        },
        damping: lambda2.sqrt(),
    }
}
