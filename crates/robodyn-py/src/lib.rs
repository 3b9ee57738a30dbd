//! Python bindings of robodyn (module `robodyn._robodyn`, re-exported by the `robodyn` package):
//! robots from files, the tree and closed-chain models on NumPy arrays (one state or N states,
//! batches over all cores with the GIL released), base parameters, code generation, simulation,
//! and the library's errors as Python exceptions.

mod arrays;
mod closed;
mod errors;
mod models;
mod robot;

use errors::IntoPy;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Read a robot file (TOML, SYMORO .par or URDF, by extension); `values` give or change symbol
/// values (`robodyn.load("robots/sr400.toml", d3=0.6)`).
#[pyfunction]
#[pyo3(signature = (path, **values))]
fn load(path: PathBuf, values: Option<&Bound<'_, pyo3::types::PyDict>>) -> PyResult<robot::Robot> {
    let mut overrides = std::collections::BTreeMap::new();
    if let Some(v) = values {
        for (k, x) in v.iter() {
            overrides.insert(k.extract::<String>()?, x.extract::<f64>()?);
        }
    }
    let r = robodyn::io::load_with(&path, &overrides).py()?;
    Ok(robot::Robot::wrap(r, Some(path)))
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
    m.add_function(wrap_pyfunction!(load, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
