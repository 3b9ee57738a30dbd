//! `robodyn com ROBOT --q ... [--qd ...] [--qdd ...] [--frame NAME] [--jacobian]`: the centre
//! of mass of the robot (or of the subtree carried by a frame) in R_0, its velocity and
//! acceleration, the mass, and with `--jacobian` its 3 x nv Jacobian (a floating base's 6
//! columns first; R_0 is then the world frame). Closed chains: the
//! state completed on the assembly branch; the Jacobian over the actuated joints (J G).

use crate::common::{format_number, write_text, CliResult, TableFormat};
use crate::kinematic_state::{
    csv_field, joint_names, rows, table_format, CsvTable, Evaluated, StateArgs,
};
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
    if let Some(input) = &a.state.input {
        return table(&a, input);
    }
    let mut e = a.state.evaluate()?;
    let root = a
        .frame
        .as_deref()
        .map(|n| e.robot.frame_id(n))
        .transpose()?;
    let (values, jacobian) = centre(&mut e, root.as_ref(), a.jacobian)?;
    let text = match a.format {
        TableFormat::Csv => {
            let v: Vec<String> = values.iter().map(|x| format_number(*x)).collect();
            let mut s = format!("{}\n{}\n", HEADERS.join(","), v.join(","));
            if let Some((j, joints)) = &jacobian {
                let names: Vec<String> = joints.iter().map(|n| csv_field(n)).collect();
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

/// The centre of mass's row (mass, position, velocity, acceleration) and, with `jacobian`, its
/// Jacobian with the names of its columns (a closed chain's J G over the actuated joints).
#[allow(clippy::type_complexity)]
fn centre(
    e: &mut Evaluated,
    root: Option<&robodyn::FrameId>,
    jacobian: bool,
) -> CliResult<(Vec<f64>, Option<(nalgebra::DMatrix<f64>, Vec<String>)>)> {
    let c = center_of_mass(&e.robot, &mut e.data, root)?;
    let mut values = vec![c.mass];
    values.extend(c.position.iter().chain(&c.velocity).chain(&c.acceleration));
    crate::common::check_finite("centre of mass", &values)?;
    if !jacobian {
        return Ok((values, None));
    }
    let mut j = nalgebra::DMatrix::zeros(3, e.robot.nv());
    center_of_mass_jacobian_into(&e.robot, &mut e.data, root, &mut j)?;
    let j = match &e.closed {
        None => (j, e.robot.velocity_names()),
        Some((chain, g)) => (j * g, chain.coordinates().names().to_vec()),
    };
    Ok((values, Some(j)))
}

/// `--input`: a line per state (the columns of one state), with --jacobian the Jacobian's
/// entries after them as columns `J<x|y|z>_<joint>`.
fn table(a: &Args, input: &std::path::Path) -> CliResult {
    table_format(a.format)?;
    let setup = |robot: &robodyn::Robot, carried: &[String]| {
        let root = a.frame.as_deref().map(|n| robot.frame_id(n)).transpose()?;
        let names = joint_names(robot)?;
        let mut columns: Vec<String> = HEADERS.iter().map(|h| h.to_string()).collect();
        if a.jacobian {
            for r in ["x", "y", "z"] {
                columns.extend(names.iter().map(|n| format!("J{r}_{n}")));
            }
        }
        let columns: Vec<&str> = columns.iter().map(String::as_str).collect();
        Ok((root, CsvTable::new(carried, &columns)))
    };
    let (_, out) = a
        .state
        .each_state(input, setup, |(root, out), row, carried, e| {
            let (mut values, j) =
                centre(e, root.as_ref(), a.jacobian).map_err(|err| format!("row {row}: {err}"))?;
            if let Some((j, _)) = j {
                values.extend(rows(&j).concat());
            }
            crate::common::check_finite(&format!("row {row}"), &values)?;
            out.line(carried, row, &[], &values);
            Ok(())
        })?;
    write_text(a.output.as_deref(), &out.text)
}
