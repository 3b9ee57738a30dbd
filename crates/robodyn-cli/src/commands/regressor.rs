//! `robodyn regressor ROBOT --input states.csv [--base]`: the regressor Phi of the equivalent
//! tree (Gamma_tr = Phi K + Gamma_e), one row per state and movable joint; with `--base`, the
//! columns of the base parameters (symbolic rules), so that Gamma_tr = Phi_b K_b + Gamma_e.
//! For a closed chain the input has the actuated joints' columns only; q_p comes from the branch
//! tracker (rows continued from the robot's assembly), qd_p, qdd_p from (10.29), (10.42), and
//! the rows are those of the actuated joints: Gamma_cl = G^T Phi K + G^T Gamma_e (eq 10.40). With
//! `--base` a closed chain uses the numerical base set when the symbolic rules do not handle
//! every loop (the numerical method is then the arbiter).

use crate::common::{
    read_joint_states, state_column, warn_conditioning, CliResult, NamesArg, Phases, RobotArgs,
    TableOutput, TimingsArg,
};
use robodyn::algorithms::regressor::{
    base_columns, standard_columns, ParameterSelection, RotorMode, ZeroParameters, PARAMS_PER_LINK,
};
use robodyn::{closed_regressor_into, regressor_batch, ClosedChain, ClosedData};
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
    pub timings: TimingsArg,
}

pub fn run(a: Args) -> CliResult {
    let mut t = Phases::start(a.timings);
    let robot = a.robot.load()?;
    let nl = robot.nl();
    // a literal 0 in a SYMORO file means the parameter does not exist (docs/robot-format.md)
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, !a.no_friction)
        .with_zero_parameters(
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
    let (states, carried) = read_joint_states(
        Some(&a.input),
        ["q", "qd", "qdd"],
        [None; 3],
        coords,
        a.names,
        "joints",
    )?;
    t.lap("read");
    let n = coords.len();
    let cols = PARAMS_PER_LINK * nl;
    let mut phi = nalgebra::DMatrix::zeros(n, cols);
    let mut tau_e = vec![0.0; n];
    let env = robot.environment();
    let mut rows = Vec::new();
    let mut closed = match &chain {
        Some(c) => Some((c, ClosedData::new(c), c.assembly_branch()?)),
        None => None,
    };
    // trees: every row at once over the cores (the library's batch; errors name their row),
    // row-major Phi of every state; closed chains: one state at a time into the first slot
    let count = if closed.is_none() { states.len() } else { 1 };
    let mut phi_all = vec![0.0; count * n * cols];
    let mut tau_e_all = vec![0.0; count * n];
    if closed.is_none() {
        let col = |i| state_column(&states, i);
        regressor_batch(
            &robot,
            env,
            &col(0),
            &col(1),
            &col(2),
            &mut phi_all,
            &mut tau_e_all,
        )?;
    }
    for (s, [q, qd, qdd]) in states.iter().enumerate() {
        let slot = match &mut closed {
            // Gamma_cl rows (10.40): G^T Phi and G^T Gamma_e, actuated-joint order
            Some((c, d, b)) => {
                let cond = closed_regressor_into(c, d, b, env, [q, qd, qdd], &mut phi, &mut tau_e)
                    .map_err(|e| e.in_row(s + 1))?;
                warn_conditioning(c, s + 1, states.len(), &cond);
                for k in 0..n {
                    for c in 0..cols {
                        phi_all[k * cols + c] = phi[(k, c)];
                    }
                }
                tau_e_all.copy_from_slice(&tau_e);
                0
            }
            None => s,
        };
        for k in 0..n {
            let r = slot * n + k;
            let mut row = carried.rows.get(s).cloned().unwrap_or_default();
            row.extend([(s + 1) as f64, coords.frame(k) as f64, tau_e_all[r]]);
            row.extend(columns.indices.iter().map(|&c| phi_all[r * cols + c]));
            rows.push(row);
        }
    }
    let headers: Vec<String> = carried
        .headers
        .iter()
        .cloned()
        .chain(["state", "joint", "tau_e"].iter().map(|s| s.to_string()))
        .chain(columns.names)
        .collect();
    t.lap("model");
    a.out.write(&headers, &rows)?;
    t.lap("write");
    t.report(states.len());
    Ok(())
}
