//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.

use crate::common::{parse_list, write_table, CliResult, RobotArgs, Table, TableFormat};
use robodyn::algorithms::inverse_dynamics::{check_state, rnea};
use robodyn::Workspace;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// CSV of states with columns q<j>, qd<j>, qdd<j> for the movable joints.
    #[arg(long, conflicts_with_all = ["q", "qd", "qdd"])]
    pub input: Option<PathBuf>,
    /// One state: joint positions, comma separated (movable joints in frame order).
    #[arg(long, allow_hyphen_values = true)]
    pub q: Option<String>,
    /// Joint velocities (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qd: Option<String>,
    /// Joint accelerations (default zeros).
    #[arg(long, allow_hyphen_values = true)]
    pub qdd: Option<String>,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let joints = robot.movable_joints();
    let nl = robot.nl();
    let states: Vec<[Vec<f64>; 3]> = if let Some(path) = &a.input {
        let t = Table::read(path)?;
        let cols: Vec<[usize; 3]> = joints
            .iter()
            .map(|j| {
                Ok([
                    t.column(&format!("q{j}"))?,
                    t.column(&format!("qd{j}"))?,
                    t.column(&format!("qdd{j}"))?,
                ])
            })
            .collect::<CliResult<_>>()?;
        t.rows
            .iter()
            .map(|r| {
                let mut s = [vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]];
                for (j, c) in joints.iter().zip(&cols) {
                    for k in 0..3 {
                        s[k][j - 1] = r[c[k]];
                    }
                }
                s
            })
            .collect()
    } else {
        let q =
            a.q.as_deref()
                .ok_or("give --input states.csv or --q (with --qd, --qdd)")?;
        let mut s = [vec![0.0; nl], vec![0.0; nl], vec![0.0; nl]];
        for (k, (name, v)) in [
            ("q", Some(q)),
            ("qd", a.qd.as_deref()),
            ("qdd", a.qdd.as_deref()),
        ]
        .into_iter()
        .enumerate()
        {
            if let Some(v) = v {
                let vals = parse_list(name, v)?;
                if vals.len() != joints.len() {
                    return Err(format!(
                        "--{name} has {} values, the robot has {} movable tree joints ({:?})",
                        vals.len(),
                        joints.len(),
                        joints
                    )
                    .into());
                }
                for (j, x) in joints.iter().zip(vals) {
                    s[k][j - 1] = x;
                }
            }
        }
        vec![s]
    };
    let model = robot.numeric();
    let mut ws = Workspace::new(model);
    let mut tau = vec![0.0; nl];
    let mut rows = Vec::with_capacity(states.len());
    for [q, qd, qdd] in &states {
        check_state(&robot, "q", q)?;
        rnea(model, &mut ws, q, qd, qdd, &mut tau);
        rows.push(joints.iter().map(|j| tau[j - 1]).collect());
    }
    let headers: Vec<String> = joints.iter().map(|j| format!("tau{j}")).collect();
    write_table(a.output.as_deref(), a.format, &headers, &rows)
}
