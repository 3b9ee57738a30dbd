//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state (q_p solved by loop closure, each row
//! continued from the previous row's solution; the first from `--guess`, else as `closure` does).

use crate::common::{
    closed_chain_rows, read_joint_states, scatter, CliResult, RobotArgs, TableOutput,
};
use robodyn::algorithms::inverse_dynamics::{check_state, rnea};
use robodyn::Workspace;
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
    pub out: TableOutput,
    /// Closed chains: initial guess of q_p for the first state (passive tree joints in order).
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    if !robot.is_tree() {
        return run_closed(a, robot);
    }
    let joints = robot.movable_joints();
    let nl = robot.nl();
    let states = read_joint_states(
        a.input.as_deref(),
        ["q", "qd", "qdd"],
        [a.q.as_deref(), a.qd.as_deref(), a.qdd.as_deref()],
        &joints,
        "movable tree joints",
    )?;
    let model = robot.numeric();
    let mut ws = Workspace::new(model);
    let mut tau = vec![0.0; nl];
    let mut rows = Vec::with_capacity(states.len());
    for (_, [q, qd, qdd]) in &states {
        let [q, qd, qdd] = [q, qd, qdd].map(|v| scatter(&joints, nl, v));
        check_state(&robot, "q", &q)?;
        rnea(model, &mut ws, &q, &qd, &qdd, &mut tau);
        rows.push(joints.iter().map(|j| tau[j - 1]).collect());
    }
    let headers: Vec<String> = joints.iter().map(|j| format!("tau{j}")).collect();
    a.out.write(&headers, &rows)
}

/// Closed chains: columns of the actuated joints in, tau<j> of the actuated joints out.
fn run_closed(a: Args, robot: robodyn::Robot) -> CliResult {
    use robodyn::algorithms::closed_chain::ClosedChain;
    let cc = ClosedChain::new(&robot)?;
    let joints = cc.actuated_joints().to_vec();
    let states = read_joint_states(
        a.input.as_deref(),
        ["q", "qd", "qdd"],
        [a.q.as_deref(), a.qd.as_deref(), a.qdd.as_deref()],
        &joints,
        "actuated joints (closed chain)",
    )?;
    let rows = closed_chain_rows(&cc, &states, a.guess.as_deref(), |ws, q, x, y, q_p| {
        let r = cc.inverse_dynamics(ws, q, x, y, Some(q_p))?;
        Ok(r.gamma_cl.iter().copied().collect())
    })?;
    let headers: Vec<String> = joints.iter().map(|j| format!("tau{j}")).collect();
    a.out.write(&headers, &rows)
}
