//! `robodyn regressor ROBOT --input states.csv [--base]`: the regressor Phi of the equivalent
//! tree (Gamma_tr = Phi K + Gamma_e), one row per state and movable joint; with `--base`, the
//! columns of the base parameters (symbolic rules), so that Gamma_tr = Phi_b K_b + Gamma_e.
//! For a closed chain the input has the actuated joints' columns only; q_p comes from loop closure
//! (continuation from the assembly, as `robodyn closure`), qd_p, qdd_p from (10.29), (10.42), and
//! the rows are those of the actuated joints: Gamma_cl = G^T Phi K + G^T Gamma_e (eq 10.40). With
//! `--base` a closed chain uses the numerical base set when the symbolic rules do not handle
//! every loop (the numerical method is then the arbiter).

use crate::common::{CliResult, RobotArgs, Table, TableOutput};
use robodyn::algorithms::base_parameters::{
    numeric_base_parameters, symbolic_base_parameters, ClosedChainSampler, NumericOptions,
    ParameterNames,
};
use robodyn::algorithms::closed_chain::ClosedChain;
use robodyn::algorithms::inverse_dynamics::check_state;
use robodyn::algorithms::regressor::{
    regressor, wrench_torques, ParameterSelection, RotorMode, ZeroParameters, PARAMS_PER_LINK,
};
use robodyn::Workspace;
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
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let nl = robot.nl();
    let t = Table::read(&a.input)?;
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, !a.no_friction)
        .with_zero_parameters(
            robot.description(),
            ZeroParameters::for_path(&a.robot.robot),
        );
    let names = ParameterNames::of(robot.description());
    let closed = if robot.is_tree() {
        None
    } else {
        let cc = ClosedChain::new(&robot)?;
        let ws = cc.workspace();
        Some((cc, ws))
    };
    let joints = match &closed {
        Some((cc, _)) => cc.actuated_joints().to_vec(),
        None => robot.movable_joints(),
    };
    let (cols, names): (Vec<usize>, Vec<String>) = if a.base {
        let sb = symbolic_base_parameters(robot.description(), &sel)?;
        if closed.is_some() && !sb.unhandled_loops.is_empty() {
            eprintln!(
                "robodyn: note: {}: the symbolic rules do not handle the loop(s) cut at joint(s) \
                 {:?}; the columns are the numerical method's base parameters (the arbiter)",
                robot.name(),
                sb.unhandled_loops
            );
            let opt = NumericOptions {
                selection: sel.clone(),
                samples: None,
                seed: a.seed,
            };
            let mut sampler = ClosedChainSampler::new(&robot)?;
            let nb = numeric_base_parameters(&robot, &mut sampler, &opt)?;
            (0..nb.count())
                .map(|r| {
                    let i = nb.base[r];
                    let n = if nb.is_regrouped(r) {
                        names.grouped(i).to_string()
                    } else {
                        names.name(i).to_string()
                    };
                    (i, n)
                })
                .unzip()
        } else {
            (0..sb.count())
                .map(|r| {
                    let i = sb.base[r];
                    let n = if sb.is_regrouped(r) {
                        names.grouped(i).to_string()
                    } else {
                        names.name(i).to_string()
                    };
                    (i, n)
                })
                .unzip()
        }
    } else {
        let c = sel.columns();
        let n = c.iter().map(|&i| names.name(i).to_string()).collect();
        (c, n)
    };
    let idx: Vec<[usize; 3]> = joints
        .iter()
        .map(|j| {
            Ok([
                t.column(&format!("q{j}"))?,
                t.column(&format!("qd{j}"))?,
                t.column(&format!("qdd{j}"))?,
            ])
        })
        .collect::<CliResult<_>>()?;
    let model = robot.numeric();
    let mut ws = Workspace::new(model);
    let mut phi = nalgebra::DMatrix::zeros(nl, PARAMS_PER_LINK * nl);
    let mut tau_e = vec![0.0; nl];
    let mut rows = Vec::new();
    let mut closed = closed;
    for (s, r) in t.rows.iter().enumerate() {
        let mut st = [vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]];
        let g = match &mut closed {
            Some((cc, cws)) => {
                let pick = |k: usize| -> Vec<f64> { idx.iter().map(|c| r[c[k]]).collect() };
                let (qa, qda, qdda) = (pick(0), pick(1), pick(2));
                let sol = super::closure::solve(cc, cws, &qa, None)
                    .map_err(|e| format!("state {}: {e}", s + 1))?;
                let state = cc
                    .state(cws, &qa, &qda, &qdda, Some(&sol.q_p))
                    .map_err(|e| format!("state {}: {e}", s + 1))?;
                st = [state.q, state.qd, state.qdd];
                Some(state.constraints.g)
            }
            None => {
                for (j, c) in joints.iter().zip(&idx) {
                    for k in 0..3 {
                        st[k][j - 1] = r[c[k]];
                    }
                }
                check_state(&robot, "q", &st[0])?;
                None
            }
        };
        regressor(model, &mut ws, &st[0], &st[1], &st[2], &mut phi);
        wrench_torques(model, &mut ws, &st[0], &mut tau_e);
        match &g {
            Some(g) => {
                // Gamma_cl rows (10.40): G^T Phi and G^T Gamma_e, actuated-joint order
                let y = g.transpose() * &phi;
                let te = g.transpose() * nalgebra::DVector::from_column_slice(&tau_e);
                for (k, &j) in joints.iter().enumerate() {
                    let mut row = vec![(s + 1) as f64, j as f64, te[k]];
                    row.extend(cols.iter().map(|&c| y[(k, c)]));
                    rows.push(row);
                }
            }
            None => {
                for &j in &joints {
                    let mut row = vec![(s + 1) as f64, j as f64, tau_e[j - 1]];
                    row.extend(cols.iter().map(|&c| phi[(j - 1, c)]));
                    rows.push(row);
                }
            }
        }
    }
    let headers: Vec<String> = ["state", "joint", "tau_e"]
        .iter()
        .map(|s| s.to_string())
        .chain(names)
        .collect();
    a.out.write(&headers, &rows)
}
