//! Python bindings of robodyn (module `robodyn._robodyn`, re-exported by the `robodyn` package):
//! robots from files, the tree and closed-chain models on NumPy arrays (one state or N states,
//! batches over all cores with the GIL released), base parameters, code generation, simulation,
//! and the library's errors as Python exceptions.

mod arrays;
mod closed;
mod errors;
mod models;
mod robot;
mod view;

use errors::IntoPy;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Read a robot file (TOML, SYMORO .par or URDF, by extension); `values` give or change symbol
/// values (`robodyn.load("robots/sr400.toml", d3=0.6)`). A file whose symbols lack values (a
/// SYMORO file of symbols only) is refused with the list of them and the two ways on: values as
/// keyword arguments, or `robodyn.base_parameters(path)`, which needs none.
#[pyfunction]
#[pyo3(signature = (path, **values))]
fn load(path: PathBuf, values: Option<&Bound<'_, pyo3::types::PyDict>>) -> PyResult<robot::Robot> {
    let overrides = robot::kwargs_values(values)?;
    match robodyn::io::load_with(&path, &overrides) {
        Ok(r) => Ok(robot::Robot::wrap(r, Some(path))),
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
    let mut exprs: Vec<&robodyn::Expr> = Vec::new();
    for f in &d.frames {
        exprs.extend(f.geometric());
    }
    for l in &d.links {
        exprs.extend(l.params.iter().chain(l.wrench.iter()));
    }
    for v in [&d.gravity, &d.w0, &d.wp0, &d.v0, &d.vp0] {
        exprs.extend(v.iter());
    }
    let mut seen = std::collections::BTreeSet::new();
    exprs
        .iter()
        .flat_map(|e| e.symbols())
        .filter(|s| !d.symbols.contains_key(s) && seen.insert(s.clone()))
        .collect()
}

#[pymodule]
fn _robodyn(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add(
        "SingularityWarning",
        m.py().get_type::<closed::SingularityWarning>(),
    )?;
    m.add_class::<robot::Robot>()?;
    m.add_class::<closed::ClosedChain>()?;
    m.add_class::<models::BaseParameters>()?;
    m.add_class::<models::Generated>()?;
    m.add_class::<view::View>()?;
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add_function(wrap_pyfunction!(models::base_parameters_of_file, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
