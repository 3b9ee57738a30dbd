//! `robodyn ddm ROBOT`: direct dynamic model qdd = f(q, qd, tau) for states from a CSV file
//! (columns q<j>, qd<j>, tau<j>) or from `--q/--qd/--tau`.
//!
//! For a closed-chain robot the states, torques and accelerations are those of the actuated
//! joints only: qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.46–10.48) at the consistent tree state (q_p by
//! loop closure, each row continued from the previous row's solution, the first from `--guess`,
//! else from the robot's assembly configuration as `closure` does).

use crate::common::{
    closed_chain_rows, read_joint_states, scatter, CliResult, RobotArgs, TableOutput,
};
use robodyn::algorithms::direct_dynamics::{ddm, DirectWorkspace, Method};
use robodyn::algorithms::inverse_dynamics::check_state;
use std::path::PathBuf;

/// Direct-dynamics algorithm.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodArg {
    /// qdd = A^-1 (tau - H), A by composite links, tree L'DL factorization.
    Composite,
    /// O(n) recursive Newton-Euler direct model (articulated bodies).
    Aba,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Composite => Method::Composite,
            MethodArg::Aba => Method::ArticulatedBody,
        }
    }
}

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
    #[arg(long, value_enum, default_value = "composite")]
    pub method: MethodArg,
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
        ["q", "qd", "tau"],
        [a.q.as_deref(), a.qd.as_deref(), a.tau.as_deref()],
        &joints,
        "movable tree joints",
    )?;
    let model = robot.numeric();
    let mut ws = DirectWorkspace::new(model);
    let mut qdd = vec![0.0; nl];
    let mut rows = Vec::with_capacity(states.len());
    for (what, [q, qd, tau]) in &states {
        let [q, qd, tau] = [q, qd, tau].map(|v| scatter(&joints, nl, v));
        check_state(&robot, "q", &q)?;
        ddm(model, &mut ws, a.method.into(), &q, &qd, &tau, &mut qdd)
            .map_err(|e| format!("{what}: {e}"))?;
        rows.push(joints.iter().map(|j| qdd[j - 1]).collect());
    }
    let headers: Vec<String> = joints.iter().map(|j| format!("qdd{j}")).collect();
    a.out.write(&headers, &rows)
}

/// Closed chains: columns q<j>, qd<j>, tau<j> of the actuated joints in, qdd<j> of the actuated
/// joints out (the `--method` is the closed-chain model's A_cl, H_cl).
fn run_closed(a: Args, robot: robodyn::Robot) -> CliResult {
    use robodyn::algorithms::closed_chain::ClosedChain;
    let cc = ClosedChain::new(&robot)?;
    let joints = cc.actuated_joints().to_vec();
    let states = read_joint_states(
        a.input.as_deref(),
        ["q", "qd", "tau"],
        [a.q.as_deref(), a.qd.as_deref(), a.tau.as_deref()],
        &joints,
        "actuated joints (closed chain)",
    )?;
    let rows = closed_chain_rows(&cc, &states, a.guess.as_deref(), |ws, q, x, y, q_p| {
        let r = cc.direct_dynamics(ws, q, x, y, Some(q_p))?;
        Ok(r.qdd_a.iter().copied().collect())
    })?;
    let headers: Vec<String> = joints.iter().map(|j| format!("qdd{j}")).collect();
    a.out.write(&headers, &rows)
}
