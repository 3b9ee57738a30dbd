//! `robodyn ik ROBOT --frame NAME --pose ...`: the inverse geometric model in closed form
//! (Paul's method, docs/models/inverse_geometry.md): every joint solution placing the frame at
//! the target, each flagged within/outside the joint limits and with its singular cases.

use crate::common::{format_number, parse_list, write_text, CliResult, TableFormat};
use nalgebra::{Matrix4, Rotation3, Vector3};
use robodyn::algorithms::inverse_geometry::{ClosedFormIgm, IgmSolution};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: crate::common::RobotArgs,
    /// The frame to place, by name as the robot file gives it (a link or joint frame of the
    /// chain, or a `[[tool]]` fixed on it; default: the last frame).
    #[arg(long)]
    pub frame: Option<String>,
    /// The target placement of the frame in R_0: `x,y,z,roll,pitch,yaw` (m, rad; URDF's rpy)
    /// or the 16 entries of the 4x4 matrix row by row.
    #[arg(long, allow_hyphen_values = true)]
    pub pose: String,
    /// The numeric inverse geometric model (Levenberg-Marquardt on the placement error, joint
    /// limits kept, seeded restarts) instead of the closed form: any robot and frame; one row
    /// with the joint values, whether it converged and the residual.
    #[arg(long)]
    pub numeric: bool,
    /// --numeric: the first start, all movable joints (default zeros; then random starts
    /// within the limits until one converges).
    #[arg(long, allow_hyphen_values = true, requires = "numeric")]
    pub q0: Option<String>,
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// csv: one row per solution (a column per joint of the chain, then within_limits and
    /// singular); json: a list of {"q", "within_limits", "singular"}.
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

pub fn run(a: Args) -> CliResult {
    let robot = a.robot.load()?;
    if a.numeric {
        return numeric(&a, &robot);
    }
    let igm = match &a.frame {
        None => ClosedFormIgm::new(&robot)?,
        Some(name) => {
            let f = robot.frame_id(name)?;
            let igm = ClosedFormIgm::for_frame(&robot, f.parent())?;
            igm.with_tool(&f.offset().matrix())?
        }
    };
    let target = pose(&a.pose)?;
    let solutions = igm.solve(&target)?;
    if solutions.is_empty() {
        eprintln!(
            "robodyn: the target is out of reach of the {}: no solution",
            igm.class().name()
        );
    }
    let names = robot.coordinates().names();
    let joints: Vec<&str> = igm.joints().iter().map(|&k| names[k].as_str()).collect();
    let text = match a.format {
        TableFormat::Csv => {
            let h: Vec<String> = joints
                .iter()
                .map(|n| crate::kinematic_state::csv_field(n))
                .collect();
            let mut s = format!("{},within_limits,singular\n", h.join(","));
            for sol in solutions.as_slice() {
                let v: Vec<String> = sol.q.iter().map(|x| format_number(*x)).collect();
                s += &format!("{},{},{}\n", v.join(","), sol.within_limits, singular(sol));
            }
            s
        }
        TableFormat::Json => {
            let items: Vec<_> = solutions
                .as_slice()
                .iter()
                .map(|sol| {
                    serde_json::json!({"q": sol.q, "within_limits": sol.within_limits,
                                       "singular": singular(sol)})
                })
                .collect();
            let v = serde_json::json!({"class": igm.class().name(), "joints": joints,
                                       "solutions": items});
            serde_json::to_string_pretty(&v)? + "\n"
        }
    };
    write_text(a.output.as_deref(), &text)
}

/// `--numeric`: one row, the movable joints, `converged`, the position (m) and rotation (rad)
/// errors, the steps and the starts used.
fn numeric(a: &Args, robot: &robodyn::Robot) -> CliResult {
    use robodyn::algorithms::inverse_geometry::{NumericIgm, NumericOptions};
    let frame = match &a.frame {
        Some(name) => robot.frame_id(name)?,
        None => robot.frame_id_of(robot.nf())?,
    };
    let start = match &a.q0 {
        Some(s) => parse_list("q0", s)?,
        None => vec![0.0; robot.dof()],
    };
    let igm = NumericIgm::new(robot, frame, NumericOptions::default())?;
    let s = igm.solve(robot, &pose(&a.pose)?, &start)?;
    if !s.converged {
        eprintln!(
            "robodyn: warning: no start converged ({} starts): the closest joint values are \
             written, {:e} m and {:e} rad from the target",
            s.starts, s.position_error, s.rotation_error
        );
    }
    let names = robot.coordinates().names();
    let text = match a.format {
        TableFormat::Csv => {
            let h: Vec<String> = names
                .iter()
                .map(|n| crate::kinematic_state::csv_field(n))
                .collect();
            let v: Vec<String> = s.q.iter().map(|x| format_number(*x)).collect();
            format!(
                "{},converged,position_error,rotation_error,iterations,starts\n{},{},{},{},{},{}\n",
                h.join(","),
                v.join(","),
                s.converged,
                format_number(s.position_error),
                format_number(s.rotation_error),
                s.iterations,
                s.starts
            )
        }
        TableFormat::Json => {
            let v = serde_json::json!({"joints": names, "q": s.q, "converged": s.converged,
                "position_error": s.position_error, "rotation_error": s.rotation_error,
                "iterations": s.iterations, "starts": s.starts});
            serde_json::to_string_pretty(&v)? + "\n"
        }
    };
    write_text(a.output.as_deref(), &text)
}

/// The singular cases of a solution, `-` when none (`shoulder+wrist`, ...).
fn singular(s: &IgmSolution) -> String {
    let c = s.singular;
    let names: Vec<&str> = [
        (c.shoulder, "shoulder"),
        (c.elbow, "elbow"),
        (c.wrist, "wrist"),
    ]
    .iter()
    .filter(|(on, _)| *on)
    .map(|(_, n)| *n)
    .collect();
    if names.is_empty() {
        "-".into()
    } else {
        names.join("+")
    }
}

/// `--pose`: six numbers (position, URDF rpy) or sixteen (the matrix row by row).
fn pose(s: &str) -> CliResult<Matrix4<f64>> {
    let v = parse_list("pose", s)?;
    match v.len() {
        6 => {
            let rot = Rotation3::from_euler_angles(v[3], v[4], v[5]);
            let mut m = Matrix4::identity();
            m.fixed_view_mut::<3, 3>(0, 0).copy_from(rot.matrix());
            m.fixed_view_mut::<3, 1>(0, 3).copy_from(&Vector3::new(v[0], v[1], v[2]));
            Ok(m)
        }
        16 => Ok(Matrix4::from_row_slice(&v)),
        n => Err(format!(
            "--pose has {n} numbers: give x,y,z,roll,pitch,yaw (6) or the 4x4 matrix row by row (16)"
        )
        .into()),
    }
}
