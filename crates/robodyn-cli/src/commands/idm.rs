//! `robodyn idm ROBOT`: inverse dynamic model (recursive Newton-Euler) for states from a CSV file
//! (columns q<j>, qd<j>, qdd<j>) or from `--q/--qd/--qdd`.
//!
//! For a closed-chain robot the states and torques are those of the actuated joints only:
//! Γ_cl = G^T Γ_tr (10.40) at the consistent tree state, every row on the assembly branch
//! (the library's branch tracker: each row continued from the previous one, the first from the
//! robot's `assembly` or `--guess`); rows near a singularity are flagged on stderr and in JSON.

use crate::common::{format_number, parse_list, write_text, CliResult, RobotArgs, TableFormat};
use crate::rows::{evaluate, EvaluationArgs};
use robodyn::{
    closed_inverse_dynamics_into, inverse_dynamics, inverse_dynamics_batch,
    inverse_dynamics_derivatives,
};
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
    /// Instead of the torques, write the derivatives of the model at the one state of
    /// --q/--qd/--qdd: dtau_dq, dtau_dqd and A = dtau/dqdd (N x N over the movable joints; row j
    /// is the derivative of tau_j; trees only). csv: columns matrix, joint, then one per joint;
    /// json: {"joints", "q", "qd", "qdd", "tau", "dtau_dq", "dtau_dqd", "A"}.
    #[arg(long, conflicts_with_all = ["input", "guess", "carry"])]
    pub derivatives: bool,
    #[command(flatten)]
    pub eval: EvaluationArgs,
}

pub fn run(a: Args) -> CliResult {
    if a.derivatives {
        return derivatives(&a);
    }
    evaluate(
        &a.robot,
        &a.eval,
        a.input.as_deref(),
        ["q", "qd", "qdd"],
        [a.q.as_deref(), a.qd.as_deref(), a.qdd.as_deref()],
        "tau",
        // chunks of the table at once over the cores (the library's batch; errors name their row)
        &mut |r, c, tau| inverse_dynamics_batch(r, r.environment(), &c.x[0], &c.x[1], &c.x[2], tau),
        // closed chains: every row on the branch tracker (continued from the previous row)
        &mut |chain, b, d, x, tau| {
            closed_inverse_dynamics_into(
                chain,
                d,
                b,
                chain.robot().environment(),
                x[0],
                x[1],
                x[2],
                tau,
            )
        },
    )
}

/// `idm --derivatives`: the three matrices at one state, in the table format of `--format`.
fn derivatives(a: &Args) -> CliResult {
    let robot = a.robot.load()?;
    crate::common::refuse_motor_drives(&robot, &a.robot.robot, "idm --derivatives")?;
    if !robot.is_tree() {
        return Err(
            "idm --derivatives: the derivatives of a closed chain's model are not \
                    available yet (trees only); drop --derivatives for the torques"
                .into(),
        );
    }
    let n = robot.dof();
    let list = |name: &str, s: &Option<String>| match s {
        Some(s) => parse_list(name, s),
        None => Ok(vec![0.0; n]),
    };
    let (q, qd, qdd) = (list("q", &a.q)?, list("qd", &a.qd)?, list("qdd", &a.qdd)?);
    let d = inverse_dynamics_derivatives(&robot, &q, &qd, &qdd)?;
    let tau = inverse_dynamics(&robot, &q, &qd, &qdd)?;
    let joints = robot.coordinates().frames().to_vec();
    let mats = [
        ("dtau_dq", &d.dtau_dq),
        ("dtau_dqd", &d.dtau_dqd),
        ("A", &d.a),
    ];
    let rows = |m: &robodyn::nalgebra::DMatrix<f64>| -> Vec<Vec<f64>> {
        (0..n).map(|i| m.row(i).iter().copied().collect()).collect()
    };
    let text = match a.eval.out.format {
        TableFormat::Csv => {
            let mut t = String::from("matrix,joint");
            for j in &joints {
                t += &format!(",{j}");
            }
            t.push('\n');
            for (name, m) in mats {
                for (i, j) in joints.iter().enumerate() {
                    t += &format!("{name},{j}");
                    for x in m.row(i).iter() {
                        t += &format!(",{}", format_number(*x));
                    }
                    t.push('\n');
                }
            }
            t
        }
        TableFormat::Json => {
            let v = serde_json::json!({
                "joints": joints, "q": q, "qd": qd, "qdd": qdd, "tau": tau.as_slice(),
                "dtau_dq": rows(&d.dtau_dq), "dtau_dqd": rows(&d.dtau_dqd), "A": rows(&d.a),
            });
            serde_json::to_string_pretty(&v)? + "\n"
        }
    };
    write_text(a.eval.out.output.as_deref(), &text)
}
