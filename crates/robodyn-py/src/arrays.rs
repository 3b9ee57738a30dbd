//! NumPy arrays in and out: one state (1-D arrays of the vector's length) or N states (2-D
//! arrays, one row per state), shapes checked with a message naming the expected shape. N
//! states run through the library's row runner (`robodyn::batch::for_each_row`).

use crate::errors::DimensionError;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::prelude::*;

/// Joint-vector arguments of one call: all one state or all N states.
pub struct States {
    /// None: one state (1-D inputs, 1-D outputs); Some(N): N rows.
    pub rows: Option<usize>,
    /// The inputs, row-major (N x n), in the order given.
    pub data: Vec<Vec<f64>>,
    /// Length of one state vector.
    pub n: usize,
}

impl States {
    /// Number of rows (1 for one state).
    pub fn count(&self) -> usize {
        self.rows.unwrap_or(1)
    }

    /// Row r of input k.
    pub fn row(&self, k: usize, r: usize) -> &[f64] {
        &self.data[k][r * self.n..(r + 1) * self.n]
    }
}

/// `obj` as a float64 array (no copy when it already is one).
pub fn float_array<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        return Ok(a.clone());
    }
    let np = obj.py().import("numpy")?;
    let a = np.call_method1("asarray", (obj, "float64"))?;
    Ok(a.cast_into::<PyArrayDyn<f64>>()?)
}

fn shape_text(s: &[usize]) -> String {
    match s {
        [n] => format!("({n},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Parse the named inputs (None: zeros) into one state or N states of length `n`. `what`
/// says what the entries are (e.g. "movable joints [j1, j2]").
pub fn states(
    inputs: &[(&str, Option<&Bound<'_, PyAny>>)],
    n: usize,
    what: &dyn Fn() -> String,
) -> PyResult<States> {
    let mut rows: Option<Option<usize>> = None; // decided by the first given input
    let mut first = "";
    let mut arrays = Vec::with_capacity(inputs.len());
    for (name, obj) in inputs {
        let Some(obj) = obj else {
            arrays.push(None);
            continue;
        };
        let a = float_array(obj)?;
        let shape = a.shape().to_vec();
        let this = match shape.as_slice() {
            [len] if *len == n => None,
            [r, len] if *len == n => Some(*r),
            _ => {
                let e = DimensionError::new_err(format!(
                    "{name} has shape {}, expected ({n},) for one state or (N, {n}) for N states \
                     ({})",
                    shape_text(&shape),
                    what()
                ));
                let v = e.value(obj.py());
                let _ = v.setattr("what", *name);
                let _ = v.setattr("expected", n);
                let _ = v.setattr("got", shape.last().copied().unwrap_or(0));
                return Err(e);
            }
        };
        match rows {
            None => {
                rows = Some(this);
                first = name;
            }
            Some(prev) if prev != this => {
                return Err(DimensionError::new_err(format!(
                    "{name} has shape {} but {first} has {}: give every input as one state \
                     ({n},) or all as N states (N, {n}) with the same N",
                    shape_text(&shape),
                    match prev {
                        None => format!("({n},)"),
                        Some(r) => format!("({r}, {n})"),
                    }
                )));
            }
            _ => {}
        }
        let ro = a.readonly();
        let v = match ro.as_slice() {
            Ok(s) => s.to_vec(),
            Err(_) => ro.as_array().iter().copied().collect(),
        };
        arrays.push(Some(v));
    }
    let rows = rows.flatten();
    let len = rows.unwrap_or(1) * n;
    Ok(States {
        rows,
        data: arrays
            .into_iter()
            .map(|a| a.unwrap_or_else(|| vec![0.0; len]))
            .collect(),
        n,
    })
}

/// The output array: `shape_one` for one state, (N, *shape_one) for N states.
pub fn output<'py>(
    py: Python<'py>,
    v: Vec<f64>,
    rows: Option<usize>,
    shape_one: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    let mut shape: Vec<usize> = rows.into_iter().collect();
    shape.extend_from_slice(shape_one);
    if shape.len() == 1 {
        // one state: a copy into a NumPy-owned array is cheaper than handing the Vec over
        return Ok(PyArray1::from_slice(py, &v).into_any());
    }
    Ok(PyArray1::from_vec(py, v).reshape(shape)?.into_any())
}
