//! `robodyn info ROBOT`: frames table, structure type, branches, loops, actuated/passive joints.

use crate::common::CliResult;
use robodyn::model::{
    validate_structure, RobotDescription, GEOMETRIC_PARAMETERS, STANDARD_PARAMETERS,
};
use robodyn::report::number::{format_number, significant, vector, Sig};
use serde_json::json;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Robot file (.toml, .par or .urdf).
    pub robot: PathBuf,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
    /// Make a URDF's root link the floating base (link 0 of a free-flyer root), as the model
    /// commands' `--floating` does. A .toml or .par file says it itself.
    #[arg(long)]
    pub floating: bool,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Format {
    /// Text for reading.
    Text,
    /// JSON for programs (every number a full double).
    Json,
}

pub fn run(a: Args) -> CliResult {
    let options = if a.floating {
        robodyn::io::LoadOptions::floating()
    } else {
        robodyn::io::LoadOptions::default()
    };
    let (desc, map) =
        robodyn::io::load_description_with_options(&a.robot, &Default::default(), &options)?;
    let s = validate_structure(&desc)?;
    crate::common::print_warnings(&map);
    let text = match a.format {
        Format::Json => format!("{}\n", serde_json::to_string_pretty(&to_json(&desc, &s))?),
        Format::Text => text(&desc, &s),
    };
    crate::common::print_out(&text)
}

fn joint_kind(d: &RobotDescription, j: usize) -> &'static str {
    let f = d.frame(j);
    match f.joint.sigma() {
        0 => "revolute",
        1 => "prismatic",
        _ => "fixed",
    }
}

fn to_json(d: &RobotDescription, s: &robodyn::model::Structure) -> serde_json::Value {
    let frames: Vec<_> = d
        .frames
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let mut o = json!({
                "j": i + 1,
                "name": f.name,
                "ant": f.ant,
                "sigma": f.joint.sigma(),
                "mu": u8::from(f.actuated),
                "type": joint_kind(d, i + 1),
                "role": role(d, i + 1),
            });
            for (k, e) in f.geometric().iter().enumerate() {
                o[GEOMETRIC_PARAMETERS[k]] = json!(e.decimal().to_string());
            }
            o
        })
        .collect();
    let links: Vec<_> = d
        .links
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let mut o = json!({ "j": i + 1, "name": l.name });
            for (k, e) in l.params.iter().enumerate() {
                o[STANDARD_PARAMETERS[k]] = json!(e.decimal().to_string());
            }
            for (k, e) in l.wrench.iter().enumerate() {
                o[robodyn::model::WRENCH_COMPONENTS[k]] = json!(e.decimal().to_string());
            }
            o
        })
        .collect();
    json!({
        "name": d.name,
        "structure": s.kind,
        "nl": d.nl,
        "nj": d.nj,
        "nf": d.nf(),
        "gravity": d.gravity.iter().map(|e| e.decimal().to_string()).collect::<Vec<_>>(),
        "base": base_kind(d),
        "symbols": d.symbols,
        "frames": frames,
        "links": links,
        "main_branches": s.main_branches,
        "loops": s.loops,
        "actuated": (1..=d.nl).filter(|&j| d.frame(j).actuated).collect::<Vec<_>>(),
        "passive": (1..=d.nl).filter(|&j| !d.frame(j).actuated && d.frame(j).joint.is_movable()).collect::<Vec<_>>(),
        "notes": d.notes,
        "assembly": d.assembly,
        "start": assembly_note(d, s),
    })
}

