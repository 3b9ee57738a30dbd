//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state (q_p solved by loop closure, each row
//! starting from the previous row's solution; the first from `--guess`, else as `closure` does).

use crate::common::{parse_list, write_table, CliResult, RobotArgs, Table, TableFormat};
use robodyn::algorithms::inverse_dynamics::{check_state, rnea};
use robodyn::Workspace;
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
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
    /// Closed chains: initial guess of q_p for the first state (passive tree joints in order).
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    if !robot.is_tree() {
        return run_closed(a, robot);
    }
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

/// Read states (q, qd, qdd) for the given joints from `--input` or `--q/--qd/--qdd`.
fn read_states(a: &Args, joints: &[usize], what: &str) -> CliResult<Vec<[Vec<f64>; 3]>> {
    let n = joints.len();
    if let Some(path) = &a.input {
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
        Ok(t.rows
            .iter()
            .map(|r| std::array::from_fn(|k| cols.iter().map(|c| r[c[k]]).collect()))
            .collect())
    } else {
        let q =
            a.q.as_deref()
                .ok_or("give --input states.csv or --q (with --qd, --qdd)")?;
        let mut s = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
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
                if vals.len() != n {
                    return Err(format!(
                        "--{name} has {} values, the robot has {n} {what} ({joints:?})",
                        vals.len()
                    )
                    .into());
                }
                s[k] = vals;
            }
        }
        Ok(vec![s])
    }
}

/// Closed chains: columns of the actuated joints in, tau<j> of the actuated joints out.
fn run_closed(a: Args, robot: robodyn::Robot) -> CliResult {
    use robodyn::algorithms::closed_chain::ClosedChain;
    let cc = ClosedChain::new(&robot)?;
    let joints = cc.actuated_joints().to_vec();
    let states = read_states(&a, &joints, "actuated joints (closed chain)")?;
    let mut guess = a
        .guess
        .as_deref()
        .map(|g| parse_list("guess", g))
        .transpose()?;
    let mut ws = cc.workspace();
    let mut rows = Vec::with_capacity(states.len());
    for (i, [q, qd, qdd]) in states.iter().enumerate() {
        let s = cc
            .solve_from_reference(&mut ws, q, guess.as_deref())
            .map_err(|e| format!("state {}: {e}", i + 1))?;
        let r = cc
            .inverse_dynamics(&mut ws, q, qd, qdd, Some(&s.q_p))
            .map_err(|e| format!("state {}: {e}", i + 1))?;
        rows.push(r.gamma_cl.iter().copied().collect());
        guess = Some(s.q_p);
    }
    let headers: Vec<String> = joints.iter().map(|j| format!("tau{j}")).collect();
    write_table(a.output.as_deref(), a.format, &headers, &rows)
}
