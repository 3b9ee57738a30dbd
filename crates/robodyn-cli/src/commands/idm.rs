//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state, every row on the assembly branch
//! (the library's branch tracker: each row continued from the previous one, the first from the
//! robot's `assembly` or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{CliResult, RobotArgs};
use crate::rows::{evaluate, EvaluationArgs};
use robodyn::{closed_inverse_dynamics_into, inverse_dynamics_batch};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// CSV of states with columns q<j>, qd<j>, qdd<j> for the movable joints (closed chains:
    /// the actuated joints).
    #[arg(long, conflicts_with_all = ["q", "qd", "qdd"])]
    pub input: Option<PathBuf>,
    /// One state: joint positions, comma separated (movable joints in frame order; closed
    /// chains: the actuated joints).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Joint velocities (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
    /// Joint accelerations (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qdd: Option<String>,
    #[command(flatten)]
    pub eval: EvaluationArgs,
}

pub fn run(a: Args) -> CliResult {
    evaluate(
        &a.robot,
        &a.eval,
        a.input.as_deref(),
        ["q", "qd", "qdd"],
        [a.q.as_deref(), a.qd.as_deref(), a.qdd.as_deref()],
        "tau",
        // chunks of the table at once over the cores (the library's batch; errors name their row)
        &mut |r, c, tau| inverse_dynamics_batch(r, r.environment(), &c.x[0], &c.x[1], &c.x[2], tau),
        // closed chains: every row on the branch tracker (continued from the previous row)
        &mut |chain, b, d, x, tau| {
            closed_inverse_dynamics_into(
                chain,
                d,
                b,
                chain.robot().environment(),
                x[0],
                x[1],
                x[2],
                tau,
            )
        },
    )
}
