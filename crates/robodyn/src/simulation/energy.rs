//! Total energy of a tree robot for the simulation output, computed the simplest way (kept
//! independent of the Lagrangian-route module `algorithms::energy`):
//! - kinetic T = 1/2 qd' A(q) qd with A from composite links; A includes the rotor inertias on
//!   its diagonal, so the rotor kinetic energy is counted as 1/2 Ia_j qd_j^2;
//! - potential U = -sum_j g_eff' (M_j 0P_j + 0A_j jMS_j) from `geometry::frame_transforms`, with
//!   g_eff = g - VP0 (a base translating with constant acceleration VP0 adds a uniform inertial
//!   field). The base is assumed not to rotate (W0 = WP0 = 0) for T + U to be conserved.

use crate::algorithms::inertia_matrix::{inertia_matrix_into, InertiaWorkspace};
use crate::geometry::frame_transforms;
use crate::model::Robot;
use nalgebra::{DMatrix, Vector3};

/// Buffers for the energy (A(q)).
#[derive(Clone, Debug)]
pub struct EnergyWorkspace {
    inertia: InertiaWorkspace<f64>,
    a: DMatrix<f64>,
}

impl EnergyWorkspace {
    pub fn new(robot: &Robot) -> Self {
        let model = robot.numeric();
        EnergyWorkspace {
            inertia: InertiaWorkspace::new(model),
            a: DMatrix::zeros(model.nl, model.nl),
        }
    }
}

/// T = 1/2 qd' A(q) qd (NL-sized q, qd; entries of fixed frames ignored).
pub fn kinetic_energy(robot: &Robot, ws: &mut EnergyWorkspace, q: &[f64], qd: &[f64]) -> f64 {
    let model = robot.numeric();
    inertia_matrix_into(model, &mut ws.inertia, q, &mut ws.a);
    let n = model.nl;
    let mut t = 0.0;
    for i in 0..n {
        for j in 0..n {
            // rows/columns of fixed frames are zero in A
            t += qd[i] * ws.a[(i, j)] * qd[j];
        }
    }
    0.5 * t
}

/// U = -sum_j g_eff' (M_j 0P_j + 0A_j jMS_j), g_eff = g - VP0.
pub fn potential_energy(robot: &Robot, q: &[f64]) -> f64 {
    let model = robot.numeric();
    let g: Vector3<f64> = model.gravity - model.vp0;
    let t = frame_transforms(robot, q);
    (1..=model.nl)
        .map(|j| {
            let l = model.link(j);
            let tj = &t[j - 1];
            -g.dot(&(tj.pos * l.mass + tj.rot * l.ms))
        })
        .sum()
}

/// T + U.
pub fn total_energy(robot: &Robot, ws: &mut EnergyWorkspace, q: &[f64], qd: &[f64]) -> f64 {
    kinetic_energy(robot, ws, q, qd) + potential_energy(robot, q)
}
