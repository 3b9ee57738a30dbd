//! Evaluating a model on every state of an input (`idm`, `ddm`): a tree's states by chunks over
//! the cores, a closed chain's one after the other on the branch tracker, every result row
//! written before the next chunk is read, so the memory does not grow with the table.

use crate::common::{
    chunk_states, conditioning_json, in_table, start_branch, warn_conditioning, CliResult,
    NamesArg, Phases, RobotArgs, TableOutput, TableWriter, TimingsArg,
};
use crate::states::{base_columns, base_columns3, CarryArg, Chunk, StateInput, StateRequest};
use robodyn::{Branch, ClosedChain, ClosedData, Conditioning};
use std::path::Path;

/// The options `idm` and `ddm` share after their inputs: the output table, the column names,
/// the closed chains' start, the carried columns, the timings.
#[derive(clap::Args, Debug)]
pub struct EvaluationArgs {
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

/// Load the robot and evaluate `tree` or `closed` on every state of `input` or of the three
/// command-line `lists` (quantities `prefixes`), writing one result per joint named `result`
/// (`idm`, `ddm`).
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    robot: &RobotArgs,
    args: &EvaluationArgs,
    input: Option<&Path>,
    prefixes: [&str; 3],
    lists: [Option<&str>; 3],
    result: &str,
    tree: &mut LoadedTreeModel,
    closed: &mut ClosedModel,
) -> CliResult {
    let mut t = Phases::start(args.timings);
    let robot = robot.load()?;
    let command = if result == "tau" { "idm" } else { "ddm" };
    crate::common::transmission_note(&robot, command);
    t.lap("robot");
    let evaluation = Evaluation {
        input,
        prefixes,
        lists,
        names: args.names,
        carry: &args.carry.carry,
        guess: args.guess.as_deref(),
        output: &args.out,
        result,
    };
    evaluation.run(&robot, &mut t, &mut |c, x| tree(&robot, c, x), closed)
}

/// What `idm` and `ddm` share: states in (a table or the command line), one result per joint
/// out, a tree's by chunks and a closed chain's on the branch tracker.
pub struct Evaluation<'a> {
    /// `--input`.
    pub input: Option<&'a Path>,
    /// The quantities read (`q`, `qd`, `qdd` or `tau`).
    pub prefixes: [&'a str; 3],
    /// `--q`, `--qd`, `--qdd` or `--tau`.
    pub lists: [Option<&'a str>; 3],
    pub names: NamesArg,
    /// `--carry`.
    pub carry: &'a [String],
    /// `--guess` (closed chains).
    pub guess: Option<&'a str>,
    pub output: &'a TableOutput,
    /// The results' columns' prefix (`tau`, `qdd`).
    pub result: &'a str,
}

/// A tree's evaluation of a chunk into its results.
pub type TreeModel<'f> = dyn FnMut(&Chunk, &mut [f64]) -> robodyn::Result<()> + 'f;
/// [`TreeModel`] on the robot [`evaluate`] loads.
pub type LoadedTreeModel<'f> =
    dyn FnMut(&robodyn::Robot, &Chunk, &mut [f64]) -> robodyn::Result<()> + 'f;
/// A closed chain's evaluation of one state on the tracker into its results.
pub type ClosedModel<'f> = dyn FnMut(
        &ClosedChain,
        &mut Branch,
        &mut ClosedData,
        [&[f64]; 3],
        &mut [f64],
    ) -> robodyn::Result<Conditioning>
    + 'f;

