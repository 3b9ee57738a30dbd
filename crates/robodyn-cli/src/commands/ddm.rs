//! `robodyn ddm ROBOT`: direct dynamic model qdd = f(q, qd, tau) for states from a CSV file
//! (columns q<j>, qd<j>, tau<j>) or from `--q/--qd/--tau`.
//!
//! For a closed-chain robot the states, torques and accelerations are those of the actuated
//! joints only: qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.46–10.48) at the consistent tree state, every
//! row on the assembly branch (the library's branch tracker, started at the robot's `assembly`
//! or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{
    conditioning_json, read_joint_states, result_rows, start_branch, state_column,
    warn_conditioning, CliResult, NamesArg, Phases, RobotArgs, TableOutput, TimingsArg,
};
use robodyn::{
    closed_direct_dynamics_into, direct_dynamics_batch, ClosedChain, ClosedData, Method,
};
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
    /// Direct model of a tree robot (closed chains always use A_cl, H_cl of 10.46-10.48).
    #[arg(long, value_enum, default_value = "composite")]
    pub method: MethodArg,
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
        ["q", "qd", "tau"],
        [a.q.as_deref(), a.qd.as_deref(), a.tau.as_deref()],
        coords,
        a.names,
        "movable joints",
    )?;
    t.lap("read");
    // every row at once over the cores (the library's batch; errors name their row)
    let (n, col) = (coords.len(), |i| state_column(&states, i));
    let mut qdd = vec![0.0; states.len() * n];
    let env = robot.environment();
    let method = a.method.into();
    direct_dynamics_batch(&robot, env, &col(0), &col(1), &col(2), method, &mut qdd)?;
    t.lap("model");
    let rows = result_rows(&qdd, n, states.len());
    let (headers, rows) = carried.prepend(&a.names.columns("qdd", coords), rows);
    a.out.write(&headers, &rows)?;
    t.lap("write");
    t.report(states.len());
    Ok(())
}

/// Closed chains: columns q<j>, qd<j>, tau<j> of the actuated joints in, qdd<j> of the actuated
/// joints out (the `--method` is the closed-chain model's A_cl, H_cl), every row on the branch.
fn run_closed(a: Args, robot: robodyn::Robot, mut t: Phases) -> CliResult {
    let chain = ClosedChain::new(&robot)?;
    let coords = chain.coordinates();
    let (states, carried) = read_joint_states(
        a.input.as_deref(),
        ["q", "qd", "tau"],
        [a.q.as_deref(), a.qd.as_deref(), a.tau.as_deref()],
        coords,
        a.names,
        "actuated joints (closed chain)",
    )?;
    t.lap("read");
    let Some(first) = states.first() else {
        let (headers, _) = carried.prepend(&a.names.columns("qdd", coords), vec![]);
        return a.out.write(&headers, &[]);
    };
    let mut branch = start_branch(&chain, &first[0], a.guess.as_deref())?;
    let mut data = ClosedData::new(&chain);
    let env = robot.environment();
    let (mut rows, mut extra) = (Vec::new(), Vec::new());
    for (k, [q, qd, tau]) in states.iter().enumerate() {
        let mut qdd = vec![0.0; coords.len()];
        let c =
            closed_direct_dynamics_into(&chain, &mut data, &mut branch, env, q, qd, tau, &mut qdd)
                .map_err(|e| e.in_row(k + 1))?;
        warn_conditioning(&chain, k + 1, states.len(), &c);
        rows.push(qdd);
        extra.push(conditioning_json(&c));
    }
    t.lap("model");
    let (headers, rows) = carried.prepend(&a.names.columns("qdd", coords), rows);
    a.out.write_with(&headers, &rows, &extra)?;
    t.lap("write");
    t.report(states.len());
    Ok(())
}
