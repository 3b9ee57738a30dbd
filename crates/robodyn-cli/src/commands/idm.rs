//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state, every row on the assembly branch
//! (the library's branch tracker: each row continued from the previous one, the first from the
//! robot's `assembly` or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{CliResult, RobotArgs};
use crate::derivatives::{ClosedModel, Names};
use crate::rows::{evaluate, EvaluationArgs};
use robodyn::{
    closed_inverse_dynamics_derivatives_into, closed_inverse_dynamics_into, inverse_dynamics_batch,
    inverse_dynamics_derivatives, ClosedIdmDerivatives, Robot,
};
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
    /// Instead of the torques, write the derivatives of the model at the one state of
    /// --q/--qd/--qdd: dtau_dq, dtau_dqd and A = dtau/dqdd (N x N over the movable joints; row j
    /// is the derivative of tau_j; closed chains: over the actuated joints, the loops kept
    /// closed on the branch, A = A_cl). csv: columns matrix, joint, then one per joint;
    /// json: {"joints", "q", "qd", "qdd", "tau", "dtau_dq", "dtau_dqd", "A"} (closed chains:
    /// and "rcond_wp", "singularity_warning").
    #[arg(long, conflicts_with_all = ["input", "carry"])]
    pub derivatives: bool,
    #[command(flatten)]
    pub eval: EvaluationArgs,
}

pub fn run(a: Args) -> CliResult {
    if a.derivatives {
        return derivatives(&a);
    }
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

/// `idm --derivatives`: the three matrices at one state, in the table format of `--format`
/// (a closed chain's over its actuated joints, on the branch of `--guess` or the assembly).
fn derivatives(a: &Args) -> CliResult {
    let robot = a.robot.load()?;
    crate::common::refuse_motor_drives(&robot, &a.robot.robot, "idm --derivatives")?;
    let names = Names {
        inputs: ["q", "qd", "qdd"],
        value: "tau",
        matrices: ["dtau_dq", "dtau_dqd", "A"],
    };
    let tree = |r: &Robot, x: [&[f64]; 3]| {
        let d = inverse_dynamics_derivatives(r, x[0], x[1], x[2])?;
        Ok((d.tau, [d.dtau_dq, d.dtau_dqd, d.a]))
    };
    let closed: &mut ClosedModel = &mut |chain, data, branch, env, x| {
        let mut d = ClosedIdmDerivatives::new(chain);
        let c = closed_inverse_dynamics_derivatives_into(
            chain, data, branch, env, x[0], x[1], x[2], &mut d,
        )?;
        Ok(((d.tau, [d.dtau_dq, d.dtau_dqd, d.a]), c))
    };
    let lists = [&a.q, &a.qd, &a.qdd];
    crate::derivatives::run(&robot, &a.eval, lists, &names, tree, closed)
}
