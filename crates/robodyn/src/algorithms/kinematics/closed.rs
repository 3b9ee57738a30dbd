//! Frame Jacobians of a closed chain in its actuated coordinates, J_a = J_tr G, on the tracked
//! branch (G = d q_tr / d q_a of eq 10.40, W = d q_p / d q_a of eq 10.30).

use super::forward::{placements_into, KinematicsData};
use super::frames::FrameId;
use super::jacobian::frame_jacobian_into;
use super::Reference;
use crate::algorithms::closed_chain::{closed_state, Branch, ClosedChain, ClosedState};
use crate::error::Result;
use nalgebra::DMatrix;

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
