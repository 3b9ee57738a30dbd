//! Total energy of a tree robot for the simulation output, computed the simplest way (kept
//! independent of the Lagrangian-route module `algorithms::energy`):
//! - kinetic T = 1/2 qd' A(q) qd with A from composite links; A includes the rotor inertias on
//!   its diagonal, so the rotor kinetic energy is counted as 1/2 Ia_j qd_j^2;
//! - potential U = -sum_j g_eff' (M_j 0P_j + 0A_j jMS_j) from `geometry::frame_transforms`, with
//!   g_eff = g - VP0 (a base translating with constant acceleration VP0 adds a uniform inertial
//!   field). The base is assumed not to rotate (W0 = WP0 = 0) for T + U to be conserved.

use crate::algorithms::inertia_matrix::inertia_matrix_into;
use crate::data::Data;
use crate::error::Result;
use crate::geometry::frame_transforms;
use crate::model::Robot;
use nalgebra::{DMatrix, Vector3};

/// T = 1/2 qd' A(q) qd (movable joints).
fn kinetic(robot: &Robot, ws: &mut Data, q: &[f64], qd: &[f64]) -> Result<f64> {
    let n = robot.dof();
    let mut a = DMatrix::zeros(n, n);
    inertia_matrix_into(robot, ws, q, &mut a)?;
    let mut t = 0.0;
    for i in 0..n {
        for j in 0..n {
            t += qd[i] * a[(i, j)] * qd[j];
        }
    }
    Ok(0.5 * t)
}

/// U = -sum_j g_eff' (M_j 0P_j + 0A_j jMS_j), g_eff = g - VP0 (movable joints q).
fn potential(robot: &Robot, q: &[f64]) -> Result<f64> {
    let model = robot.numeric();
    let env = robot.environment();
    let g: Vector3<f64> = env.gravity - env.base.vp0;
    let t = frame_transforms(robot, q)?;
    Ok((1..=robot.nl())
        .map(|j| {
            let l = model.link(j);
            let tj = &t[j - 1];
            -g.dot(&(tj.pos * l.mass + tj.rot * l.ms))
        })
        .sum())
}

/// T + U of the simulation output (movable joints q, qd), on the checked path.
pub(crate) fn mechanical_energy(
    robot: &Robot,
    ws: &mut Data,
    q: &[f64],
    qd: &[f64],
) -> Result<f64> {
    Ok(kinetic(robot, ws, q, qd)? + potential(robot, q)?)
}
