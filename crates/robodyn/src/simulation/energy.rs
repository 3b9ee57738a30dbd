//! Total energy of a tree robot for the simulation output, computed the simplest way (kept
//! independent of the Lagrangian-route module `algorithms::energy`):
//! - kinetic T = 1/2 qd' A(q) qd with A from composite links; A includes the rotor inertias on
//!   its diagonal, so the rotor kinetic energy is counted as 1/2 Ia_j qd_j^2;
//! - potential U = -sum_j g_eff' (M_j 0P_j + 0A_j jMS_j) from `geometry::frame_transforms_per_frame`, with
//!   g_eff = g - VP0 (a base translating with constant acceleration VP0 adds a uniform inertial
//!   field). The base is assumed not to rotate (W0 = WP0 = 0) for T + U to be conserved.

use crate::algorithms::inertia_matrix::composite_inertia_matrix;
use crate::data::Data;
use crate::geometry::frame_transforms_per_frame;
use crate::model::Robot;
use nalgebra::{DMatrix, Vector3};

/// T = 1/2 qd' A(q) qd (tree arrays q, qd; entries of fixed frames ignored).
fn kinetic(robot: &Robot, ws: &mut Data, q: &[f64], qd: &[f64]) -> f64 {
    let model = robot.numeric();
    let mut a = std::mem::replace(&mut ws.a, DMatrix::zeros(0, 0));
    composite_inertia_matrix(model, ws, q, &mut a);
    let n = model.nl;
    let mut t = 0.0;
    for i in 0..n {
        for j in 0..n {
            // rows/columns of fixed frames are zero in A
            t += qd[i] * a[(i, j)] * qd[j];
        }
    }
    ws.a = a;
    0.5 * t
}

/// U = -sum_j g_eff' (M_j 0P_j + 0A_j jMS_j), g_eff = g - VP0.
fn potential(robot: &Robot, q: &[f64]) -> f64 {
    let model = robot.numeric();
    let env = &model.env;
    let g: Vector3<f64> = env.gravity - env.base.vp0;
    let t = frame_transforms_per_frame(robot, q);
    (1..=model.nl)
        .map(|j| {
            let l = model.link(j);
            let tj = &t[j - 1];
            -g.dot(&(tj.pos * l.mass + tj.rot * l.ms))
        })
        .sum()
}

/// T + U of the simulation output (tree arrays q, qd).
pub(crate) fn mechanical_energy(robot: &Robot, ws: &mut Data, q: &[f64], qd: &[f64]) -> f64 {
    kinetic(robot, ws, q, qd) + potential(robot, q)
}
