//! The library's `Error` as Python exceptions: one class per kind, all subclasses of
//! `robodyn.Error`, with the library's message and the kind's fields as attributes.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use robodyn::error::Location;
use robodyn::Error;

create_exception!(
    robodyn,
    RobodynError,
    PyException,
    "Base class of every robodyn error."
);
create_exception!(
    robodyn,
    RobotFileError,
    RobodynError,
    "A robot file or description is invalid or cannot be read (attributes `file`, `line`, `column`, `item`, `reason`)."
);
create_exception!(
    robodyn,
    PhysicalParameterError,
    RobotFileError,
    "A physically inconsistent parameter (negative mass, rotor inertia or friction)."
);
create_exception!(
    robodyn,
    DimensionError,
    RobodynError,
    "An array of the wrong shape or size (attributes `what`, `expected`, `got`)."
);
create_exception!(
    robodyn,
    NotFiniteError,
    RobodynError,
    "A NaN or infinite input (attributes `what`, `index`, `value`)."
);
create_exception!(
    robodyn,
    SingularConfiguration,
    RobodynError,
    "A singular configuration: Wp, A_cl or A below its hard conditioning limit (attribute `rcond`)."
);
create_exception!(
    robodyn,
    LoopClosureError,
    RobodynError,
    "The loop-closure equations have no solution near the guess."
);
create_exception!(
    robodyn,
    BranchLost,
    LoopClosureError,
    "The actuated values cannot be reached on the tracker's assembly branch."
);
create_exception!(
    robodyn,
    InputError,
    RobodynError,
    "Other input that does not fit the robot."
);
create_exception!(
    robodyn,
    NumericalError,
    RobodynError,
    "A numerical failure (no convergence, step-size underflow...)."
);

create_exception!(
    robodyn,
    RobotFileWarning,
    pyo3::exceptions::PyUserWarning,
    "What a robot file's reader noticed that is not an error (inertial parameters no rigid body has, a legged robot loaded with a fixed base, ...): the file loads, but may not mean what its author meant."
);

/// Register the classes in the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("Error", py.get_type::<RobodynError>())?;
    m.add("RobotFileError", py.get_type::<RobotFileError>())?;
    m.add(
        "PhysicalParameterError",
        py.get_type::<PhysicalParameterError>(),
    )?;
    m.add("DimensionError", py.get_type::<DimensionError>())?;
    m.add("NotFiniteError", py.get_type::<NotFiniteError>())?;
    m.add(
        "SingularConfiguration",
        py.get_type::<SingularConfiguration>(),
    )?;
    m.add("LoopClosureError", py.get_type::<LoopClosureError>())?;
    m.add("BranchLost", py.get_type::<BranchLost>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    Ok(())
}

/// The Python exception of a library error (the message is the library's).
pub fn to_py(e: Error) -> PyErr {
    Python::attach(|py| build(py, e))
}

fn build(py: Python<'_>, e: Error) -> PyErr {
    let msg = e.to_string();
    // an error of a table row: the inner error's class, with `row` (1-based) set
    let (row, inner) = match e {
        Error::Row { row, source } => (Some(row), *source),
        other => (None, other),
    };
    let mut attrs: Vec<(&str, Py<PyAny>)> = Vec::new();
    let loc = |l: &Location, attrs: &mut Vec<(&str, Py<PyAny>)>| {
        attrs.push((
            "file",
            l.file
                .clone()
                .into_pyobject(py)
                .unwrap()
                .into_any()
                .unbind(),
        ));
        attrs.push((
            "line",
            l.line.into_pyobject(py).unwrap().into_any().unbind(),
        ));
        attrs.push((
            "column",
            l.column.into_pyobject(py).unwrap().into_any().unbind(),
        ));
    };
    let s = |x: &str| x.into_pyobject(py).unwrap().into_any().unbind();
    let f = |x: f64| x.into_pyobject(py).unwrap().into_any().unbind();
    let u = |x: usize| x.into_pyobject(py).unwrap().into_any().unbind();
    let err = match &inner {
        Error::Invalid {
            location,
            item,
            reason,
        } => {
            loc(location, &mut attrs);
            attrs.push(("item", s(&item.to_string())));
            attrs.push(("reason", s(reason)));
            RobotFileError::new_err(msg)
        }
        Error::Parse { location, reason } => {
            loc(location, &mut attrs);
            attrs.push(("reason", s(reason)));
            RobotFileError::new_err(msg)
        }
        Error::Physical {
            location,
            item,
            reason,
        } => {
            loc(location, &mut attrs);
            attrs.push(("item", s(&item.to_string())));
            attrs.push(("reason", s(reason)));
            PhysicalParameterError::new_err(msg)
        }
        Error::Io { path, .. } => {
            attrs.push(("file", s(path)));
            attrs.push(("line", py.None()));
            attrs.push(("column", py.None()));
            RobotFileError::new_err(msg)
        }
        Error::Dimension {
            what,
            expected,
            got,
            ..
        } => {
            attrs.push(("what", s(what)));
            attrs.push(("expected", u(*expected)));
            attrs.push(("got", u(*got)));
            DimensionError::new_err(msg)
        }
        Error::NotFinite { what, index, value } => {
            attrs.push(("what", s(what)));
            attrs.push(("index", u(*index)));
            attrs.push(("value", f(*value)));
            NotFiniteError::new_err(msg)
        }
        Error::Singular { what, rcond, .. } => {
            attrs.push(("what", s(what)));
            attrs.push(("rcond", f(*rcond)));
            SingularConfiguration::new_err(msg)
        }
        Error::SingularStart { rcond, .. } => {
            attrs.push(("what", s("Wp")));
            attrs.push(("rcond", f(*rcond)));
            SingularConfiguration::new_err(msg)
        }
        Error::LoopNotClosed { residual, .. } => {
            attrs.push(("residual", f(*residual)));
            LoopClosureError::new_err(msg)
        }
        Error::BranchLost { .. } => BranchLost::new_err(msg),
        Error::Input(_) => InputError::new_err(msg),
        Error::Setting { option, .. } => {
            attrs.push(("option", s(option)));
            InputError::new_err(msg)
        }
        Error::Numerical(_) => NumericalError::new_err(msg),
        _ => RobodynError::new_err(msg),
    };
    attrs.push(("row", row.into_pyobject(py).unwrap().into_any().unbind()));
    let value = err.value(py);
    for (k, v) in attrs {
        let _ = value.setattr(k, v);
    }
    err
}

/// `Result` conversion for the bindings.
pub trait IntoPy<T> {
    /// Map the library error to its Python exception.
    fn py(self) -> PyResult<T>;
}

impl<T> IntoPy<T> for robodyn::Result<T> {
    fn py(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
