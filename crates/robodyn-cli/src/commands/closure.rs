//! `robodyn closure ROBOT --qa ...`: loop closure of a closed-chain robot: the passive tree
//! variables q_p (and the cut-joint variables) for given actuated variables q_a, and with
//! `--jacobian` W = d q_p / d q_a (10.30).

use crate::common::{parse_list, CliResult, RobotArgs};
use robodyn::algorithms::closed_chain::{ClosedChain, ClosedChainWorkspace};
use robodyn::algorithms::loop_closure::ClosureSolution;
use serde_json::json;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Actuated joint values q_a, comma separated, in joint order (see `robodyn info`).
    #[arg(long, allow_hyphen_values = true)]
    pub qa: String,
    /// Initial guess of q_p (passive tree joints in joint order); default: continuation from
    /// the robot's `assembly` configuration (else q = 0) when the loops close there, else
    /// damped Newton from its q_p.
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
    /// Also print W = d q_p / d q_a.
    #[arg(long)]
    pub jacobian: bool,
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Text,
    Json,
}

/// Solve q_p for q_a from `guess`, else from the reference assembly
/// ([`ClosedChain::solve_from_reference`]).
pub fn solve(
    cc: &ClosedChain,
    ws: &mut ClosedChainWorkspace,
    q_a: &[f64],
    guess: Option<&[f64]>,
) -> CliResult<ClosureSolution> {
    Ok(cc.solve_from_reference(ws, q_a, guess)?)
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let cc = ClosedChain::new(&robot)?;
    let mut ws = cc.workspace();
    let qa = parse_list("qa", &a.qa)?;
    let guess = a
        .guess
        .as_deref()
        .map(|g| parse_list("guess", g))
        .transpose()?;
    let s = solve(&cc, &mut ws, &qa, guess.as_deref())?;
    let w = if a.jacobian {
        Some(cc.constraints(&mut ws, &s.q_tr)?.w)
    } else {
        None
    };
    let act = cc.actuated_joints();
    let pas = cc.passive_joints();
    let cuts: Vec<usize> = cc
        .closure()
        .loops()
        .iter()
        .map(|l| l.topology.cut)
        .collect();
    match a.format {
        Format::Json => {
            let named = |js: &[usize], v: &[f64]| -> serde_json::Map<String, serde_json::Value> {
                js.iter()
                    .zip(v)
                    .map(|(j, x)| (format!("q{j}"), json!(x)))
                    .collect()
            };
            let mut o = json!({
                "robot": robot.name(),
                "q_a": named(act, &qa),
                "q_p": named(pas, &s.q_p),
                "q_c": named(&cuts, &s.q_c),
                "residual": s.residual,
                "iterations": s.iterations,
            });
            if let Some(w) = &w {
                let rows: Vec<Vec<f64>> = (0..w.nrows())
                    .map(|r| w.row(r).iter().copied().collect())
                    .collect();
                o["W"] = json!({
                    "rows": pas.iter().map(|j| format!("q{j}")).collect::<Vec<_>>(),
                    "columns": act.iter().map(|j| format!("q{j}")).collect::<Vec<_>>(),
                    "values": rows,
                });
            }
            println!("{}", serde_json::to_string_pretty(&o)?);
        }
        Format::Text => {
            println!(
                "{}: {} loop(s), N = {} actuated, p = {} passive tree joints",
                robot.name(),
                cuts.len(),
                act.len(),
                pas.len()
            );
            let list = |js: &[usize], v: &[f64]| {
                for (j, x) in js.iter().zip(v) {
                    println!("  q{j:<3} = {x:>20.12e}");
                }
            };
            println!("actuated q_a:");
            list(act, &qa);
            println!("passive q_p:");
            list(pas, &s.q_p);
            println!("cut joints q_c:");
            list(&cuts, &s.q_c);
            println!(
                "closure residual {:.3e} after {} iteration(s)",
                s.residual, s.iterations
            );
            if let Some(w) = &w {
                let cols: Vec<String> = act
                    .iter()
                    .map(|j| format!("{:>14}", format!("q{j}")))
                    .collect();
                println!("W = d q_p / d q_a (10.30):");
                println!("       {}", cols.join(" "));
                for (r, j) in pas.iter().enumerate() {
                    let v: Vec<String> = w.row(r).iter().map(|x| format!("{x:>14.6e}")).collect();
                    println!("  {:<5}{}", format!("q{j}"), v.join(" "));
                }
            }
        }
    }
    Ok(())
}
