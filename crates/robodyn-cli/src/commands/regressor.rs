//! `robodyn regressor ROBOT --input states.csv [--base]`: the regressor Phi of the equivalent
//! tree (Gamma_tr = Phi K + Gamma_e), one row per state and movable joint; with `--base`, the
//! columns of the base parameters (symbolic rules), so that Gamma_tr = Phi_b K_b + Gamma_e.
//! For a closed chain, Gamma_cl = G^T Phi K (eq 10.40).

use crate::common::{write_table, CliResult, RobotArgs, Table, TableFormat};
use robodyn::algorithms::base_parameters::report::grouped_name;
use robodyn::algorithms::base_parameters::symbolic_base_parameters;
use robodyn::algorithms::inverse_dynamics::check_state;
use robodyn::algorithms::regressor::{
    parameter_name, regressor, wrench_torques, ParameterSelection, RotorMode, PARAMS_PER_LINK,
};
use robodyn::Workspace;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// CSV of states with columns q<j>, qd<j>, qdd<j> for the movable tree joints.
    #[arg(long)]
    pub input: PathBuf,
    /// Only the columns of the base parameters (named with R when grouped).
    #[arg(long)]
    pub base: bool,
    /// Leave out FS, FV.
    #[arg(long)]
    pub no_friction: bool,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let nl = robot.nl();
    let joints = robot.movable_joints();
    let t = Table::read(&a.input)?;
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, !a.no_friction);
    if a.base && !robot.is_tree() {
        eprintln!(
            "robodyn: note: {} is a closed chain: its base parameters hold for the closed-chain \
             model G^T Phi_b K_b (eq 10.40), not for the tree torques of each row",
            robot.name()
        );
    }
    let (cols, names): (Vec<usize>, Vec<String>) = if a.base {
        let sb = symbolic_base_parameters(robot.description(), &sel)?;
        (0..sb.count())
            .map(|r| {
                let i = sb.base[r];
                let n = if sb.is_regrouped(r) {
                    grouped_name(i)
                } else {
                    parameter_name(i)
                };
                (i, n)
            })
            .unzip()
    } else {
        let c = sel.columns();
        let n = c.iter().map(|&i| parameter_name(i)).collect();
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
    for (s, r) in t.rows.iter().enumerate() {
        let mut st = [vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]];
        for (j, c) in joints.iter().zip(&idx) {
            for k in 0..3 {
                st[k][j - 1] = r[c[k]];
            }
        }
        check_state(&robot, "q", &st[0])?;
        regressor(model, &mut ws, &st[0], &st[1], &st[2], &mut phi);
        wrench_torques(model, &mut ws, &st[0], &mut tau_e);
        for &j in &joints {
            let mut row = vec![(s + 1) as f64, j as f64, tau_e[j - 1]];
            row.extend(cols.iter().map(|&c| phi[(j - 1, c)]));
            rows.push(row);
        }
    }
    let headers: Vec<String> = ["state", "joint", "tau_e"]
        .iter()
        .map(|s| s.to_string())
        .chain(names)
        .collect();
    write_table(a.output.as_deref(), a.format, &headers, &rows)
}