/// Issue 12.2: what a closed robot's loop closure starts from: its `assembly`, or, without one,
/// q = 0 when the loops close there with Wp regular, else how to give one. `None` for a tree.
fn assembly_note(d: &RobotDescription, s: &robodyn::model::Structure) -> Option<String> {
    if s.loops.is_empty() {
        return None;
    }
    if let Some(a) = &d.assembly {
        let q: Vec<String> = a.iter().map(|&x| format_number(x)).collect();
        return Some(format!(
            "assembly (start of loop closure): q = [{}]",
            q.join(", ")
        ));
    }
    const HOW: &str = "give one: `assembly = [..]` in a .toml, or in a .par the comment \
        `(* robodyn assembly (joint values where the loops close): 1 = ..; 2 = .. *)` \
        (docs/robot-format.md), or a start with --guess";
    let start = robodyn::Robot::new(d.clone())
        .and_then(|r| robodyn::ClosedChain::new(&r)?.assembly_branch());
    Some(match start {
        Ok(b) => {
            format!(
                "assembly: none; the start is q_a = 0, where the loops close (q_p = {}) with Wp \
                 regular (reciprocal condition number {}): results follow that branch; if it is \
                 not the intended one, {HOW}",
                vector(b.q_p(), 6),
                Sig(b.rcond(), 2)
            )
        }
        Err(robodyn::Error::SingularStart { rcond, .. }) => format!(
            "assembly: none, and q = 0 is singular (Wp reciprocal condition number {}): \
             closed-chain evaluation refuses to start there; {HOW}",
            Sig(rcond, 2)
        ),
        Err(e) => format!("assembly: none, and q = 0 cannot serve as the start ({e}); {HOW}"),
    })
}

fn role(d: &RobotDescription, j: usize) -> &'static str {
    if j <= d.nl {
        "tree"
    } else if j <= d.nj {
        "cut joint"
    } else {
        "cut-joint twin"
    }
}

/// `fixed`, `mobile` (its motion imposed) or `floating` (its motion from the dynamics).
fn base_kind(d: &RobotDescription) -> &'static str {
    if d.floating_base.is_some() {
        "floating"
    } else if d.mobile_base {
        "mobile"
    } else {
        "fixed"
    }
}

/// The base line of the text report: its kind, and for a floating base the state layout and
/// link 0's mass.
fn base_text(d: &RobotDescription) -> String {
    match &d.floating_base {
        Some(l) => format!(
            "floating (link 0 `{}`, M0 = {}; q = [x, y, z, qx, qy, qz, qw, joints], v = [base \
             linear and angular velocity in R_0, joint rates]: docs/models/floating_base.md)",
            l.name,
            expr(&l.params[robodyn::model::param::M])
        ),
        None if d.mobile_base => "mobile (W0, WP0, V0, VP0 imposed)".into(),
        None => "fixed".into(),
    }
}

fn text(d: &RobotDescription, s: &robodyn::model::Structure) -> String {
    let mut out = String::new();
    outln!(
        out,
        "{}: {} structure, NL = {}, NJ = {}, NF = {}",
        d.name,
        s.kind,
        d.nl,
        d.nj,
        d.nf()
    );
    for n in &d.notes {
        outln!(out, "  note: {n}");
    }
    let g: Vec<String> = d.gravity.iter().map(expr).collect();
    outln!(out, "gravity: [{}]", g.join(", "));
    outln!(out, "base: {}", base_text(d));
    outln!(out);
    print_rows(&mut out, &frame_rows(d));
    outln!(out);
    outln!(out, "main branches:");
    for b in &s.main_branches {
        let p: Vec<String> = b.iter().map(|x| x.to_string()).collect();
        outln!(out, "  0 - {}", p.join(" - "));
    }
    if s.loops.is_empty() {
        outln!(out, "loops: none");
    } else {
        outln!(out, "loops:");
        for (l, lp) in s.loops.iter().enumerate() {
            outln!(out,
                "  loop {}: cut joint {} joins link {} and link {} (twin frame {}), root {}, branches {:?} / {:?}",
                l + 1, lp.cut, lp.link_i, lp.link_j, lp.twin, lp.root, lp.branch_i, lp.branch_j
            );
        }
    }
    if let Some(note) = assembly_note(d, s) {
        outln!(out, "{note}");
    }
    let act: Vec<String> = (1..=d.nl)
        .filter(|&j| d.frame(j).actuated)
        .map(|j| j.to_string())
        .collect();
    let pas: Vec<String> = (1..=d.nl)
        .filter(|&j| !d.frame(j).actuated && d.frame(j).joint.is_movable())
        .map(|j| j.to_string())
        .collect();
    outln!(
        out,
        "actuated joints: {}",
        if act.is_empty() {
            "none".into()
        } else {
            act.join(", ")
        }
    );
    outln!(
        out,
        "passive tree joints: {}",
        if pas.is_empty() {
            "none".into()
        } else {
            pas.join(", ")
        }
    );
    limits_text(&mut out, d);
    out
}

