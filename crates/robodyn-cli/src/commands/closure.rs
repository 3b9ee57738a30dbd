//! `robodyn closure ROBOT --qa ...`: loop closure of a closed-chain robot: the passive tree
//! variables q_p (and the cut-joint variables) for given actuated variables q_a, and with
//! `--jacobian` W = d q_p / d q_a (10.30).

use crate::common::{
    conditioning_json, format_number, parse_list, print_out, start_branch, warn_conditioning,
    CliResult, Names, NamesArg, RobotArgs,
};
use robodyn::report::Sig;
use robodyn::{loop_closure, ClosedChain};
use serde_json::json;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Actuated joint values q_a, comma separated, in joint order (see `robodyn info`).
    #[arg(long, allow_hyphen_values = true)]
    pub qa: String,
    /// Guess of q_p (passive tree joints in joint order) at the given q_a, which then picks the
    /// assembly branch; default: continuation from the robot's `assembly` configuration (else
    /// q = 0) along the straight path in q_a, on its branch.
    #[arg(long, allow_hyphen_values = true)]
    pub guess: Option<String>,
    /// Also print W = d q_p / d q_a.
    #[arg(long)]
    pub jacobian: bool,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
    #[command(flatten)]
    pub names: NamesArg,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Text for reading.
    Text,
    /// JSON for programs (every number a full double).
    Json,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    let cc = ClosedChain::new(&robot)?;
    let qa = parse_list("qa", &a.qa)?;
    let mut branch = start_branch(&cc, &qa, a.guess.as_deref())?;
    let s = loop_closure(&cc, &mut branch, &qa)?;
    warn_conditioning(&cc, None, &s.conditioning);
    let w = a.jacobian.then(|| s.w.clone());
    let act = cc.coordinates().frames();
    let pas = cc.passive_coordinates().frames();
    let cuts: Vec<usize> = cc.loops().iter().map(|l| l.topology.cut).collect();
    let (q_p, q_c) = (s.q_p.as_slice(), s.q_c.as_slice());
    // the variable of tree frame j: `q<j>`, or `q_<joint name>` with --names joint
    // (cut frames included: the joint name of frame j, as in the coordinate map)
    let var = |j: &usize| match a.names.names {
        Names::Joint => format!("q_{}", robot.description().frame(*j).name),
        Names::Frame => format!("q{j}"),
    };
    let mut out = String::new();
    match a.format {
        Format::Json => {
            let named = |js: &[usize], v: &[f64]| -> serde_json::Map<String, serde_json::Value> {
                js.iter().zip(v).map(|(j, x)| (var(j), json!(x))).collect()
            };
            let mut o = json!({
                "robot": robot.name(),
                "q_a": named(act, &qa),
                "q_p": named(pas, q_p),
                "q_c": named(&cuts, q_c),
                "residual": s.residual,
            });
            for (k, v) in conditioning_json(&s.conditioning) {
                o[k] = v;
            }
            if let Some(w) = &w {
                let rows: Vec<Vec<f64>> = (0..w.nrows())
                    .map(|r| w.row(r).iter().copied().collect())
                    .collect();
                o["W"] = json!({
                    "rows": pas.iter().map(var).collect::<Vec<_>>(),
                    "columns": act.iter().map(var).collect::<Vec<_>>(),
                    "values": rows,
                });
            }
            outln!(out, "{}", serde_json::to_string_pretty(&o)?);
        }
        Format::Text => {
            outln!(
                out,
                "{}: {} loop(s), N = {} actuated, p = {} passive tree joints",
                robot.name(),
                cuts.len(),
                act.len(),
                pas.len()
            );
            let list = |out: &mut String, js: &[usize], v: &[f64]| {
                for (j, x) in js.iter().zip(v) {
                    outln!(out, "  {:<4} = {:>24}", var(j), format_number(*x));
                }
            };
            outln!(out, "actuated q_a:");
            list(&mut out, act, &qa);
            outln!(out, "passive q_p:");
            list(&mut out, pas, q_p);
            outln!(out, "cut joints q_c:");
            list(&mut out, &cuts, q_c);
            outln!(
                out,
                "closure residual {}; {}",
                Sig(s.residual, 3),
                s.conditioning.describe(cc.limits())
            );
            if let Some(w) = &w {
                let cols: Vec<String> = act.iter().map(|j| format!("{:>14}", var(j))).collect();
                outln!(out, "W = d q_p / d q_a (10.30):");
                outln!(out, "       {}", cols.join(" "));
                for (r, j) in pas.iter().enumerate() {
                    let v: Vec<String> = w
                        .row(r)
                        .iter()
                        .map(|&x| format!("{:>14}", Sig(x, 6).to_string()))
                        .collect();
                    outln!(out, "  {:<5}{}", var(j), v.join(" "));
                }
            }
        }
    }
    print_out(&out)
}
