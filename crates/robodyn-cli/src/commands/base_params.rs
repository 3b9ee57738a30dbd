//! `robodyn base-params ROBOT`: base inertial parameters by the symbolic rules, the numerical
//! method or both (§10.2.4, §10.3.4–10.3.6), as a table like Table 10.2 with the grouping
//! equations and the values for the robot's numbers.

use crate::common::{CliResult, RobotArgs};
use robodyn::algorithms::base_parameters::{
    base_robot, compare_methods, numeric_base_parameters, symbolic_base_parameters,
    ClosedChainSampler, NumericOptions, Report, TreeSampler,
};
use robodyn::algorithms::regressor::{ParameterSelection, RotorMode};
use std::path::PathBuf;

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Symbolic,
    Numeric,
    Both,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Text,
    Latex,
    Json,
}

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rotor {
    /// Rotor inertia IA_j on the actuated joints.
    Actuated,
    /// On every movable joint.
    All,
    /// No rotor inertia.
    None,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// symbolic (rules, equations in the robot's symbols), numeric (stacked regressor, QR) or
    /// both (symbolic output, checked against the numerical count and set).
    #[arg(long, value_enum, default_value = "both")]
    pub method: Method,
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
    /// Leave out the Coulomb and viscous friction parameters FS, FV.
    #[arg(long)]
    pub no_friction: bool,
    /// Which rotor inertias IA are parameters.
    #[arg(long, value_enum, default_value = "actuated")]
    pub rotor: Rotor,
    /// Seed of the random samples of the numerical method.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write a base robot (.toml) whose parameters are the grouped values.
    #[arg(long, value_name = "FILE.toml")]
    pub write_robot: Option<PathBuf>,
}

pub fn run(a: Args) -> CliResult {
    let mut desc = robodyn::io::load_description(&a.robot.robot)?;
    desc.symbols.extend(a.robot.overrides()?);
    let rotor = match a.rotor {
        Rotor::Actuated => RotorMode::Actuated,
        Rotor::All => RotorMode::All,
        Rotor::None => RotorMode::None,
    };
    let sel = ParameterSelection::from_description(&desc, rotor, !a.no_friction);
    let symbolic = match a.method {
        Method::Symbolic | Method::Both => Some(symbolic_base_parameters(&desc, &sel)?),
        Method::Numeric => None,
    };
    let numeric = match a.method {
        Method::Numeric | Method::Both => {
            let robot = robodyn::Robot::new(desc.clone())
                .map_err(|e| format!("the numerical method needs every symbol's value: {e}"))?;
            let opt = NumericOptions {
                selection: sel.clone(),
                samples: None,
                seed: a.seed,
            };
            let nb = if robot.is_tree() {
                numeric_base_parameters(&robot, &mut TreeSampler, &opt)?
            } else {
                // consistent samples by loop closure from the assembly configuration
                let mut sampler = ClosedChainSampler::new(&robot)?;
                numeric_base_parameters(&robot, &mut sampler, &opt)?
            };
            Some((robot, nb))
        }
        Method::Symbolic => None,
    };
    let mut report = match (&symbolic, &numeric) {
        (Some(sb), _) => Report::from_symbolic(&desc, sb),
        (None, Some((robot, nb))) => Report::from_numeric(&desc, nb, &robot.standard_parameters()),
        _ => unreachable!(),
    };
    if let (Some(sb), Some((_, nb))) = (&symbolic, &numeric) {
        report.add_comparison(&compare_methods(sb, nb));
    }
    match a.format {
        Format::Text => print!("{}", report.to_text()),
        Format::Latex => print!("{}", report.to_latex()),
        Format::Json => println!("{}", serde_json::to_string_pretty(&report.to_json())?),
    }
    if let Some(path) = &a.write_robot {
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
        let out = base_robot(&desc, &base, &values)?;
        robodyn::io::save_description(&out, path)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}
