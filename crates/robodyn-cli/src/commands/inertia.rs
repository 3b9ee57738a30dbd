//! `robodyn inertia ROBOT --q ...`: the inertia matrix A(q) of the (equivalent) tree by the
//! composite-link method, over the movable joints (rotor inertias on the diagonal); for a
//! floating robot over its nv velocities (the base's six first, `base_vx` .. `base_wz`).

use crate::common::{parse_list, write_table, CliResult, RobotArgs, TableFormat};
use crate::states::base_columns;
use robodyn::inertia_matrix;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Joint positions, comma separated (movable joints in frame order; default zeros). A
    /// floating robot's configuration: the base position, its unit quaternion (x, y, z, w), then
    /// the joints (nq = 7 + joints values, required).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: one column per movable joint (header = joint number), rows in the same order (a
    /// floating base's six first, headers base_vx .. base_wz); json: {"joints": [...], "A":
    /// [[...]]} (and "base": the base's names).
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    crate::common::transmission_note(&robot, "inertia");
    let joints = robot.coordinates().frames().to_vec();
    let q = match &a.q {
        Some(s) => parse_list("q", s)?,
        None if robot.is_floating() => {
            return Err(format!(
                "give --q: a floating robot's configuration has nq = 7 + {} values (base \
                 position, unit quaternion x y z w, then the joints)",
                joints.len()
            )
            .into())
        }
        None => vec![0.0; joints.len()],
    };
    if robot.is_floating() && q.len() != robot.nq() {
        return Err(format!(
            "--q has {} values, the robot has {}{} movable joints ({joints:?}): {} values",
            q.len(),
            base_text(&robot),
            joints.len(),
            robot.nq()
        )
        .into());
    }
    let m = inertia_matrix(&robot, &q)?;
    let nv = robot.nv();
    let rows: Vec<Vec<f64>> = (0..nv)
        .map(|i| m.row(i).iter().copied().collect())
        .collect();
    // a floating base's rows and columns first, named as `simulate` names its velocities
    let base = base_columns(&robot, "qd");
    match a.format {
        TableFormat::Csv => {
            let headers: Vec<String> = base
                .iter()
                .cloned()
                .chain(joints.iter().map(|j| j.to_string()))
                .collect();
            write_table(a.output.as_deref(), a.format, &headers, &rows)
        }
        TableFormat::Json => {
            let mut v = serde_json::json!({ "joints": joints, "q": q, "A": rows });
            if robot.is_floating() {
                v["base"] = serde_json::json!(base);
            }
            crate::common::check_finite("A", &rows.concat())?;
            let text = serde_json::to_string_pretty(&v)?;
            crate::common::write_text(a.output.as_deref(), &(text + "\n"))
        }
    }
}

/// "7 base entries (floating base) then " for a floating robot, else nothing.
fn base_text(robot: &robodyn::Robot) -> &'static str {
    if robot.is_floating() {
        "7 base entries (base_x, base_y, base_z, base_qx, base_qy, base_qz, base_qw: floating \
         base) then "
    } else {
        ""
    }
}
