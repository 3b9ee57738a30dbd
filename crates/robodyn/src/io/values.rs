//! Values given by name to a loaded description (the CLI's `--set NAME=VALUE`, the Python
//! package's `load(path, NAME=VALUE)` and `Robot.with_values`): one rule for every consumer.
//!
//! A name is a symbol of the description, or the name of a standard parameter
//! ([`ParameterNames::of`]: the file's own symbol, else the canonical `M3`, `FS2`, ...). A
//! parameter that the file writes as a number (every inertial and drive parameter of a URDF)
//! has no symbol to set: its name replaces that entry by the value, so that the mass of link 3
//! of a URDF robot is changed by `M3 = 12`. Any other name is refused with the names known (a
//! misspelt `d3` for `D3` would otherwise be a symbol nothing uses, silently).

use crate::algorithms::base_parameters::ParameterNames;
use crate::algorithms::regressor::PARAMS_PER_LINK;
use crate::error::{Error, Result};
use crate::model::{RobotDescription, STANDARD_PARAMETERS};
use robodyn_symbolic::Expr;
use std::collections::{BTreeMap, BTreeSet};

/// What a name given a value refers to.
enum Target {
    /// A symbol: its value is given or changed.
    Symbol,
    /// Standard parameter k (K index), written as a number or an expression: replaced.
    Parameter(usize),
}

/// Give or change values by name in `desc` (see the module's rule): symbols, and standard
/// parameters written as numbers or expressions (replaced by the value). Every name is checked
/// before anything changes; an unknown name is an [`Error::Input`] listing the known ones, a
/// value that is not finite an [`Error::Input`] naming it.
pub fn set_values(desc: &mut RobotDescription, values: &BTreeMap<String, f64>) -> Result<()> {
    let targets = values
        .iter()
        .map(|(name, &v)| {
            if !v.is_finite() {
                return Err(Error::Input(format!("{name} = {v}: not a finite number")));
            }
            Ok((name, v, target(desc, name)?))
        })
        .collect::<Result<Vec<_>>>()?;
    for (name, v, t) in targets {
        match t {
            Target::Symbol => {
                desc.symbols.insert(name.clone(), v);
            }
            Target::Parameter(k) => {
                desc.links[k / PARAMS_PER_LINK].params[k % PARAMS_PER_LINK] = Expr::num(v);
            }
        }
    }
    Ok(())
}

/// The symbols of `desc`: those with a value and those its expressions use.
pub fn known_symbols(desc: &RobotDescription) -> BTreeSet<String> {
    let mut known: BTreeSet<String> = desc.symbols.keys().cloned().collect();
    known.extend(desc.used_symbols());
    known
}

fn target(desc: &RobotDescription, name: &str) -> Result<Target> {
    let symbols = known_symbols(desc);
    if symbols.contains(name) {
        return Ok(Target::Symbol);
    }
    let names = ParameterNames::of(desc);
    let n = PARAMS_PER_LINK * desc.nl;
    if let Some(k) = (0..n).find(|&k| names.name(k) == name) {
        return Ok(Target::Parameter(k));
    }
    Err(Error::Input(unknown(desc, name, &symbols, &names)))
}

/// The message for an unknown name: the symbols, the rule of the standard parameters' names
/// (and the names that do not follow it), and a known name differing only in case.
fn unknown(
    desc: &RobotDescription,
    name: &str,
    symbols: &BTreeSet<String>,
    names: &ParameterNames,
) -> String {
    let n = PARAMS_PER_LINK * desc.nl;
    let canonical = |k: usize| {
        format!(
            "{}{}",
            STANDARD_PARAMETERS[k % PARAMS_PER_LINK],
            k / PARAMS_PER_LINK + 1
        )
    };
    let special: Vec<&str> = (0..n)
        .filter(|&k| !symbols.contains(names.name(k)) && names.name(k) != canonical(k))
        .map(|k| names.name(k))
        .collect();
    let close = symbols
        .iter()
        .map(String::as_str)
        .chain((0..n).map(|k| names.name(k)))
        .find(|s| s.eq_ignore_ascii_case(name));
    let hint = close.map_or(String::new(), |c| format!(" (did you mean `{c}`?)"));
    let list = if symbols.is_empty() {
        "none".to_string()
    } else {
        symbols.iter().cloned().collect::<Vec<_>>().join(", ")
    };
    let mut params = format!(
        "{}<j> for link j = 1..{} (IA, FS, FV: joint j's drive), or the symbol the file writes \
         for one",
        STANDARD_PARAMETERS.join("<j> "),
        desc.nl
    );
    if !special.is_empty() {
        params += &format!(
            " (renamed where that name is taken: {})",
            special.join(", ")
        );
    }
    format!(
        "the robot has no symbol `{name}` and no standard parameter of that name{hint}; its \
         symbols: {list}; its standard parameters: {params}"
    )
}
