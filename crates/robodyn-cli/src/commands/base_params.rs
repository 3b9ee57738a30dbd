//! `robodyn base-params ROBOT`: base inertial parameters by the symbolic rules, the numerical
//! method or both (§10.2.4, §10.3.4–10.3.6), as a table like Table 10.2 with the grouping
//! equations and the values for the robot's numbers.

use crate::common::{choices, CliResult, RobotArgs};
use robodyn::algorithms::base_parameters::{
    base_robot, compare_methods, generic_values_note, geometry_robot, numeric_base_parameters_auto,
    standard_values, symbolic_base_parameters, NumericOptions, ParameterNames, Summary,
};
use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode, ZeroParameters};
use robodyn::report::base_parameters as write;
use std::path::PathBuf;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Grouping rules on the robot's symbols (§10.3): equations in its symbols.
    Symbolic,
    /// Stacked regressor of random states, QR: works for any robot, numeric coefficients.
    Numeric,
    /// The symbolic output, checked against the numerical count and set.
    Both,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Text: the table (like Table 10.2), the lists, the grouping equations, the values.
    Text,
    /// A LaTeX fragment (amsmath): tabular, legend, align* equations, values.
    Latex,
    /// JSON for programs.
    Json,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// symbolic (rules, equations in the robot's symbols), numeric (stacked regressor, QR) or
    /// both (symbolic output, checked against the numerical count and set).
    #[arg(long, value_enum, default_value = "both")]
    pub method: Method,
    /// Output format.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
    /// Leave out the Coulomb and viscous friction parameters FS, FV.
    #[arg(long)]
    pub no_friction: bool,
    /// Which rotor inertias IA are parameters.
    #[arg(long, default_value = "actuated", value_parser = choices(&RotorMode::ALL, RotorMode::name, RotorMode::describe))]
    pub rotor: RotorMode,
    /// Seed of the random samples of the numerical method.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// What a parameter written as a literal 0 means (default: absent for a SYMORO .par, as in
    /// SYMORO; value for .toml and .urdf).
    #[arg(long, value_parser = choices(&ZeroParameters::ALL, ZeroParameters::name, ZeroParameters::describe))]
    pub zeros: Option<ZeroParameters>,
    /// Write a base robot (.toml) whose parameters are the grouped values.
    #[arg(long, value_name = "FILE.toml")]
    pub write_robot: Option<PathBuf>,
}

impl Args {
    /// The friction parameters `--no-friction` selects.
    fn friction(&self) -> Friction {
        if self.no_friction {
            Friction::None
        } else {
            Friction::Actuated
        }
    }
}

pub fn run(a: Args) -> CliResult {
    let (desc, _) = a.robot.description()?;
    desc.require_no_motor_drive_parameters("base-params")?;
    let rotor = a.rotor;
    let zeros = a
        .zeros
        .unwrap_or_else(|| ZeroParameters::for_path(&a.robot.robot));
    let sel = ParameterSelection::from_description(&desc, rotor, a.friction())
        .with_zero_parameters(&desc, zeros);
    let names = ParameterNames::of(&desc);
    let symbolic = match a.method {
        Method::Symbolic | Method::Both => Some(symbolic_base_parameters(&desc, &sel)?),
        Method::Numeric => None,
    };
    let numeric = match a.method {
        Method::Numeric | Method::Both => {
            // the geometry, with generic values for symbols without value
            let (robot, generic) = geometry_robot(&desc)?;
            let opt = NumericOptions {
                selection: sel.clone(),
                samples: None,
                seed: a.seed,
            };
            let (nb, start) = numeric_base_parameters_auto(&robot, &opt)?;
            let mut notes = Vec::new();
            if let Some(start) = start {
                notes.push(format!("closed chain: {}", start.describe()));
            }
            if let Some(note) = generic_values_note(&generic) {
                notes.push(format!("{note} (give values with --set)"));
            }
            Some((nb, notes))
        }
        Method::Symbolic => None,
    };
    let values = standard_values(&desc);
    let mut report = match (&symbolic, &numeric) {
        (Some(sb), _) => Summary::from_symbolic(&desc, sb, &names),
        (None, Some((nb, _))) => Summary::from_numeric(&desc, nb, &names, &values),
        _ => unreachable!("a method is chosen"),
    };
    if let Some((nb, notes)) = &numeric {
        report.notes.extend(notes.iter().cloned());
        if let Some(sb) = &symbolic {
            report.add_comparison(&compare_methods(sb, nb, &names));
        }
    }
    if !report.has_values() {
        let missing: Vec<String> = desc
            .links
            .iter()
            .chain(&desc.floating_base)
            .flat_map(|l| l.params.iter())
            .zip(&values)
            .filter(|(_, v)| v.is_none())
            .flat_map(|(e, _)| e.symbols())
            .filter(|s| !desc.symbols.contains_key(s))
            .take(6)
            .collect();
        if !missing.is_empty() {
            report.notes.push(format!(
                "values left out where a parameter has no numeric value ({}{})",
                missing.join(", "),
                if missing.len() == 6 { ", ..." } else { "" }
            ));
        }
    }
    // the base robot first: an error (a value missing, a missing directory) before any output
    let robot_file = match &a.write_robot {
        Some(path) => Some((path, base_robot_file(&desc, &report, path)?)),
        None => None,
    };
    crate::common::print_out(&match a.format {
        Format::Text => write::text(&report),
        Format::Latex => write::latex(&report),
        Format::Json => format!("{}\n", serde_json::to_string_pretty(&write::json(&report))?),
    })?;
    if let Some((path, file)) = robot_file {
        file.commit()?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// `--write-robot`: the base robot (its parameters the grouped values), written into an
/// [`Output`](crate::output::Output) to be committed after the report.
fn base_robot_file(
    desc: &robodyn::model::RobotDescription,
    report: &robodyn::algorithms::base_parameters::summary::Summary,
    path: &std::path::Path,
) -> CliResult<crate::output::Output> {
    let values: Vec<f64> = report
        .base
        .iter()
        .map(|b| {
            b.value.ok_or_else(|| {
                format!(
                    "--write-robot: {} has no numeric value (give every symbol a value)",
                    b.name
                )
            })
        })
        .collect::<Result<_, _>>()?;
    let base: Vec<usize> = report.base.iter().map(|b| b.index).collect();
    let out = base_robot(desc, &base, &values)?;
    let format = robodyn::io::Format::from_path(path)?;
    let mut file = crate::output::Output::create(Some(path))?;
    file.write_all(robodyn::io::description_text(&out, format)?.as_bytes())?;
    Ok(file)
}
