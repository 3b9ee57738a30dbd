//! `robodyn ddm ROBOT`: direct dynamic model qdd = f(q, qd, tau) for states from a CSV file
//! (columns q<j>, qd<j>, tau<j>) or from `--q/--qd/--tau`.
//!
//! For a closed-chain robot the states, torques and accelerations are those of the actuated
//! joints only: qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.46–10.48) at the consistent tree state, every
//! row on the assembly branch (the library's branch tracker, started at the robot's `assembly`
//! or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{choices, CliResult, RobotArgs};
use crate::derivatives::{ClosedModel, Names};
use crate::rows::{evaluate, EvaluationArgs};
use robodyn::{
    closed_direct_dynamics_derivatives_into, closed_direct_dynamics_into, direct_dynamics_batch,
    direct_dynamics_derivatives, ClosedDdmDerivatives, Method, Robot,
};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// CSV of states with columns q<j>, qd<j>, tau<j> for the movable joints (closed chains:
    /// the actuated joints).
    #[arg(long, conflicts_with_all = ["q", "qd", "tau"])]
    pub input: Option<PathBuf>,
    /// One state: joint positions, comma separated (movable joints in frame order; closed
    /// chains: the actuated joints).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Joint velocities (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
    /// Joint torques (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub tau: Option<String>,
    /// Direct model of a tree robot (closed chains always use A_cl, H_cl of 10.46-10.48).
    #[arg(long, default_value = "composite", value_parser = choices(&Method::ALL, Method::name, Method::describe))]
    pub method: Method,
    /// Instead of the accelerations, write the derivatives of the model at the one state of
    /// --q/--qd/--tau: dqdd_dq, dqdd_dqd and Ainv = dqdd/dtau (N x N over the movable joints;
    /// row j is the derivative of qdd_j; closed chains: over the actuated joints, the loops kept
    /// closed on the branch, Ainv = A_cl^-1). csv: columns matrix, joint, then one per joint;
    /// json: {"joints", "q", "qd", "tau", "qdd", "dqdd_dq", "dqdd_dqd", "Ainv"} (closed chains:
    /// and "rcond_wp", "rcond_a_cl", "singularity_warning").
    #[arg(long, conflicts_with_all = ["input", "carry"])]
    pub derivatives: bool,
    #[command(flatten)]
    pub eval: EvaluationArgs,
}

pub fn run(a: Args) -> CliResult {
    if a.derivatives {
        return derivatives(&a);
    }
    let method = a.method;
    evaluate(
        &a.robot,
        &a.eval,
        a.input.as_deref(),
        ["q", "qd", "tau"],
        [a.q.as_deref(), a.qd.as_deref(), a.tau.as_deref()],
        "qdd",
        // chunks of the table at once over the cores (the library's batch; errors name their row)
        &mut |r, c, qdd| {
            direct_dynamics_batch(r, r.environment(), &c.x[0], &c.x[1], &c.x[2], method, qdd)
        },
        // closed chains: every row on the branch tracker (continued from the previous row); A_cl,
        // H_cl of 10.46-10.48, not --method
        &mut |chain, b, d, x, qdd| {
            closed_direct_dynamics_into(
                chain,
                d,
                b,
                chain.robot().environment(),
                x[0],
                x[1],
                x[2],
                qdd,
            )
        },
    )
}

/// `ddm --derivatives`: the three matrices at one state, in the table format of `--format`
/// (a closed chain's over its actuated joints, on the branch of `--guess` or the assembly).
fn derivatives(a: &Args) -> CliResult {
    let robot = a.robot.load()?;
    let names = Names {
        inputs: ["q", "qd", "tau"],
        value: "qdd",
        matrices: ["dqdd_dq", "dqdd_dqd", "Ainv"],
    };
    let tree = |r: &Robot, x: [&[f64]; 3]| {
        let d = direct_dynamics_derivatives(r, x[0], x[1], x[2])?;
        Ok((d.qdd, [d.dqdd_dq, d.dqdd_dqd, d.ainv]))
    };
    let closed: &mut ClosedModel = &mut |chain, data, branch, env, x| {
        let mut d = ClosedDdmDerivatives::new(chain);
        let c = closed_direct_dynamics_derivatives_into(
            chain, data, branch, env, x[0], x[1], x[2], &mut d,
        )?;
        Ok(((d.qdd, [d.dqdd_dq, d.dqdd_dqd, d.ainv]), c))
    };
    let lists = [&a.q, &a.qd, &a.tau];
    crate::derivatives::run(&robot, &a.eval, lists, &names, tree, closed)
}
