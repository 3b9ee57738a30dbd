//! Python bindings of robodyn (module `robodyn._robodyn`, re-exported by the `robodyn` package):
//! robots from files, the tree and closed-chain models on NumPy arrays (one state or N states,
//! batches over all cores with the GIL released), base parameters, code generation, simulation,
//! and the library's errors as Python exceptions.

mod arrays;
mod closed;
mod errors;
mod excitation;
mod floating;
mod identification;
mod joint_problems;
mod kinematics;
mod models;
mod robot;
mod view;

use errors::IntoPy;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Read a robot file (TOML, SYMORO .par or URDF, by extension). `values` give or change values
/// by name: symbols (`robodyn.load("robots/sr400.toml", d3=0.6)`) or standard parameters the
/// file writes as numbers (`load("ur5.urdf", M3=3.2, FV2=0.5)`: mass of link 3, viscous
/// friction of joint 2; names as `Robot.parameter_names`); an unknown name raises InputError
/// listing the known ones. What the reader notices (inertias no rigid body has, a legged robot
/// loaded with a fixed base, ...) is issued as a `robodyn.RobotFileWarning`. A file whose symbols
/// lack values (a SYMORO file of symbols only) is refused with the list of them and the two
/// ways on: values as keyword arguments, or `robodyn.base_parameters(path)`, which needs none.
///
/// floating=True makes the base floating: a URDF's root link becomes link 0 of a free-flyer
/// base with its `<inertial>` (Pinocchio's `JointModelFreeFlyer` root); the state vectors then
/// have nq = 7 + N (q: base position, quaternion x y z w, joints) and nv = 6 + N entries. A
/// .toml or .par file says it itself (`base = "floating"`, `is_floating = 1`).
#[pyfunction]
#[pyo3(signature = (path, *, floating=false, **values))]
fn load(
    py: Python<'_>,
    path: PathBuf,
    floating: bool,
    values: Option<&Bound<'_, pyo3::types::PyDict>>,
) -> PyResult<robot::Robot> {
    let overrides = robot::kwargs_values(values)?;
    robot::check_finite(&overrides)?;
    let options = if floating {
        robodyn::io::LoadOptions::floating()
    } else {
        robodyn::io::LoadOptions::default()
    };
    match robodyn::io::load_with_warnings_options(&path, &overrides, &options) {
        Ok((r, warnings)) => {
            let warn = py.import("warnings")?;
            for w in warnings {
                warn.call_method1(
                    "warn",
                    (w.to_string(), py.get_type::<errors::RobotFileWarning>(), 1),
                )?;
            }
            Ok(robot::Robot::wrap(r, Some(path)))
        }
        Err(e) => {
            let missing = robodyn::io::load_description(&path)
                .map(|mut d| {
                    d.symbols.extend(overrides);
                    symbols_without_value(&d)
                })
                .unwrap_or_default();
            let hint = |missing: &[String]| {
                let shown: Vec<&str> = missing.iter().take(8).map(String::as_str).collect();
                format!(
                    "; {} symbol{} without a value ({}{}): give them as keyword arguments \
                     (robodyn.load(path, {}=...)); for the base parameters alone (names, count, \
                     grouping), which need no values, use robodyn.base_parameters(path) as the \
                     CLI's `robodyn base-params` does",
                    missing.len(),
                    if missing.len() > 1 { "s" } else { "" },
                    shown.join(", "),
                    if missing.len() > shown.len() {
                        ", ..."
                    } else {
                        ""
                    },
                    shown[0]
                )
            };
            Err(match e {
                robodyn::Error::Invalid {
                    location,
                    item,
                    reason,
                } if !missing.is_empty() => robodyn::Error::Invalid {
                    location,
                    item,
                    reason: reason + &hint(&missing),
                },
                e => e,
            })
            .py()
        }
    }
}

/// The symbols a description uses without giving them a value, in order.
fn symbols_without_value(d: &robodyn::RobotDescription) -> Vec<String> {
    d.used_symbols()
        .into_iter()
        .filter(|s| !d.symbols.contains_key(s))
        .collect()
}

#[pymodule]
fn _robodyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add(
        "SingularityWarning",
        m.py().get_type::<closed::SingularityWarning>(),
    )?;
    m.add(
        "RobotFileWarning",
        m.py().get_type::<errors::RobotFileWarning>(),
    )?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<closed::ClosedChain>()?;
    m.add_class::<models::BaseParameters>()?;
    m.add_class::<models::Generated>()?;
    m.add_class::<view::View>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(models::base_parameters_of_file, m)?)?;
    identification::register(m)?;
    joint_problems::register(m)?;
    m.add_function(wrap_pyfunction!(excitation::excite, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