/// The frames table: one row per frame (its geometric parameters, the joint variable added
/// to theta or r) under a header row.
fn frame_rows(d: &RobotDescription) -> Vec<Vec<String>> {
    let mut rows = vec![[
        "j", "name", "a(j)", "sigma", "mu", "gamma", "b", "alpha", "d", "theta", "r", "role",
    ]
    .map(String::from)
    .to_vec()];
    for (i, f) in d.frames.iter().enumerate() {
        let mut r = vec![
            (i + 1).to_string(),
            f.name.clone(),
            f.ant.to_string(),
            f.joint.sigma().to_string(),
            u8::from(f.actuated).to_string(),
        ];
        for (k, e) in f.geometric().iter().enumerate() {
            let var = match (k, f.joint.sigma(), i < d.nj) {
                (4, 0, true) => Some(format!("th{}", i + 1)),
                (5, 1, true) => Some(format!("r{}", i + 1)),
                _ => None,
            };
            r.push(match var {
                Some(v) if e.is_zero() => v,
                Some(v) if expr(e) == e.decimal().to_string() => (robodyn::Expr::symbol(v)
                    + (*e).clone())
                .decimal()
                .to_string(),
                Some(v) => format!("{v} + {}", expr(e)).replace("+ -", "- "),
                None => expr(e),
            });
        }
        r.push(role(d, i + 1).into());
        rows.push(r);
    }
    rows
}

/// The joint limits of the robot file, if any.
fn limits_text(out: &mut String, d: &RobotDescription) {
    if !d.limits.is_empty() {
        outln!(*out);
        outln!(*out, "joint limits (rad, rad/s, rad/s^2, N m for revolute joints; m, m/s, m/s^2, N for prismatic):");
        for (j, l) in &d.limits {
            let mut parts = Vec::new();
            if let (Some(a), Some(b)) = (l.q_min, l.q_max) {
                parts.push(format!("q in [{}, {}]", short(a), short(b)));
            }
            for (name, v) in [("|qd|", l.qd), ("|qdd|", l.qdd), ("|tau|", l.tau)] {
                if let Some(v) = v {
                    parts.push(format!("{name} <= {}", short(v)));
                }
            }
            outln!(*out, "  {j} ({}): {}", d.frame(*j).name, parts.join(", "));
        }
    }
}

/// A number for reading: 12 significant digits, so that float noise of an import
/// (`0.22094100000000003`) reads `0.220941` (the report form of `robodyn::report::number`).
fn short(x: f64) -> String {
    significant(x, 12)
}

/// An expression for reading: a float (`0.22094100000000003`) by [`short`], a rational by its
/// exact decimal (`-9.81`) or, without one, as written (`1/3`), an expression with symbols or
/// constants such as `pi/2` as written.
fn expr(e: &robodyn::Expr) -> String {
    let s = e.decimal().to_string();
    if s.bytes()
        .any(|b| (b.is_ascii_alphabetic() && b != b'e') || b == b'/')
    {
        return s;
    }
    match e.eval(&|_| None) {
        Ok(x) => short(x),
        Err(_) => s,
    }
}

fn print_rows(out: &mut String, rows: &[Vec<String>]) {
    let n = rows[0].len();
    let w: Vec<usize> = (0..n)
        .map(|c| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0))
        .collect();
    for r in rows {
        let line: Vec<String> = r
            .iter()
            .enumerate()
            .map(|(c, x)| format!("{x:<width$}", width = w[c]))
            .collect();
        outln!(out, "{}", line.join("  ").trim_end());
    }
}