impl Evaluation<'_> {
    /// Evaluate every state with `tree` (a tree robot) or `closed` (a closed chain's actuated
    /// joints, in and out) and write the table.
    pub fn run(
        &self,
        robot: &robodyn::Robot,
        t: &mut Phases,
        tree: &mut TreeModel,
        closed: &mut ClosedModel,
    ) -> CliResult {
        let chain = (!robot.is_tree())
            .then(|| ClosedChain::new(robot))
            .transpose()?;
        let (coords, what) = match &chain {
            Some(c) => (c.coordinates(), "actuated joints (closed chain)"),
            None => (robot.coordinates(), "movable joints"),
        };
        let mut input = StateInput::open(&StateRequest {
            input: self.input,
            prefixes: self.prefixes,
            lists: self.lists,
            coords,
            tree: robot.coordinates(),
            names: self.names,
            what,
            carry: self.carry,
            base: base_columns3(robot, self.prefixes),
        })?;
        let results = [
            base_columns(robot, self.result),
            self.names.columns(self.result, coords),
        ]
        .concat();
        let mut out = self.output.writer(input.headers_with(&results)?)?;
        match &chain {
            None => tree_rows(&mut input, &mut out, results.len(), t, tree)?,
            Some(c) => closed_rows(&mut input, &mut out, c, self.guess, t, |b, d, x, r| {
                closed(c, b, d, x, r)
            })?,
        }
        out.finish()?;
        t.lap("write");
        t.report(input.count());
        Ok(())
    }
}

/// Tree: `eval(chunk, out)` fills `n` results per state of the chunk (row-major); each row is
/// written with the carried columns in front.
fn tree_rows(
    input: &mut StateInput,
    out: &mut TableWriter,
    n: usize,
    t: &mut Phases,
    eval: &mut TreeModel,
) -> CliResult {
    let nc = input.carried_headers().len();
    let (mut chunk, mut results, mut row) = (Chunk::default(), Vec::new(), Vec::new());
    let numbered = !input.is_command_line();
    t.lap("read");
    while input.next_chunk(chunk_states(3 * n + nc), &mut chunk)? {
        t.lap("read");
        results.resize(chunk.count * n, 0.0);
        eval(&chunk, &mut results).map_err(|e| in_table(e, chunk.first))?;
        t.lap("model");
        for s in 0..chunk.count {
            row.clear();
            row.extend_from_slice(chunk.carried(s, nc));
            row.extend_from_slice(&results[s * n..(s + 1) * n]);
            out.row(numbered.then_some(chunk.first + s), &row, None)?;
        }
        t.lap("write");
    }
    Ok(())
}

/// Closed chain: `eval(branch, data, state, out)` fills the `n` results of one state on the
/// branch tracker (started at the first state from `guess` or the robot's assembly); the rows
/// carry the conditioning in JSON, and a state near a singularity is flagged on stderr.
fn closed_rows(
    input: &mut StateInput,
    out: &mut TableWriter,
    chain: &ClosedChain,
    guess: Option<&str>,
    t: &mut Phases,
    mut eval: impl FnMut(
        &mut Branch,
        &mut ClosedData,
        [&[f64]; 3],
        &mut [f64],
    ) -> robodyn::Result<Conditioning>,
) -> CliResult {
    let n = chain.dof();
    let nc = input.carried_headers().len();
    let (mut chunk, mut row) = (Chunk::default(), Vec::new());
    let mut tracker: Option<(Branch, ClosedData)> = None;
    let numbered = !input.is_command_line();
    t.lap("read");
    while input.next_chunk(chunk_states(3 * n + nc), &mut chunk)? {
        t.lap("read");
        for s in 0..chunk.count {
            let state = chunk.state(s, n);
            let (branch, data) = match &mut tracker {
                Some(t) => t,
                None => tracker.insert((
                    start_branch(chain, state[0], guess)?,
                    ClosedData::new(chain),
                )),
            };
            let number = chunk.first + s;
            row.clear();
            row.extend_from_slice(chunk.carried(s, nc));
            row.resize(nc + n, 0.0);
            let c = eval(branch, data, state, &mut row[nc..]).map_err(|e| e.in_row(number))?;
            let number = numbered.then_some(number);
            warn_conditioning(chain, number, &c);
            t.lap("model");
            out.row(number, &row, Some(&conditioning_json(&c)))?;
            t.lap("write");
        }
    }
    Ok(())
}
