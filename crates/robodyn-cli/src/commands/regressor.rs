//! `robodyn regressor ROBOT --input states.csv [--base]`: the regressor Phi of the equivalent
//! tree (Gamma_tr = Phi K + Gamma_e), one row per state and movable joint; with `--base`, the
//! columns of the base parameters (symbolic rules), so that Gamma_tr = Phi_b K_b + Gamma_e.
//! For a closed chain the input has the actuated joints' columns only; q_p comes from the branch
//! tracker (rows continued from the robot's assembly), qd_p, qdd_p from (10.29), (10.42), and
//! the rows are those of the actuated joints: Gamma_cl = G^T Phi K + G^T Gamma_e (eq 10.40). With
//! `--base` a closed chain uses the numerical base set when the symbolic rules do not handle
//! every loop (the numerical method is then the arbiter).
//!
//! A floating robot (`--floating` for a URDF): states of nq = 7 + N, nv = 6 + N values, the base
//! columns first (as `simulate` writes them), nv rows per state (a `row` column: 0..5 the base
//! wrench fx fy fz mx my mz, joint 0; then the joints) and the columns of the links' parameters
//! then link 0's (`XX0` .. `M0`); `--base`: the numerical base set (on the full nv rows).

use crate::common::{
    chunk_states, in_table, warn_conditioning, CliResult, NamesArg, Phases, RobotArgs, TableOutput,
    TableWriter, TimingsArg,
};
use crate::states::{base_columns3, CarryArg, Chunk, StateInput, StateRequest};
use robodyn::algorithms::base_parameters::{base_columns, standard_columns};
use robodyn::algorithms::regressor::{
    parameter_count, Friction, ParameterSelection, RotorMode, ZeroParameters,
};
use robodyn::{closed_regressor_into, regressor_batch, ClosedChain, ClosedData, Coordinates};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// CSV of states with columns q<j>, qd<j>, qdd<j> for the movable tree joints (closed chain:
    /// for the actuated joints).
    #[arg(long)]
    pub input: PathBuf,
    /// Only the columns of the base parameters (named with R when grouped).
    #[arg(long)]
    pub base: bool,
    /// Leave out FS, FV.
    #[arg(long)]
    pub no_friction: bool,
    /// Seed of the numerical method's samples (closed chain with `--base`).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[command(flatten)]
    pub out: TableOutput,
    #[command(flatten)]
    pub names: NamesArg,
    #[command(flatten)]
    pub carry: CarryArg,
    #[command(flatten)]
    pub timings: TimingsArg,
}

pub fn run(a: Args) -> CliResult {
    let mut t = Phases::start(a.timings);
    let robot = a.robot.load()?;
    // its IA, FS, FV columns are joint-side: with motors' values the product W K is not the IDM
    crate::common::refuse_motor_drives(&robot, &a.robot.robot, "robodyn regressor")?;
    // a literal 0 in a SYMORO file means the parameter does not exist (docs/robot-format.md)
    let friction = if a.no_friction {
        Friction::None
    } else {
        Friction::Actuated
    };
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, friction).with_zero_parameters(
        robot.description(),
        ZeroParameters::for_path(&a.robot.robot),
    );
    let columns = if a.base {
        base_columns(&robot, &sel, a.seed)?
    } else {
        standard_columns(&robot, &sel)
    };
    if let Some(note) = &columns.note {
        eprintln!("robodyn: note: {note}");
    }
    let chain = if robot.is_tree() {
        None
    } else {
        Some(ClosedChain::new(&robot)?)
    };
    let coords = match &chain {
        Some(c) => c.coordinates(),
        None => robot.coordinates(),
    };
    t.lap("robot");
    let mut input = StateInput::open(&StateRequest {
        input: Some(&a.input),
        prefixes: ["q", "qd", "qdd"],
        lists: [None; 3],
        coords,
        tree: robot.coordinates(),
        names: a.names,
        what: "joints",
        carry: &a.carry.carry,
        base: base_columns3(&robot, ["q", "qd", "qdd"]),
    })?;
    let floating = robot.is_floating();
    let first: &[&str] = if floating {
        &["state", "row", "joint", "tau_e"]
    } else {
        &["state", "joint", "tau_e"]
    };
    let headers = input.headers_with(
        &first
            .iter()
            .map(|s| s.to_string())
            .chain(columns.names.iter().cloned())
            .collect::<Vec<_>>(),
    )?;
    let mut rows = Rows {
        out: a.out.writer(headers)?,
        coords,
        indices: &columns.indices,
        cols: parameter_count(&robot),
        floating,
        row: Vec::new(),
    };
    t.lap("read");
    match &chain {
        None if floating => floating_rows(&robot, &mut input, &mut rows, &mut t)?,
        None => tree_rows(&robot, &mut input, &mut rows, &mut t)?,
        Some(c) => closed_rows(c, &mut input, &mut rows, &mut t)?,
    }
    rows.out.finish()?;
    t.lap("write");
    t.report(input.count());
    Ok(())
}

