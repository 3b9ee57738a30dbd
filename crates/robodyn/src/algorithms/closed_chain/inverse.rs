//! The closed-chain inverse dynamic model (§10.3.2): Γ_cl = G^T Γ_tr (10.40), the Lagrange
//! multipliers λ = -Wp^-T Γ_p (10.37) and Γ_cl = Γ_a + Wa^T λ (10.36, upper part).

use super::{Branch, ClosedChain, ClosedData, ClosedState, Conditioning};
use crate::algorithms::inverse_dynamics::rnea_with_environment;
use crate::error::Result;
use crate::model::Environment;
use nalgebra::DVector;

/// Result of the closed-chain inverse dynamic model.
#[derive(Clone, Debug, PartialEq)]
pub struct ClosedIdm {
    /// Γ_cl (N), actuated order: G^T Γ_tr (10.40).
    pub gamma_cl: DVector<f64>,
    /// Γ_tr (movable joints of the tree) at the consistent state.
    pub gamma_tr: DVector<f64>,
    /// Lagrange multipliers λ = -Wp^-T Γ_p (10.37): the cut-joint reactions along the kept
    /// closure equations.
    pub lambda: DVector<f64>,
    /// Γ_cl by the multiplier form Γ_a + Wa^T λ (10.36).
    pub gamma_cl_lagrange: DVector<f64>,
    /// The consistent state.
    pub state: ClosedState,
}

/// Closed-chain inverse dynamic model into `tau_a`: Γ_cl = G^T Γ_tr (10.40, N m or N) of the
/// actuated joints for q_a, qd_a, qdd_a (actuated joints) under `env`, on the tracker's branch.
/// Allocation-free on the branch. Returns the conditioning of Wp (check `warning`).
///
/// # Example
///
/// Torques of the Acma SR400 (a parallelogram loop, Example 10.1) along a trajectory, with the
/// buffers and the branch tracker made once:
///
/// ```
/// use robodyn::{closed_inverse_dynamics_into, ClosedChain, ClosedData};
/// # fn main() -> robodyn::Result<()> {
/// let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
/// let sr400 = robodyn::io::load(path)?;
/// let chain = ClosedChain::new(&sr400)?; // vectors over the actuated joints 1, 2, 4, 5, 6, 7
/// let mut data = ClosedData::new(&chain);
/// let mut branch = chain.assembly_branch()?; // the parallelogram assembly of the file
/// let mut gamma = vec![0.0; chain.dof()];
/// for k in 0..100 {
///     let s = k as f64 * 0.01;
///     let q_a = [0.1 + s, 0.2 - s, 0.3, 0.4, 0.5 + s, 1.6];
///     let cond = closed_inverse_dynamics_into(
///         &chain, &mut data, &mut branch, sr400.environment(),
///         &q_a, &[0.1; 6], &[0.0; 6], &mut gamma,
///     )?;
///     assert!(!cond.warning, "near a singular configuration: {cond:?}");
/// }
/// # Ok(())
/// # }
/// ```
#[allow(clippy::too_many_arguments)]
pub fn closed_inverse_dynamics_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    env: &Environment,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
    tau_a: &mut [f64],
) -> Result<Conditioning> {
    env.check(chain.robot().nl())?;
    chain
        .coords
        .check_output("tau_a", tau_a, "actuated joints")?;
    chain.state_into(
        data,
        branch,
        [("q_a", q_a), ("qd_a", qd_a), ("qdd_a", qdd_a)],
    )?;
    let d = data;
    rnea_with_environment(
        chain.robot().numeric(),
        &mut d.tree,
        env,
        &d.q_tr,
        &d.qd_tr,
        &d.qdd_tr,
        &mut d.tau_tr,
    );
    ClosedChain::project(d, &d.tau_tr, tau_a);
    Ok(chain.conditioning(branch, None))
}

/// Closed-chain inverse dynamic model with the robot's environment: Γ_cl, Γ_tr, the Lagrange
/// multipliers (10.37) and the consistent state. Allocates.
pub fn closed_inverse_dynamics(
    chain: &ClosedChain,
    branch: &mut Branch,
    q_a: &[f64],
    qd_a: &[f64],
    qdd_a: &[f64],
) -> Result<ClosedIdm> {
    let mut d = ClosedData::new(chain);
    let mut gamma_cl = DVector::zeros(chain.dof());
    let cond = closed_inverse_dynamics_into(
        chain,
        &mut d,
        branch,
        chain.robot().environment(),
        q_a,
        qd_a,
        qdd_a,
        gamma_cl.as_mut_slice(),
    )?;
    let lc = &chain.closure;
    let gp: Vec<f64> = lc
        .passive_joints()
        .iter()
        .map(|&j| d.tau_tr[j - 1])
        .collect();
    // (10.37): Wp^T λ = -Γ_p
    let mut lambda: Vec<f64> = gp.iter().map(|x| -x).collect();
    d.lu.solve_transpose(&mut lambda);
    let lambda = DVector::from_vec(lambda);
    let state = chain.state_result(&d, branch, cond);
    let ga = DVector::from_iterator(
        chain.dof(),
        lc.actuated_joints().iter().map(|&j| d.tau_tr[j - 1]),
    );
    let gamma_cl_lagrange = ga + state.wa.transpose() * &lambda;
    Ok(ClosedIdm {
        gamma_cl,
        gamma_tr: chain.tree_vector(&d.tau_tr),
        lambda,
        gamma_cl_lagrange,
        state,
    })
}
