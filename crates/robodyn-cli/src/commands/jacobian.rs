//! `robodyn jacobian ROBOT --q ... --frame NAME [--reference ...]`: the Jacobian of a frame,
//! 6 x N with rows [linear; angular] (Pinocchio's order), in one of the three references of
//! docs/models/kinematics.md. Closed chains: the Jacobian in the actuated coordinates
//! J_a = J_tr G on the assembly branch.

use crate::common::{choices, format_number, write_text, CliResult, TableFormat};
use crate::kinematic_state::{rows, StateArgs};
use robodyn::{frame_jacobian_into, Reference};
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
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: a header of joint names (closed chains: the actuated joints), six rows vx vy vz wx
    /// wy wz; json: {"frame", "reference", "joints", "J"}.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

const ROWS: [&str; 6] = ["vx", "vy", "vz", "wx", "wy", "wz"];

pub fn run(a: Args) -> CliResult {
    let e = a.state.evaluate()?;
    let f = e.robot.frame_id(&a.frame)?;
    let mut j = nalgebra::DMatrix::zeros(6, e.robot.dof());
    frame_jacobian_into(&e.robot, &e.data, &f, a.reference, &mut j)?;
    // closed chains: J_a = J_tr G at the state evaluate() reached on the branch
    let (j, joints) = match &e.closed {
        None => (j, e.robot.coordinates().names().to_vec()),
        Some((chain, g)) => (j * g, chain.coordinates().names().to_vec()),
    };
    let rows = rows(&j);
    crate::common::check_finite("J", &rows.concat())?;
    let text = match a.format {
        TableFormat::Csv => {
            let names: Vec<String> = joints
                .iter()
                .map(|n| crate::commands::fk::csv_field(n))
                .collect();
            let mut s = format!("row,{}\n", names.join(","));
            for (label, r) in ROWS.iter().zip(&rows) {
                let v: Vec<String> = r.iter().map(|x| format_number(*x)).collect();
                s += &format!("{label},{}\n", v.join(","));
            }
            s
        }
        TableFormat::Json => {
            let v = serde_json::json!({
                "frame": a.frame, "reference": a.reference.name(), "joints": joints,
                "q": e.q, "J": rows,
            });
            serde_json::to_string_pretty(&v)? + "\n"
        }
    };
    write_text(a.output.as_deref(), &text)
}
