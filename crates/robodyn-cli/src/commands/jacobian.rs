//! `robodyn jacobian ROBOT --q ... --frame NAME [--reference ...]`: the Jacobian of a frame,
//! 6 x nv with rows [linear; angular] (Pinocchio's order; a floating base's 6 columns first), in one of the three references of
//! docs/models/kinematics.md. Closed chains: the Jacobian in the actuated coordinates
//! J_a = J_tr G on the assembly branch. `--time-variation`: J̇ at --q, --qd instead (trees).

use crate::common::{choices, format_number, write_text, CliResult, TableFormat};
use crate::kinematic_state::{
    csv_field, joint_names, rows, table_format, CsvTable, Evaluated, StateArgs,
};
use robodyn::{frame_jacobian_into, frame_jacobian_time_variation_into, Reference};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub state: StateArgs,
    /// The frame by name as the robot file gives it (URDF link or joint, `[[tool]]`, a frame
    /// number).
    #[arg(long)]
    pub frame: String,
    /// Where the Jacobian is expressed (Pinocchio's WORLD, LOCAL, LOCAL_WORLD_ALIGNED).
    #[arg(long, default_value = "local_world_aligned",
          value_parser = choices(&Reference::ALL, Reference::name, Reference::describe))]
    pub reference: Reference,
    /// Write J̇ = dJ/dt at --q and --qd (Pinocchio's getFrameJacobianTimeVariation) instead
    /// of J: J̇ qd + J qdd is the frame's classical acceleration in the reference (`fk`'s
    /// acceleration). Tree robots, fixed or floating base.
    #[arg(long)]
    pub time_variation: bool,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: a header of joint names (closed chains: the actuated joints), six rows vx vy vz wx
    /// wy wz; json: {"frame", "reference", "joints", "J"} ("dJ" with --time-variation).
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

const ROWS: [&str; 6] = ["vx", "vy", "vz", "wx", "wy", "wz"];

impl Args {
    /// The matrix written: `J`, or `dJ` with `--time-variation` (the JSON key, error names).
    fn matrix_name(&self) -> &'static str {
        if self.time_variation {
            "dJ"
        } else {
            "J"
        }
    }
}

pub fn run(a: Args) -> CliResult {
    if let Some(input) = &a.state.input {
        return table(&a, input);
    }
    let e = a.state.evaluate()?;
    let f = e.robot.frame_id(&a.frame)?;
    let (j, joints) = jacobian(&e, &f, &a)?;
    let rows = rows(&j);
    let key = a.matrix_name();
    crate::common::check_finite(key, &rows.concat())?;
    let text = match a.format {
        TableFormat::Csv => {
            let names: Vec<String> = joints.iter().map(|n| csv_field(n)).collect();
            let mut s = format!("row,{}\n", names.join(","));
            for (label, r) in ROWS.iter().zip(&rows) {
                let v: Vec<String> = r.iter().map(|x| format_number(*x)).collect();
                s += &format!("{label},{}\n", v.join(","));
            }
            s
        }
        TableFormat::Json => {
            let mut v = serde_json::json!({
                "frame": a.frame, "reference": a.reference.name(), "joints": joints,
                "q": e.q,
            });
            v[key] = serde_json::json!(rows);
            serde_json::to_string_pretty(&v)? + "\n"
        }
    };
    write_text(a.output.as_deref(), &text)
}

/// The frame's Jacobian (or J̇ with `--time-variation`) at the evaluated state and the names
/// of its columns: a closed chain's J_a = J_tr G (G at the state reached on the branch).
fn jacobian(
    e: &Evaluated,
    f: &robodyn::FrameId,
    a: &Args,
) -> CliResult<(nalgebra::DMatrix<f64>, Vec<String>)> {
    let mut j = nalgebra::DMatrix::zeros(6, e.robot.nv());
    if a.time_variation {
        if e.closed.is_some() {
            return Err(
                "--time-variation: J̇ of a closed chain's actuated coordinates is not \
                        given by the CLI (Python's ClosedChain.drift gives J̇_a qd_a)"
                    .into(),
            );
        }
        frame_jacobian_time_variation_into(&e.robot, &e.data, f, a.reference, &mut j)?;
        return Ok((j, e.robot.velocity_names()));
    }
    frame_jacobian_into(&e.robot, &e.data, f, a.reference, &mut j)?;
    Ok(match &e.closed {
        None => (j, e.robot.velocity_names()),
        Some((chain, g)) => (j * g, chain.coordinates().names().to_vec()),
    })
}

/// `--input`: six lines per state (vx .. wz), a column per joint.
fn table(a: &Args, input: &std::path::Path) -> CliResult {
    table_format(a.format)?;
    let setup = |robot: &robodyn::Robot, carried: &[String]| {
        let f = robot.frame_id(&a.frame)?;
        let names = joint_names(robot)?;
        let mut columns = vec!["component"];
        columns.extend(names.iter().map(String::as_str));
        Ok((f, CsvTable::new(carried, &columns)))
    };
    let (_, out) = a
        .state
        .each_state(input, setup, |(f, out), row, carried, e| {
            let (j, _) = jacobian(e, f, a)?;
            let key = a.matrix_name();
            for (label, r) in ROWS.iter().zip(rows(&j)) {
                crate::common::check_finite(&format!("row {row}, {key}"), &r)?;
                out.line(carried, row, &[label], &r);
            }
            Ok(())
        })?;
    write_text(a.output.as_deref(), &out.text)
}
