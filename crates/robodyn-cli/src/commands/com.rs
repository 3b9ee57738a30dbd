//! `robodyn com ROBOT --q ... [--qd ...] [--qdd ...] [--frame NAME] [--jacobian]`: the centre
//! of mass of the robot (or of the subtree carried by a frame) in R_0, its velocity and
//! acceleration, the mass, and with `--jacobian` its 3 x N Jacobian. Closed chains: the
//! state completed on the assembly branch; the Jacobian over the actuated joints (J G).

use crate::common::{format_number, write_text, CliResult, TableFormat};
use crate::kinematic_state::{rows, StateArgs};
use robodyn::algorithms::kinematics::{center_of_mass, center_of_mass_jacobian_into};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub state: StateArgs,
    /// The subtree carried by this frame (its link and every link after it); default the
    /// whole robot.
    #[arg(long)]
    pub frame: Option<String>,
    /// Also the Jacobian of the centre of mass (3 x N).
    #[arg(long)]
    pub jacobian: bool,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: one row (mass, x y z, vx vy vz, ax ay az), then with --jacobian a blank line and
    /// the Jacobian (rows x y z, a column per joint); json: the same as named fields.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

const HEADERS: [&str; 10] = ["mass", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"];

pub fn run(a: Args) -> CliResult {
    let mut e = a.state.evaluate()?;
    let root = a
        .frame
        .as_deref()
        .map(|n| e.robot.frame_id(n))
        .transpose()?;
    let c = center_of_mass(&e.robot, &mut e.data, root.as_ref())?;
    let mut values = vec![c.mass];
    values.extend(c.position.iter().chain(&c.velocity).chain(&c.acceleration));
    crate::common::check_finite("centre of mass", &values)?;
    let jacobian = if a.jacobian {
        let mut j = nalgebra::DMatrix::zeros(3, e.robot.dof());
        center_of_mass_jacobian_into(&e.robot, &mut e.data, root.as_ref(), &mut j)?;
        Some(match &e.closed {
            None => (j, e.robot.coordinates().names().to_vec()),
            Some((chain, g)) => (j * g, chain.coordinates().names().to_vec()),
        })
    } else {
        None
    };
    let text = match a.format {
        TableFormat::Csv => {
            let v: Vec<String> = values.iter().map(|x| format_number(*x)).collect();
            let mut s = format!("{}\n{}\n", HEADERS.join(","), v.join(","));
            if let Some((j, joints)) = &jacobian {
                let names: Vec<String> = joints
                    .iter()
                    .map(|n| crate::commands::fk::csv_field(n))
                    .collect();
                s += &format!("\nrow,{}\n", names.join(","));
                for (label, r) in ["x", "y", "z"].iter().zip(rows(j)) {
                    let v: Vec<String> = r.iter().map(|x| format_number(*x)).collect();
                    s += &format!("{label},{}\n", v.join(","));
                }
            }
            s
        }
        TableFormat::Json => {
            let mut o = serde_json::Map::new();
            for (h, x) in HEADERS.iter().zip(&values) {
                o.insert((*h).into(), serde_json::json!(x));
            }
            if let Some((j, joints)) = &jacobian {
                o.insert("joints".into(), serde_json::json!(joints));
                o.insert("J".into(), serde_json::json!(rows(j)));
            }
            serde_json::to_string_pretty(&serde_json::Value::Object(o))? + "\n"
        }
    };
    write_text(a.output.as_deref(), &text)
}