/// Trees: chunks of states at once over the cores (the library's batch; errors name their row),
/// row-major Phi of every state of the chunk, written before the next chunk is read.
fn tree_rows(
    robot: &robodyn::Robot,
    input: &mut StateInput,
    rows: &mut Rows,
    t: &mut Phases,
) -> CliResult {
    let (n, cols) = (rows.coords.len(), rows.cols);
    let nc = input.carried_headers().len();
    let (mut chunk, mut phi, mut tau_e) = (Chunk::default(), Vec::new(), Vec::new());
    let per_state = n * (cols + 1) + 3 * n + nc;
    while input.next_chunk(chunk_states(per_state), &mut chunk)? {
        t.lap("read");
        phi.resize(chunk.count * n * cols, 0.0);
        tau_e.resize(chunk.count * n, 0.0);
        let x = &chunk.x;
        regressor_batch(
            robot,
            robot.environment(),
            &x[0],
            &x[1],
            &x[2],
            &mut phi,
            &mut tau_e,
        )
        .map_err(|e| in_table(e, chunk.first))?;
        t.lap("model");
        for s in 0..chunk.count {
            let (phi, tau_e) = (&phi[s * n * cols..], &tau_e[s * n..]);
            let number = chunk.first + s;
            rows.state(number, chunk.carried(s, nc), tau_e, |k, c| {
                phi[k * cols + c]
            })?;
        }
        t.lap("write");
    }
    Ok(())
}

/// Floating robots: one state at a time (q of nq, v and a of nv values), nv rows each; the
/// library refuses external wrenches there, so tau_e is 0.
fn floating_rows(
    robot: &robodyn::Robot,
    input: &mut StateInput,
    rows: &mut Rows,
    t: &mut Phases,
) -> CliResult {
    let (nq, nv) = (robot.nq(), robot.nv());
    let nc = input.carried_headers().len();
    let (mut data, mut chunk) = (robodyn::Data::new(robot), Chunk::default());
    let mut phi = nalgebra::DMatrix::zeros(nv, rows.cols);
    let tau_e = vec![0.0; nv];
    while input.next_chunk(chunk_states(nq + 2 * nv + nc), &mut chunk)? {
        t.lap("read");
        for s in 0..chunk.count {
            let number = chunk.first + s;
            let x = [
                &chunk.x[0][s * nq..(s + 1) * nq],
                &chunk.x[1][s * nv..(s + 1) * nv],
                &chunk.x[2][s * nv..(s + 1) * nv],
            ];
            robodyn::regressor_into(
                robot,
                &mut data,
                robot.environment(),
                x[0],
                x[1],
                x[2],
                &mut phi,
            )
            .map_err(|e| e.in_row(number))?;
            t.lap("model");
            rows.state(number, chunk.carried(s, nc), &tau_e, |k, c| phi[(k, c)])?;
            t.lap("write");
        }
    }
    Ok(())
}

/// Closed chains: one state at a time on the branch tracker (from the robot's assembly):
/// G^T Phi and G^T Gamma_e, actuated-joint order (10.40).
fn closed_rows(
    c: &ClosedChain,
    input: &mut StateInput,
    rows: &mut Rows,
    t: &mut Phases,
) -> CliResult {
    let (n, nc, env) = (
        c.dof(),
        input.carried_headers().len(),
        c.robot().environment(),
    );
    let (mut d, mut b, mut chunk) = (ClosedData::new(c), c.assembly_branch()?, Chunk::default());
    let mut phi = nalgebra::DMatrix::zeros(n, rows.cols);
    let mut tau_e = vec![0.0; n];
    while input.next_chunk(chunk_states(3 * n + nc), &mut chunk)? {
        t.lap("read");
        for s in 0..chunk.count {
            let number = chunk.first + s;
            let x = chunk.state(s, n);
            let cond = closed_regressor_into(c, &mut d, &mut b, env, x, &mut phi, &mut tau_e)
                .map_err(|e| e.in_row(number))?;
            warn_conditioning(c, Some(number), &cond);
            t.lap("model");
            rows.state(number, chunk.carried(s, nc), &tau_e, |k, c| phi[(k, c)])?;
            t.lap("write");
        }
    }
    Ok(())
}

/// The regressor's output rows: one per state and joint.
struct Rows<'a> {
    out: TableWriter,
    coords: &'a Coordinates,
    /// The columns of Phi written (standard or base parameters).
    indices: &'a [usize],
    /// Columns of Phi (13 per link, then a floating base's 10).
    cols: usize,
    /// nv rows per state (the base's 6 first, joint 0), a `row` column in front of `joint`.
    floating: bool,
    row: Vec<f64>,
}

impl Rows<'_> {
    /// The rows of state `number`: carried values, state, joint, tau_e, the selected columns of
    /// Phi (`phi(joint, column)`).
    fn state(
        &mut self,
        number: usize,
        carried: &[f64],
        tau_e: &[f64],
        phi: impl Fn(usize, usize) -> f64,
    ) -> CliResult {
        let (base, n) = if self.floating {
            (6, 6 + self.coords.len())
        } else {
            (0, self.coords.len())
        };
        for (k, &tau_e) in tau_e.iter().take(n).enumerate() {
            self.row.clear();
            self.row.extend_from_slice(carried);
            self.row.push(number as f64);
            if self.floating {
                self.row.push(k as f64);
            }
            let joint = if k < base {
                0
            } else {
                self.coords.frame(k - base)
            };
            self.row.extend([joint as f64, tau_e]);
            self.row.extend(self.indices.iter().map(|&c| phi(k, c)));
            self.out.row(Some(number), &self.row, None)?;
        }
        Ok(())
    }
}
