//! Base inertial parameters (§10.2.4, §10.3.4–10.3.6).
//!
//! - [`numeric`]: the numerical method (stacked regressor, rank, ordered QR, beta);
//! - [`symbolic`]: the rules of §10.3.6 with the grouping equations as expressions;
//! - [`closed`]: consistent random states of a closed chain for the numerical method;
//! - [`names`]: the robot's own names of the standard parameters;
//! - [`summary`]: the structured result (table, lists, equations, values, comparison); its
//!   writers (text, LaTeX, JSON) are in [`crate::report::base_parameters`].
//!
//! # Example
//!
//! The base parameters of the Acma SR400 (a closed chain) by both methods: the rules of
//! §10.3.6, with the grouping equations over the file's symbols, and the numerical method on
//! states sampled on the loop-closure branch. Khalil & Dombre's Table 10.2 has 42 without
//! friction.
//!
//! ```
//! use robodyn::algorithms::base_parameters::{
//!     compare_methods, geometry_robot, numeric_base_parameters_auto, symbolic_base_parameters,
//!     NumericOptions, ParameterNames,
//! };
//! use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode};
//! # fn main() -> robodyn::Result<()> {
//! let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
//! let desc = robodyn::io::load_description(path)?;
//! let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::None);
//! let names = ParameterNames::of(&desc);
//! let symbolic = symbolic_base_parameters(&desc, &sel)?;
//! for (r, e) in symbolic.equations.iter().enumerate().filter(|(r, _)| symbolic.is_regrouped(*r)) {
//!     println!("{} = {e}", names.name(symbolic.base[r])); // e.g. ZZR1 = ZZ1 + YY2 + ...
//! }
//! let opt = NumericOptions { selection: sel, samples: None, seed: 1 };
//! let (robot, _) = geometry_robot(&desc)?; // generic values for symbols without one
//! let (numeric, _start) = numeric_base_parameters_auto(&robot, &opt)?;
//! assert!(compare_methods(&symbolic, &numeric, &names).same());
//! assert_eq!(symbolic.count(), 42);
//! # Ok(())
//! # }
//! ```

pub mod closed;
pub mod columns;
pub mod names;
pub mod numeric;
pub mod summary;
pub mod symbolic;

pub use closed::{ClosedChainSampler, StartReport};
pub use columns::{base_columns, standard_columns, RegressorColumns};
pub use names::ParameterNames;
pub use numeric::{
    numeric_base_parameters, ConsistentSample, NumericBase, NumericOptions, Sampler, TreeSampler,
};
pub use summary::{base_robot, compare_methods, standard_values, MethodComparison, Summary};
pub use symbolic::{
    collect_by_coefficient, symbolic_base_parameters, SymbolicBase, FLOAT_TERM_TOLERANCE,
};

use crate::error::{Error, Result};
use crate::model::{JointType, Robot, RobotDescription};
use robodyn_symbolic::Expr;

/// The robot the numerical method samples: `desc`'s geometry, where every symbol without a
/// value takes the generic value of the symbolic method ([`symbolic::generic_value`]), and
/// every inertial parameter and external wrench set to zero (the regressor does not depend on
/// them). Returns the robot and the symbols given a generic value (name, value): the count and
/// the grouping then hold for generic geometry, the values of the base parameters are unknown.
pub fn geometry_robot(desc: &RobotDescription) -> Result<(Robot, Vec<(String, f64)>)> {
    let mut d = desc.clone();
    for l in d.links.iter_mut().chain(d.floating_base.as_mut()) {
        for e in l.params.iter_mut().chain(l.wrench.iter_mut()) {
            *e = Expr::zero();
        }
    }
    let mut generic = Vec::new();
    let mut exprs: Vec<&Expr> = Vec::new();
    for f in &d.frames {
        exprs.extend(f.geometric());
    }
    for v in [&d.gravity, &d.w0, &d.wp0, &d.v0, &d.vp0] {
        exprs.extend(v.iter());
    }
    let missing: std::collections::BTreeSet<String> = exprs
        .iter()
        .flat_map(|e| e.symbols())
        .filter(|s| !d.symbols.contains_key(s))
        .collect();
    for s in missing {
        let v = symbolic::generic_value(&s);
        d.symbols.insert(s.clone(), v);
        generic.push((s, v));
    }
    let robot = Robot::new(d).map_err(|e| {
        Error::Input(format!(
            "{}: the geometry cannot be evaluated for the numerical method: {e}",
            desc.name
        ))
    })?;
    Ok((robot, generic))
}

/// The note of the numerical method on a geometry with generic values (the symbols of
/// [`geometry_robot`]): "symbols without value took generic values for the numerical method
/// (L3 = 0.4142, ...): the count and the grouping hold for generic values of them, not for
/// special ones". None when every symbol had a value. A surface adds how to give values.
pub fn generic_values_note(generic: &[(String, f64)]) -> Option<String> {
    if generic.is_empty() {
        return None;
    }
    let list: Vec<String> = generic
        .iter()
        .map(|(s, v)| format!("{s} = {}", (v * 1e4).round() / 1e4))
        .collect();
    Some(format!(
        "symbols without value took generic values for the numerical method ({}): the count \
         and the grouping hold for generic values of them, not for special ones",
        list.join(", ")
    ))
}

/// The numerical method with the sampler the structure needs: random states for a tree, the
/// loop-closure sampler ([`ClosedChainSampler`]) for a closed chain, whose start (and branch)
/// is returned too.
pub fn numeric_base_parameters_auto(
    robot: &Robot,
    opt: &NumericOptions,
) -> Result<(NumericBase, Option<StartReport>)> {
    if robot.is_tree() {
        Ok((numeric_base_parameters(robot, &mut TreeSampler, opt)?, None))
    } else {
        let mut sampler = ClosedChainSampler::new(robot)?;
        let start = sampler.start().clone();
        Ok((
            numeric_base_parameters(robot, &mut sampler, opt)?,
            Some(start),
        ))
    }
}

/// Upper bound b_m of the number of base inertial parameters of the links (rotors and friction
/// not included): eq 10.24 for a tree, eq 10.57 for a closed chain with `n_parallelograms`
/// parallelogram loops:
/// b_m = 7 n_r + 4 n_p - 4 n_r0 - 3 n_p0 - 11 n_par - 2 n_g0, with n_r (n_p) the revolute
/// (prismatic) joints of the equivalent tree, n_r0 (n_p0) those connected to the base, n_g0 the
/// revolute joints connected to the base whose axes are parallel to gravity.
pub fn inertial_bound(robot: &Robot, n_parallelograms: usize) -> usize {
    let g = robot.numeric().env.gravity;
    let (mut nr, mut np, mut nr0, mut np0, mut ng0) = (0i64, 0i64, 0i64, 0i64, 0i64);
    for j in 1..=robot.nl() {
        let at_base = robot.ant(j) == 0;
        match robot.frame(j).joint {
            JointType::Revolute => {
                nr += 1;
                if at_base {
                    nr0 += 1;
                    let (rot, _) = robot.numeric().frame(j).transform(&0.0);
                    if rot.column(2).cross(&g).norm() < 1e-9 * g.norm().max(1.0) {
                        ng0 += 1;
                    }
                }
            }
            JointType::Prismatic => {
                np += 1;
                np0 += i64::from(at_base);
            }
            JointType::Fixed => {}
        }
    }
    (7 * nr + 4 * np - 4 * nr0 - 3 * np0 - 11 * n_parallelograms as i64 - 2 * ng0).max(0) as usize
}
