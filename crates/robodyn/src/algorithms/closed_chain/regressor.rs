//! The closed-chain regressor (§10.3.2 with the tree's linear form): G^T Φ (10.40).

use super::{tr_mul_into, Branch, ClosedChain, ClosedData, Conditioning};
use crate::algorithms::regressor::{tree_regressor, tree_wrench_torques, PARAMS_PER_LINK};
use crate::error::{Error, Result};
use crate::model::Environment;
use nalgebra::DMatrix;

/// Regressor of the closed chain into `phi` (N x 13 NL): G^T Φ (10.40), so that
/// Γ_cl = G^T Φ K + Γ_e,cl, and Γ_e,cl = G^T Γ_e into `tau_e` (actuated joints), for q_a, qd_a,
/// qdd_a on the tracker's branch under `env`. Allocation-free on the branch.
#[allow(clippy::too_many_arguments)]
pub fn closed_regressor_into(
    chain: &ClosedChain,
    data: &mut ClosedData,
    branch: &mut Branch,
    env: &Environment,
    x: [&[f64]; 3],
    phi: &mut DMatrix<f64>,
    tau_e: &mut [f64],
) -> Result<Conditioning> {
    env.check(chain.robot().nl())?;
    let (n, nl) = (chain.dof(), chain.robot().nl());
    if phi.shape() != (n, PARAMS_PER_LINK * nl) {
        return Err(Error::dimension(
            "Phi",
            n * PARAMS_PER_LINK * nl,
            phi.len(),
            format!(
                "{n} x {} (actuated joints x 13 per link)",
                PARAMS_PER_LINK * nl
            ),
        ));
    }
    chain
        .coords
        .check_output("tau_e", tau_e, "actuated joints")?;
    chain.state_into(
        data,
        branch,
        [("q_a", x[0]), ("qd_a", x[1]), ("qdd_a", x[2])],
    )?;
    let d = data;
    let model = chain.robot().numeric();
    let mut full = std::mem::replace(&mut d.phi, DMatrix::zeros(0, 0));
    if full.shape() != (nl, PARAMS_PER_LINK * nl) {
        full = DMatrix::zeros(nl, PARAMS_PER_LINK * nl); // first call only
    }
    tree_regressor(
        model,
        &mut d.tree,
        env,
        &d.q_tr,
        &d.qd_tr,
        &d.qdd_tr,
        &mut full,
    );
    tr_mul_into(&d.g, &full, phi);
    d.phi = full;
    tree_wrench_torques(model, &mut d.tree, env, &d.q_tr, &mut d.tau_tr);
    ClosedChain::project(d, &d.tau_tr, tau_e);
    Ok(chain.conditioning(branch, None))
}
