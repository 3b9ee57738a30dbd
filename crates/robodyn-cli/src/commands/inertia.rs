//! `robodyn inertia ROBOT --q ...`: the inertia matrix A(q) of the (equivalent) tree by the
//! composite-link method, over the movable joints (rotor inertias on the diagonal).

use crate::common::{parse_list, write_table, CliResult, RobotArgs, TableFormat};
use robodyn::inertia_matrix;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Joint positions, comma separated (movable joints in frame order; default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: one column per movable joint (header = joint number), rows in the same order; json: {"joints": [...], "A": [[...]]}.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let joints = robot.coordinates().frames().to_vec();
    let q = match &a.q {
        Some(s) => parse_list("q", s)?,
        None => vec![0.0; joints.len()],
    };
    let m = inertia_matrix(&robot, &q)?;
    let rows: Vec<Vec<f64>> = (0..joints.len())
        .map(|i| m.row(i).iter().copied().collect())
        .collect();
    match a.format {
        TableFormat::Csv => {
            let headers: Vec<String> = joints.iter().map(|j| j.to_string()).collect();
            write_table(a.output.as_deref(), a.format, &headers, &rows)
        }
        TableFormat::Json => {
            let v = serde_json::json!({ "joints": joints, "q": q, "A": rows });
            crate::common::check_finite("A", &rows.concat())?;
            let text = serde_json::to_string_pretty(&v)?;
            crate::common::write_text(a.output.as_deref(), &(text + "\n"))
        }
    }
}
