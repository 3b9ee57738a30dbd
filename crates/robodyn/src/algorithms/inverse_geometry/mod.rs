//! Inverse geometric model (IGM: joint values for a placement of a frame) and inverse kinematic
//! model (IKM: joint velocities for a twist of a frame), Khalil & Dombre ch. 7 and 6.
//!
//! - [`closed_form`]: every solution by Paul's method for the 6R classes it handles
//!   ([`IgmClass`]), found from the robot's axes;
//! - [`numeric`]: one solution for any robot and frame, by damped least squares from several
//!   starts ([`NumericIgm`], [`numeric_igm_batch`]);
//! - [`ikm`]: joint velocities for a twist, damped near singularities ([`inverse_kinematics`]).
//!
//! The equations and the methods' parameters: docs/models/inverse_geometry.md.
//!
//! # Example
//!
//! ```
//! use robodyn::algorithms::inverse_geometry::{ClosedFormIgm, IgmClass};
//! # fn main() -> robodyn::Result<()> {
//! let robots = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots");
//! let rx90 = robodyn::io::load(format!("{robots}/rx90.toml"))?;
//! let igm = ClosedFormIgm::new(&rx90)?;
//! assert_eq!(igm.class(), IgmClass::SphericalWrist);
//! let q = [0.1, -0.5, 1.0, 0.3, 0.7, -0.2];
//! let target = robodyn::geometry::frame_transforms(&rx90, &q)?[igm.frame() - 1].matrix();
//! let solutions = igm.solve(&target)?;
//! assert_eq!(solutions.len(), 8);
//! assert!(solutions.as_slice().iter().any(|s| {
//!     s.q.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-9)
//! }));
//! # Ok(())
//! # }
//! ```

mod chain;
pub mod closed_form;
pub mod ikm;
pub mod numeric;

pub use closed_form::{
    ClosedFormIgm, IgmClass, IgmSolution, IgmSolutions, Singularity, CLOSED_FORM_TOLERANCE,
};

pub use ikm::{inverse_kinematics, IkmOptions, IkmSolution};
pub use numeric::{numeric_igm_batch, NumericIgm, NumericOptions, NumericSolution};

use crate::error::{Error, Result};
use crate::geometry::Transform;
use nalgebra::{Matrix4, Vector3};

/// Tolerance of the checks of a placement: |R^T R - I|, |det R - 1| and the last row.
pub const PLACEMENT_TOLERANCE: f64 = 1e-9;

/// The refusal of the inverse models (`what` names one) for a floating robot: its frames'
/// poses in the world depend on the base pose (7 of the nq coordinates), which no joint sets,
/// so a joint solution for a world target is undefined (or, solving for the base too, a
/// free-flying body reaching anything). The joints that place a frame relative to the base
/// are those of the same robot on a fixed base.
pub(crate) fn refuse_floating(robot: &crate::Robot, what: &str) -> Result<()> {
    if robot.is_floating() {
        return Err(Error::Input(format!(
            "{what}: robot `{}` has a floating base, whose pose no joint sets: a frame's world \
             pose is reached by moving the base alone, so the inverse models (which solve the \
             joints) are not defined for it; for a target given in the base frame, load the \
             robot with a fixed base",
            robot.name()
        )));
    }
    Ok(())
}

/// A 4x4 placement as a [`Transform`], checked: finite, rotation part orthonormal with
/// determinant 1, last row (0, 0, 0, 1), each within [`PLACEMENT_TOLERANCE`].
pub(crate) fn transform_of(what: &str, m: &Matrix4<f64>) -> Result<Transform> {
    check_target(what, m)?;
    Ok(Transform {
        rot: m.fixed_view::<3, 3>(0, 0).into_owned(),
        pos: m.fixed_view::<3, 1>(0, 3).into_owned(),
    })
}

/// The checks of [`transform_of`].
pub(crate) fn check_target(what: &str, m: &Matrix4<f64>) -> Result<()> {
    // column-major index k = row + 4 column, reported as [row, column]
    // the slice, not the matrix's strided iterator (a quarter of the closed form's bookkeeping)
    if let Some(k) = m.as_slice().iter().position(|x| !x.is_finite()) {
        return Err(Error::NotFinite {
            what: format!("{what}[{}, {}]", k % 4, k / 4),
            index: k,
            value: m[k],
        });
    }
    let row = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)]];
    let last = [row[0], row[1], row[2], row[3] - 1.0]
        .iter()
        .fold(0.0, |e: f64, x| e.max(x.abs()));
    if last > PLACEMENT_TOLERANCE {
        return Err(Error::Input(format!(
            "{what}: the last row of a 4x4 placement must be (0, 0, 0, 1), it is ({}, {}, {}, {})",
            row[0], row[1], row[2], row[3]
        )));
    }
    // R'R - I and det R from the columns (the closed form's bookkeeping: nalgebra's generic
    // product, amax and determinant were a tenth of its time)
    let col = |j: usize| Vector3::new(m[(0, j)], m[(1, j)], m[(2, j)]);
    let (a, b, c) = (col(0), col(1), col(2));
    let ortho = [
        a.dot(&a) - 1.0,
        b.dot(&b) - 1.0,
        c.dot(&c) - 1.0,
        a.dot(&b),
        a.dot(&c),
        b.dot(&c),
    ]
    .iter()
    .fold(0.0, |e: f64, x| e.max(x.abs()));
    let det = a.dot(&b.cross(&c));
    if ortho > PLACEMENT_TOLERANCE || (det - 1.0).abs() > PLACEMENT_TOLERANCE {
        return Err(Error::Input(format!(
            "{what}: the rotation part of a placement must be orthonormal with determinant 1 \
             (largest entry of R'R - I: {ortho:.3e}, det R = {det}, tolerance {PLACEMENT_TOLERANCE:.0e})"
        )));
    }
    Ok(())
}
