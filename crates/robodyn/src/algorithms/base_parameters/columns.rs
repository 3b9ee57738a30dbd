//! The regressor's columns of a model: the selected standard parameters, or the base
//! parameters (symbolic rules, the numerical method where the rules do not handle a loop),
//! with the robot file's own names.

use super::{
    numeric_base_parameters, symbolic_base_parameters, ClosedChainSampler, NumericOptions,
    ParameterNames,
};
use crate::algorithms::regressor::{parameter_count, ParameterSelection, PARAMS_PER_LINK};
use crate::error::Result;
use crate::model::Robot;

/// Columns of the regressor kept for a model: indices in K and their names.
#[derive(Clone, Debug, PartialEq)]
pub struct RegressorColumns {
    /// Indices in K (13 per link), in K order.
    pub indices: Vec<usize>,
    /// Names: `XX1`..., base parameters that group others get an `R` (`XX2R`).
    pub names: Vec<String>,
    /// How the set was chosen when it is not the symbolic rules' (for the user).
    pub note: Option<String>,
}

/// The regressor columns of the standard parameters selected by `selection` (absent ones left
/// out), then a floating base's 10 (K indices 13 NL.., `XX0` .. `M0`), named with the robot
/// file's own parameter names.
pub fn standard_columns(robot: &Robot, selection: &ParameterSelection) -> RegressorColumns {
    let names = ParameterNames::of(robot.description());
    let mut indices = selection.columns();
    indices.extend(PARAMS_PER_LINK * robot.nl()..parameter_count(robot));
    RegressorColumns {
        names: indices.iter().map(|&i| names.name(i).to_string()).collect(),
        indices,
        note: None,
    }
}

/// The regressor columns of the base parameters (Phi_b with Gamma = Phi_b K_b + Gamma_e): the
/// symbolic rules' set (§10.3.6); for a closed chain whose loops the rules do not all handle, the
/// numerical method's set (§10.3.4, samples seeded by `seed`), said in `note`. Names are the
/// robot file's own (grouped ones with their `R` name).
pub fn base_columns(
    robot: &Robot,
    selection: &ParameterSelection,
    seed: u64,
) -> Result<RegressorColumns> {
    let names = ParameterNames::of(robot.description());
    let name = |i: usize, regrouped: bool| {
        if regrouped {
            names.grouped(i).to_string()
        } else {
            names.name(i).to_string()
        }
    };
    let sb = symbolic_base_parameters(robot.description(), selection)?;
    if !robot.is_tree() && !sb.unhandled_loops.is_empty() {
        let opt = NumericOptions {
            selection: selection.clone(),
            samples: None,
            seed,
        };
        let mut sampler = ClosedChainSampler::new(robot)?;
        let note = format!(
            "{}: the symbolic rules do not handle the loop(s) cut at joint(s) {:?}; the \
             columns are the numerical method's base parameters (the arbiter)",
            robot.name(),
            sb.unhandled_loops
        );
        return numeric_columns(robot, &name, opt, &mut sampler, note);
    }
    let (indices, names) = (0..sb.count())
        .map(|r| (sb.base[r], name(sb.base[r], sb.is_regrouped(r))))
        .unzip();
    Ok(RegressorColumns {
        indices,
        names,
        note: None,
    })
}

/// The columns of the numerical method's base parameters, with `note`.
fn numeric_columns(
    robot: &Robot,
    name: &dyn Fn(usize, bool) -> String,
    opt: NumericOptions,
    sampler: &mut dyn super::Sampler,
    note: String,
) -> Result<RegressorColumns> {
    let nb = numeric_base_parameters(robot, sampler, &opt)?;
    let (indices, names) = (0..nb.count())
        .map(|r| (nb.base[r], name(nb.base[r], nb.is_regrouped(r))))
        .unzip();
    Ok(RegressorColumns {
        indices,
        names,
        note: Some(note),
    })
}
