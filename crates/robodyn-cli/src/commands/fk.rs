//! `robodyn fk ROBOT --q ... [--frame NAME]...`: the direct geometric model, placements of
//! frames in the base frame R_0 (the world frame for a floating base), and with `--qd`/`--qdd` their velocities and classical
//! accelerations (at the frame's origin, in R_0's axes). Closed chains: `--q` holds the
//! actuated joints; the passive ones come from the assembly branch.

use crate::common::{format_number, write_text, CliResult, TableFormat};
use crate::kinematic_state::{csv_field, frames, table_format, CsvTable, StateArgs};
use robodyn::algorithms::kinematics::rpy;
use robodyn::{frame_classical_acceleration, frame_placement, frame_velocity, Reference};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub state: StateArgs,
    /// A frame by name as the robot file gives it (URDF link or joint, `[[tool]]`, a frame
    /// number); repeat for several (default: every frame name).
    #[arg(long)]
    pub frame: Vec<String>,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: one row per frame (x y z in m, roll pitch yaw in rad as URDF's rpy, then velocity
    /// and acceleration columns when --qd/--qdd are given); json: the same with the 4x4 T.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

const POSE: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];
const VELOCITY: [&str; 6] = ["vx", "vy", "vz", "wx", "wy", "wz"];
const ACCELERATION: [&str; 6] = ["ax", "ay", "az", "dwx", "dwy", "dwz"];

pub fn run(a: Args) -> CliResult {
    if let Some(input) = &a.state.input {
        return table(&a, input);
    }
    let e = a.state.evaluate()?;
    let motion = a.state.qd.is_some() || a.state.qdd.is_some();
    let lwa = Reference::LocalWorldAligned;
    let mut rows = Vec::new();
    for (name, f) in frames(&e.robot, &a.frame)? {
        let t = frame_placement(&e.robot, &e.data, &f)?;
        let mut values: Vec<f64> = t.pos.iter().copied().chain(rpy(&t.rot)).collect();
        if motion {
            let v = frame_velocity(&e.robot, &e.data, &f, lwa)?;
            let acc = frame_classical_acceleration(&e.robot, &e.data, &f, lwa)?;
            values.extend(v.to_vector().iter().chain(acc.to_vector().iter()));
        }
        crate::common::check_finite(&name, &values)?;
        rows.push((name, t, values));
    }
    let mut headers: Vec<&str> = POSE.to_vec();
    if motion {
        headers.extend(VELOCITY.iter().chain(&ACCELERATION));
    }
    let text = match a.format {
        TableFormat::Csv => {
            let mut s = format!("frame,{}\n", headers.join(","));
            for (name, _, values) in &rows {
                let v: Vec<String> = values.iter().map(|x| format_number(*x)).collect();
                s += &format!("{},{}\n", csv_field(name), v.join(","));
            }
            s
        }
        TableFormat::Json => {
            let items: Vec<_> = rows
                .iter()
                .map(|(name, t, values)| {
                    let mut o = serde_json::Map::new();
                    o.insert("frame".into(), name.as_str().into());
                    let m = t.matrix();
                    let m: Vec<Vec<f64>> =
                        (0..4).map(|i| m.row(i).iter().copied().collect()).collect();
                    o.insert("T".into(), serde_json::json!(m));
                    for (h, x) in headers.iter().zip(values) {
                        o.insert((*h).into(), serde_json::json!(x));
                    }
                    serde_json::Value::Object(o)
                })
                .collect();
            serde_json::to_string_pretty(&items)? + "\n"
        }
    };
    write_text(a.output.as_deref(), &text)
}

/// `--input`: a line per state and frame, the pose, velocity and classical acceleration columns
/// (zero velocities for a table without qd columns).
fn table(a: &Args, input: &std::path::Path) -> CliResult {
    table_format(a.format)?;
    let lwa = Reference::LocalWorldAligned;
    let columns: Vec<&str> = ["frame"]
        .iter()
        .chain(&POSE)
        .chain(&VELOCITY)
        .chain(&ACCELERATION)
        .copied()
        .collect();
    let setup = |robot: &robodyn::Robot, carried: &[String]| {
        Ok((frames(robot, &a.frame)?, CsvTable::new(carried, &columns)))
    };
    let (_, out) = a
        .state
        .each_state(input, setup, |(fr, out), row, carried, e| {
            for (name, f) in fr.iter() {
                let t = frame_placement(&e.robot, &e.data, f)?;
                let v = frame_velocity(&e.robot, &e.data, f, lwa)?;
                let acc = frame_classical_acceleration(&e.robot, &e.data, f, lwa)?;
                let values: Vec<f64> = (t.pos.iter().copied().chain(rpy(&t.rot)))
                    .chain(v.to_vector().iter().copied())
                    .chain(acc.to_vector().iter().copied())
                    .collect();
                crate::common::check_finite(&format!("row {row}, {name}"), &values)?;
                out.line(carried, row, &[name.as_str()], &values);
            }
            Ok(())
        })?;
    write_text(a.output.as_deref(), &out.text)
}
