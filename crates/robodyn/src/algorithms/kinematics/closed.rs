//! Frame Jacobians of a closed chain in its actuated coordinates, J_a = J_tr G, on the tracked
//! branch (G = d q_tr / d q_a of eq 10.40, W = d q_p / d q_a of eq 10.30), and their drift
//! J̇_a q̇_a = J_tr Ġ q̇_a + J̇_tr q̇_tr.

use super::forward::{forward_kinematics_into, placements_into, KinematicsData};
use super::frames::FrameId;
use super::jacobian::{frame_jacobian_into, frame_jacobian_time_variation_into};
use super::{Motion, Reference};
use crate::algorithms::closed_chain::{closed_state, Branch, ClosedChain, ClosedState};
use crate::error::Result;
use nalgebra::{DMatrix, DVector, Vector3};

/// The Jacobian of a frame of a closed chain at a closed configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedJacobian {
    /// J_a = J_tr G (6 x N over the actuated joints): the frame's velocity in the reference is
    /// J_a q̇_a on the closure manifold.
    pub j_a: DMatrix<f64>,
    /// J_tr (6 x movable joints of the equivalent tree) at q_tr.
    pub j_tree: DMatrix<f64>,
    /// The closed configuration with G (movable tree joints x N) and W (p x N).
    pub state: ClosedState,
}

/// The Jacobian of frame `f` of the equivalent tree of `chain` in `reference`, in the actuated
/// coordinates: J_a = J_tr(q_tr) G, with q_tr closed on the tracker's branch at `q_a` (the
/// branch moves there, as every closed-chain evaluation). Allocates.
///
/// G and W come from [`closed_state`] (the closed chain's public API: loop closure on the
/// branch, W = -Wp^-1 Wa, G = [I; W] in the tree's joint order); J_tr is
/// [`frame_jacobian_into`] at q_tr.
///
/// Errors: those of [`closed_state`] (a bad `q_a`, a lost branch, a singular Wp) and of
/// [`frame_jacobian_into`] (a frame of another robot).
///
/// # Example
///
/// ```
/// use robodyn::algorithms::kinematics::closed_frame_jacobian;
/// use robodyn::{ClosedChain, Reference};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
/// let sr400 = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&sr400)?;
/// let mut branch = chain.assembly_branch()?;
/// let wrist = sr400.frame_id_of(7)?;
/// let q_a = [0.1, 0.2, 0.3, 0.4, 0.5, 1.6];
/// let j = closed_frame_jacobian(&chain, &mut branch, &q_a, &wrist, Reference::LocalWorldAligned)?;
/// assert_eq!(j.j_a.shape(), (6, 6));
/// # Ok(())
/// # }
/// ```
pub fn closed_frame_jacobian(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    f: &FrameId,
    reference: Reference,
) -> Result<ClosedJacobian> {
    let robot = chain.robot();
    let zeros = vec![0.0; chain.dof()];
    let state = closed_state(chain, branch, q_a, &zeros, &zeros)?;
    let mut data = KinematicsData::new(robot);
    placements_into(robot, &mut data, state.q.as_slice())?;
    let mut j_tree = DMatrix::zeros(6, robot.dof());
    frame_jacobian_into(robot, &data, f, reference, &mut j_tree)?;
    let j_a = &j_tree * &state.g;
    Ok(ClosedJacobian { j_a, j_tree, state })
}

/// The Jacobian of a frame of a closed chain and its drift at a closed state (q_a, q̇_a).
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedDrift {
    /// J_a, J_tr and the closed state (q_tr, q̇_tr = G q̇_a, q̈_tr = Ġ q̇_a, G, W), as
    /// [`closed_frame_jacobian`] gives them.
    pub jacobian: ClosedJacobian,
    /// J̇_a q̇_a = J_tr Ġ q̇_a + J̇_tr q̇_tr in the reference: on the closure manifold the
    /// derivative of the frame's velocity J_a q̇_a is J_a q̈_a + J̇_a q̇_a (as for a tree: the
    /// classical acceleration of the origin and ẇ in `LocalWorldAligned`, Khalil's 0V̇_n,
    /// 0ẇ_n; [`frame_acceleration`](super::frame_acceleration) in `World` and `Local`).
    pub drift: Motion,
}

/// The drift J̇_a q̇_a of frame `f` of the equivalent tree of `chain` in `reference`, in the
/// actuated coordinates, with its Jacobian J_a: the loops closed at `q_a` on the tracker's
/// branch (the branch moves there), q̇_tr = G q̇_a, and Ġ q̇_a the tree's joint accelerations
/// at q̈_a = 0 (q̈_p = -Wp^-1 Ψ of eq 10.42, from [`closed_state`]); then
///
/// J̇_a q̇_a = d(J_tr G)/dt q̇_a = J_tr (Ġ q̇_a) + J̇_tr q̇_tr,
///
/// with J̇_tr of [`frame_jacobian_time_variation_into`] at (q_tr, q̇_tr). Allocates.
///
/// Errors: those of [`closed_frame_jacobian`], and [`Error::Dimension`](crate::Error::Dimension)
/// / [`Error::NotFinite`](crate::Error::NotFinite) for a bad `qd_a`.
///
/// # Example
///
/// ```
/// use robodyn::algorithms::kinematics::closed_frame_drift;
/// use robodyn::{ClosedChain, Reference};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/fivebar.toml");
/// let fivebar = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&fivebar)?;
/// let mut branch = chain.assembly_branch()?;
/// let tip = fivebar.frame_id_of(2)?;
/// let d = closed_frame_drift(&chain, &mut branch, &[0.1, -0.15], &[1.0, 0.5], &tip,
///                            Reference::LocalWorldAligned)?;
/// // the frame's acceleration for q̈_a: J_a q̈_a + J̇_a q̇_a
/// let qdd_a = nalgebra::DVector::from_vec(vec![0.2, -0.3]);
/// let acc = &d.jacobian.j_a * qdd_a + d.drift.to_vector();
/// assert!(acc.iter().all(|x| x.is_finite()));
/// # Ok(())
/// # }
/// ```
pub fn closed_frame_drift(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    f: &FrameId,
    reference: Reference,
) -> Result<ClosedDrift> {
    let robot = chain.robot();
    let zeros = vec![0.0; chain.dof()];
    let state = closed_state(chain, branch, q_a, qd_a, &zeros)?;
    let mut data = KinematicsData::new(robot);
    let qdd_zero = vec![0.0; robot.dof()];
    let (q, qd) = (state.q.as_slice(), state.qd.as_slice());
    forward_kinematics_into(robot, &mut data, q, qd, &qdd_zero)?;
    let mut j_tree = DMatrix::zeros(6, robot.dof());
    frame_jacobian_into(robot, &data, f, reference, &mut j_tree)?;
    let mut jd_tree = DMatrix::zeros(6, robot.dof());
    frame_jacobian_time_variation_into(robot, &data, f, reference, &mut jd_tree)?;
    // state.qdd is Ġ q̇_a (q̈_a = 0)
    let d: DVector<f64> = &j_tree * &state.qdd + &jd_tree * &state.qd;
    let drift = Motion::new(
        Vector3::new(d[0], d[1], d[2]),
        Vector3::new(d[3], d[4], d[5]),
    );
    let j_a = &j_tree * &state.g;
    Ok(ClosedDrift {
        jacobian: ClosedJacobian { j_a, j_tree, state },
        drift,
    })
}
