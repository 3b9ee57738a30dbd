//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state, every row on the assembly branch
//! (the library's branch tracker: each row continued from the previous one, the first from the
//! robot's `assembly` or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{
    conditioning_json, read_joint_states, result_rows, start_branch, state_column,
    warn_conditioning, CliResult, NamesArg, Phases, RobotArgs, TableOutput, TimingsArg,
};
use robodyn::{closed_inverse_dynamics_into, inverse_dynamics_batch, ClosedChain, ClosedData};
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
    #[command(flatten)]
    pub names: NamesArg,
    /// Closed chains: start the assembly branch at the first state's q_a with this guess of q_p
    /// (passive tree joints in order) instead of the robot's `assembly`.
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
    #[command(flatten)]
    pub timings: TimingsArg,
}

pub fn run(a: Args) -> CliResult {
    let mut t = Phases::start(a.timings);
    let robot = a.robot.load()?;
    t.lap("robot");
    if !robot.is_tree() {
        return run_closed(a, robot, t);
    }
    let coords = robot.coordinates();
    let (states, carried) = read_joint_states(
        a.input.as_deref(),
        ["q", "qd", "qdd"],
        [a.q.as_deref(), a.qd.as_deref(), a.qdd.as_deref()],
        coords,
        a.names,
        "movable joints",
    )?;
    t.lap("read");
    // every row at once over the cores (the library's batch; errors name their row)
    let (n, col) = (coords.len(), |i| state_column(&states, i));
    let mut tau = vec![0.0; states.len() * n];
    let env = robot.environment();
    inverse_dynamics_batch(&robot, env, &col(0), &col(1), &col(2), &mut tau)?;
    t.lap("model");
    let rows = result_rows(&tau, n, states.len());
    let (headers, rows) = carried.prepend(&a.names.columns("tau", coords), rows);
    a.out.write(&headers, &rows)?;
    t.lap("write");
    t.report(states.len());
    Ok(())
}

/// Closed chains: columns of the actuated joints in, tau<j> of the actuated joints out, every
/// row on the branch tracker (library: continuation from the previous row).
fn run_closed(a: Args, robot: robodyn::Robot, mut t: Phases) -> CliResult {
    let chain = ClosedChain::new(&robot)?;
    let coords = chain.coordinates();
    let (states, carried) = read_joint_states(
        a.input.as_deref(),
        ["q", "qd", "qdd"],
        [a.q.as_deref(), a.qd.as_deref(), a.qdd.as_deref()],
        coords,
        a.names,
        "actuated joints (closed chain)",
    )?;
    t.lap("read");
    let Some(first) = states.first() else {
        let (headers, _) = carried.prepend(&a.names.columns("tau", coords), vec![]);
        return a.out.write(&headers, &[]);
    };
    let mut branch = start_branch(&chain, &first[0], a.guess.as_deref())?;
    let mut data = ClosedData::new(&chain);
    let env = robot.environment();
    let (mut rows, mut extra) = (Vec::new(), Vec::new());
    for (k, [q, qd, qdd]) in states.iter().enumerate() {
        let mut tau = vec![0.0; coords.len()];
        let c =
            closed_inverse_dynamics_into(&chain, &mut data, &mut branch, env, q, qd, qdd, &mut tau)
                .map_err(|e| e.in_row(k + 1))?;
        warn_conditioning(&chain, k + 1, states.len(), &c);
        rows.push(tau);
        extra.push(conditioning_json(&c));
    }
    t.lap("model");
    let (headers, rows) = carried.prepend(&a.names.columns("tau", coords), rows);
    a.out.write_with(&headers, &rows, &extra)?;
    t.lap("write");
    t.report(states.len());
    Ok(())
}
