//! Centroidal dynamics of a floating robot (docs/models/floating_base.md): the total mass, the
//! centre of mass, the centroidal momentum h_G (linear momentum, angular momentum about the
//! centre of mass, world components) and the centroidal momentum matrix A_G(q) with
//! h_G = A_G(q) v (Orin, Goswami and Lee 2013; Pinocchio's `ccrba` / `computeCentroidalMap`).
//!
//! Both read as three steps:
//! 1. the composite links give the momentum map about O_0 in R_0, A_0 = [A_bb | A_bj], the base
//!    rows of the inertia matrix (the momentum conjugate to the base twist);
//! 2. its base block holds the total mass M and the first moment MS = M c (c the centre of mass
//!    in R_0);
//! 3. the momentum is moved to the centre of mass and rotated to the world:
//!    `h_G = [R h_lin; R (h_ang - c x h_lin)]`, i.e. `A_G = [[R, 0], [-R [c]x, R]] A_0`.

use crate::algorithms::floating_base::{check_state, composite_blocks, dot, skew, v3};
use crate::data::Data;
use crate::error::{check_finite_matrix, Error, Result};
use crate::model::Robot;
use nalgebra::{DMatrix, Matrix3, Matrix6, Vector3, Vector6};

/// The centroidal quantities of a floating robot: mass, centre of mass and momentum.
#[derive(Clone, Debug, PartialEq)]
pub struct Centroidal {
    /// Total mass (kg), the base included.
    pub mass: f64,
    /// Centre of mass in the world frame (m).
    pub com: Vector3<f64>,
    /// Linear momentum (kg m/s), world components.
    pub linear: Vector3<f64>,
    /// Angular momentum about the centre of mass (kg m²/s), world components.
    pub angular: Vector3<f64>,
}

/// What steps 1–2 give (the base rows over the joints are in `data.base_rows`).
struct MomentumMap {
    /// The base block of A: the 6 x 6 composite inertia of the whole robot about O_0 in R_0.
    abb: Matrix6<f64>,
    /// wR_0.
    rot: Matrix3<f64>,
    /// Total mass.
    mass: f64,
    /// The centre of mass in R_0.
    c: Vector3<f64>,
}

/// Steps 1–2: the base block and base rows of A, wR_0, the total mass and the centre of mass
/// in R_0. `what` names the caller in errors.
fn momentum_map(
    robot: &Robot,
    data: &mut Data,
    q: &[f64],
    vs: &[(&str, &[f64])],
    what: &str,
) -> Result<MomentumMap> {
    if !robot.is_floating() {
        return Err(Error::Input(format!(
            "{what}: robot `{}` has a {} base; the centroidal momentum is that of a floating \
             base (nq = 7 + N, nv = 6 + N)",
            robot.name(),
            robot.base_kind().name()
        )));
    }
    let rot = check_state(robot, data, None, q, vs, ("v", robot.nv()))?;
    let abb = composite_blocks(robot, data, q);
    let mass = abb[(0, 0)];
    if mass.is_nan() || mass <= 0.0 {
        return Err(Error::Input(format!(
            "{what}: robot `{}` has no mass (total {mass} kg)",
            robot.name()
        )));
    }
    // skew(MS) sits at rows 3..6, columns 0..3 of the base block
    let c = Vector3::new(abb[(5, 1)], abb[(3, 2)], abb[(4, 0)]) / mass;
    Ok(MomentumMap { abb, rot, mass, c })
}

/// Mass, centre of mass and centroidal momentum (linear, and angular about the centre of mass,
/// Pinocchio's `computeCentroidalMomentum` hg, world components) of a floating robot at q (nq),
/// v (nv). The spatial momentum about O_0 in R_0 is the base rows of A times v (the momentum
/// conjugate to the base twist), moved to the centre of mass and rotated to the world.
/// Allocation-free.
pub fn centroidal_momentum(
    robot: &Robot,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<Centroidal> {
    let MomentumMap { abb, rot, mass, c } =
        momentum_map(robot, data, q, &[("v", v)], "centroidal momentum")?;
    let n = robot.dof();
    let base = Vector6::from_column_slice(&v[..6]);
    let h = Vector6::from_fn(|r, _| {
        (abb.row(r) * base)[0] + dot(&data.base_rows[r * n..(r + 1) * n], &v[6..])
    });
    let (lin, ang) = (v3(&h.as_slice()[0..3]), v3(&h.as_slice()[3..6]));
    Ok(Centroidal {
        mass,
        com: v3(&q[0..3]) + rot * c,
        linear: rot * lin,
        angular: rot * (ang - c.cross(&lin)),
    })
}

/// The centroidal momentum matrix A_G(q) of a floating robot into `ag` (6 x nv): h_G = A_G v,
/// rows [linear momentum; angular momentum about the centre of mass] in world components, the
/// columns over v = [base linear, angular velocity in the base frame, joints] (Pinocchio's
/// `computeCentroidalMap`, `ccrba`'s `data.Ag`). Allocation-free.
pub fn centroidal_map_into(
    robot: &Robot,
    data: &mut Data,
    q: &[f64],
    ag: &mut DMatrix<f64>,
) -> Result<()> {
    let nv = robot.nv();
    if robot.is_floating() && ag.shape() != (6, nv) {
        return Err(Error::dimension(
            "A_G",
            6 * nv,
            ag.len(),
            format!("6 x {nv}: nv = 6 + {}", robot.dof()),
        ));
    }
    let MomentumMap { abb, rot, c, .. } = momentum_map(robot, data, q, &[], "centroidal map")?;
    // step 3: A_G = [[R, 0], [-R [c]x, R]] A_0, column by column
    let shift = -rot * skew(&c);
    let n = robot.dof();
    for k in 0..nv {
        let col = |r: usize| {
            if k < 6 {
                abb[(r, k)]
            } else {
                data.base_rows[r * n + k - 6]
            }
        };
        let lin = Vector3::new(col(0), col(1), col(2));
        let ang = Vector3::new(col(3), col(4), col(5));
        let (l, a) = (rot * lin, rot * ang + shift * lin);
        for r in 0..3 {
            ag[(r, k)] = l[r];
            ag[(3 + r, k)] = a[r];
        }
    }
    check_finite_matrix("A_G", ag)
}

/// [`centroidal_map_into`], allocating its buffers and result.
pub fn centroidal_map(robot: &Robot, q: &[f64]) -> Result<DMatrix<f64>> {
    let mut ag = DMatrix::zeros(6, robot.nv());
    centroidal_map_into(robot, &mut Data::new(robot), q, &mut ag)?;
    Ok(ag)
}
