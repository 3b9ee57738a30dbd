//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state, every row on the assembly branch
//! (the library's branch tracker: each row continued from the previous one, the first from the
//! robot's `assembly` or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{CliResult, NamesArg, Phases, RobotArgs, TableOutput, TimingsArg};
use crate::rows::{closed_rows, tree_rows};
use crate::states::{CarryArg, StateInput, StateRequest};
use robodyn::{closed_inverse_dynamics_into, inverse_dynamics_batch, ClosedChain};
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
    pub carry: CarryArg,
    #[command(flatten)]
    pub timings: TimingsArg,
}

impl Args {
    /// The states asked for, over `coords` (`what` names the joints in messages).
    fn states<'a>(
        &'a self,
        robot: &'a robodyn::Robot,
        coords: &'a robodyn::Coordinates,
        what: &'a str,
    ) -> StateRequest<'a> {
        StateRequest {
            tree: robot.coordinates(),
            input: self.input.as_deref(),
            prefixes: ["q", "qd", "qdd"],
            lists: [self.q.as_deref(), self.qd.as_deref(), self.qdd.as_deref()],
            coords,
            names: self.names,
            what,
            carry: &self.carry.carry,
        }
    }
}

pub fn run(a: Args) -> CliResult {
    let mut t = Phases::start(a.timings);
    let robot = a.robot.load()?;
    t.lap("robot");
    let env = robot.environment();
    let (mut input, mut out);
    if robot.is_tree() {
        let coords = robot.coordinates();
        input = StateInput::open(&a.states(&robot, coords, "movable joints"))?;
        out = a
            .out
            .writer(input.headers_with(&a.names.columns("tau", coords))?)?;
        // chunks of the table at once over the cores (the library's batch; errors name their
        // row)
        tree_rows(&mut input, &mut out, coords.len(), &mut t, |c, tau| {
            inverse_dynamics_batch(&robot, env, &c.x[0], &c.x[1], &c.x[2], tau)
        })?;
    } else {
        // closed chains: the actuated joints' columns in and out, every row on the branch
        // tracker (library: continuation from the previous row)
        let chain = ClosedChain::new(&robot)?;
        let coords = chain.coordinates();
        input = StateInput::open(&a.states(&robot, coords, "actuated joints (closed chain)"))?;
        out = a
            .out
            .writer(input.headers_with(&a.names.columns("tau", coords))?)?;
        let guess = a.guess.as_deref();
        closed_rows(
            &mut input,
            &mut out,
            &chain,
            guess,
            &mut t,
            |b, d, x, tau| closed_inverse_dynamics_into(&chain, d, b, env, x[0], x[1], x[2], tau),
        )?;
    }
    out.finish()?;
    t.lap("write");
    t.report(input.count());
    Ok(())
}
