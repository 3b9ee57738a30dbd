//! NumPy arrays in and out: one state (1-D arrays of the vector's length) or N states (2-D
//! arrays, one row per state), shapes checked with a message naming the expected shape.
//!
//! Inputs are read by their logical indices, whatever their memory layout: float64 arrays whose
//! rows are contiguous (C order, a slice of rows, a broadcast row, rows in reverse order) are
//! read in place; any other layout (Fortran order, a transpose, a column slice) or dtype
//! (float32, integers, lists, big-endian) is converted to float64 rows first. Results go to a
//! new array, or to the caller's `out` (float64, C-contiguous, writeable, of the result's shape).
//! N states run through the library's row runner in blocks, the signals checked between blocks.

use crate::errors::{DimensionError, InputError, IntoPy};
use numpy::npyffi;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyMemoryError;
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// Zeros for an omitted vector: one row serves every state.
static ZERO_ROW: [f64; 64] = [0.0; 64];

/// How long a block of rows runs with the GIL released before the signals are checked
/// (Ctrl-C raises KeyboardInterrupt between blocks).
pub const SIGNAL_INTERVAL: Duration = Duration::from_millis(50);

/// A vector of `len` zeros, or MemoryError when the memory cannot be had (a batch of 20 M
/// states asks for gigabytes: an error, never an abort).
pub fn try_zeros(len: usize) -> PyResult<Vec<f64>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).map_err(|_| {
        PyMemoryError::new_err(format!(
            "cannot allocate {len} float64 values ({:.1} GB)",
            len as f64 * 8e-9
        ))
    })?;
    v.resize(len, 0.0);
    Ok(v)
}

/// The float64 arrays of the given joint-vector arguments, their number of rows checked.
pub struct Inputs<'py> {
    arrays: [Option<Bound<'py, PyArrayDyn<f64>>>; 3],
    /// None: one state (1-D inputs, 1-D outputs); Some(N): N rows.
    pub rows: Option<usize>,
    /// Length of one state vector, per input (a floating robot's q has nq entries, its
    /// velocities nv).
    pub n: [usize; 3],
}

/// A float64 array whose memory can be read in place: aligned, strides whole elements.
fn readable(a: &Bound<'_, PyArrayDyn<f64>>) -> bool {
    // SAFETY: the array object is alive (borrowed); its flags field is plain data
    let aligned = unsafe { (*a.as_array_ptr()).flags & npyffi::NPY_ARRAY_ALIGNED != 0 };
    aligned && a.strides().iter().all(|s| s % 8 == 0)
}

/// `obj` as a float64 array: the array itself when it is one that can be read in place, else
/// NumPy's conversion (a copy in C order for other dtypes, lists, unaligned or byte-swapped
/// memory).
fn float64<'py>(obj: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        if readable(a) {
            return Ok(a.clone());
        }
    }
    let py = obj.py();
    let kwargs = pyo3::types::PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    kwargs.set_item("order", "C")?;
    let a = py
        .import("numpy")?
        .call_method("array", (obj,), Some(&kwargs))?;
    Ok(a.cast_into::<PyArrayDyn<f64>>()?)
}

/// `obj` (an array or anything NumPy converts) as float64 values in logical order (C order
/// whatever its layout), with its shape.
pub fn values(obj: &Bound<'_, PyAny>) -> PyResult<(Vec<f64>, Vec<usize>)> {
    let a = float64(obj)?;
    // SAFETY: aligned float64 memory of whole-element strides (`float64`), only read here
    let v = unsafe { a.as_array() }.iter().copied().collect();
    Ok((v, a.shape().to_vec()))
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
/// says what the entries are (e.g. "movable joints [j1, j2]"). At most three inputs.
pub fn inputs<'py>(
    given: &[(&str, Option<&Bound<'py, PyAny>>)],
    n: usize,
    what: &dyn Fn() -> String,
) -> PyResult<Inputs<'py>> {
    inputs_sized(given, [n; 3], what)
}

/// [`inputs`] with a length per input (`lens[k]` for input k: a floating robot's q has nq
/// entries, its velocities nv).
pub fn inputs_sized<'py>(
    given: &[(&str, Option<&Bound<'py, PyAny>>)],
    lens: [usize; 3],
    what: &dyn Fn() -> String,
) -> PyResult<Inputs<'py>> {
    let mut rows: Option<Option<usize>> = None; // decided by the first given input
    let mut first = "";
    let mut first_n = 0;
    let mut arrays: [Option<Bound<'py, PyArrayDyn<f64>>>; 3] = [None, None, None];
    for (k, (name, obj)) in given.iter().enumerate() {
        let Some(obj) = obj else { continue };
        let n = lens[k];
        let a = float64(obj)?;
        let shape = a.shape();
        let this = match shape {
            [len] if *len == n => None,
            [r, len] if *len == n => Some(*r),
            _ => {
                let e = DimensionError::new_err(format!(
                    "{name} has shape {}, expected ({n},) for one state or (N, {n}) for N states \
                     ({})",
                    shape_text(shape),
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
                first_n = n;
            }
            Some(prev) if prev != this => {
                return Err(DimensionError::new_err(format!(
                    "{name} has shape {} but {first} has {}: give every input as one state \
                     (1-D) or all as N states (2-D) with the same N",
                    shape_text(shape),
                    match prev {
                        None => format!("({first_n},)"),
                        Some(r) => format!("({r}, {first_n})"),
                    }
                )));
            }
            _ => {}
        }
        arrays[k] = Some(a);
    }
    Ok(Inputs {
        arrays,
        rows: rows.flatten(),
        n: lens,
    })
}

/// Rows of `n` float64 entries in memory that another object keeps alive for `'a`: row r at
/// `ptr + r * stride` (elements; 0 for a broadcast row, negative for rows in reverse order).
#[derive(Clone, Copy)]
struct RawRows<'a> {
    ptr: *const f64,
    stride: isize,
    _life: std::marker::PhantomData<&'a f64>,
}

// SAFETY: read-only access to float64 memory kept alive for 'a (as &'a [f64] would be)
unsafe impl Send for RawRows<'_> {}
// SAFETY: as above
unsafe impl Sync for RawRows<'_> {}

/// One input as rows of `n` entries.
enum Rows<'a> {
    /// float64 memory with contiguous rows, read in place.
    View(RawRows<'a>),
    /// A C-order copy (N x n).
    Copy(Vec<f64>),
    /// Omitted: zeros (the static row, or `n` zeros when longer).
    Zeros(Option<Vec<f64>>),
}

/// The inputs of one call, row by row.
pub struct States<'a> {
    inputs: [Rows<'a>; 3],
    /// None: one state; Some(N): N rows.
    pub rows: Option<usize>,
    n: [usize; 3],
}

impl States<'_> {
    /// Number of rows (1 for one state).
    pub fn count(&self) -> usize {
        self.rows.unwrap_or(1)
    }

    /// Row r (< count) of input k.
    pub fn row(&self, k: usize, r: usize) -> &[f64] {
        let n = self.n[k];
        match &self.inputs[k] {
            Rows::View(v) => {
                assert!(r < self.count());
                // SAFETY: r is a row of the array (checked), whose n entries from
                // ptr + r * stride are contiguous, aligned float64 memory alive for 'a
                unsafe { std::slice::from_raw_parts(v.ptr.offset(r as isize * v.stride), n) }
            }
            Rows::Copy(c) => &c[r * n..(r + 1) * n],
            Rows::Zeros(None) => &ZERO_ROW[..n],
            Rows::Zeros(Some(z)) => z,
        }
    }

    /// Row r of every input.
    pub fn rows3(&self, r: usize) -> [&[f64]; 3] {
        std::array::from_fn(|k| self.row(k, r))
    }
}

/// The memory of an array read in place: its rows (None when they are not contiguous) and its
/// byte span [first, last] (None when empty).
fn layout<'a>(a: &'a Bound<'_, PyArrayDyn<f64>>) -> (Option<RawRows<'a>>, Option<(usize, usize)>) {
    let (shape, strides) = (a.shape(), a.strides());
    // as rows x n: a 1-D array is one row
    let (rows, n, s0, s1) = match (shape, strides) {
        ([n], [s1]) => (1, *n, 0, *s1),
        ([r, n], [s0, s1]) => (*r, *n, *s0, *s1),
        _ => unreachable!("shapes are checked to be (n,) or (N, n)"),
    };
    let ptr = a.data() as *const f64;
    if rows == 0 || n == 0 {
        let view = RawRows {
            ptr,
            stride: 0,
            _life: std::marker::PhantomData,
        };
        return (Some(view), None);
    }
    let p = ptr as isize;
    let (mut lo, mut hi) = (p, p + 7);
    for d in [(rows as isize - 1) * s0, (n as isize - 1) * s1] {
        if d < 0 {
            lo += d;
        } else {
            hi += d;
        }
    }
    let contiguous = n == 1 || s1 == 8;
    let view = contiguous.then_some(RawRows {
        ptr,
        stride: s0 / 8,
        _life: std::marker::PhantomData,
    });
    (view, Some((lo as usize, hi as usize)))
}

impl<'py> Inputs<'py> {
    /// The inputs row by row: in place where rows are contiguous and the memory is not that of
    /// `avoid` (the caller's output, a byte span), else copied in C order.
    pub fn states(&self, avoid: Option<(usize, usize)>) -> PyResult<States<'_>> {
        let mut out: [Rows<'_>; 3] = [Rows::Zeros(None), Rows::Zeros(None), Rows::Zeros(None)];
        for (k, a) in self.arrays.iter().enumerate() {
            let n = self.n[k];
            out[k] = match a {
                None if n <= ZERO_ROW.len() => Rows::Zeros(None),
                None => Rows::Zeros(Some(try_zeros(n)?)),
                Some(a) => {
                    let (view, span) = layout(a);
                    let clash = match (avoid, span) {
                        (Some((lo, hi)), Some((a, b))) => a <= hi && lo <= b,
                        _ => false,
                    };
                    match view {
                        Some(v) if !clash => Rows::View(v),
                        _ => {
                            // SAFETY: aligned float64 memory of whole-element strides
                            // (`float64`), only read, before the output is written
                            let view = unsafe { a.as_array() };
                            let mut c = try_zeros(view.len())?;
                            for (x, y) in c.iter_mut().zip(view.iter()) {
                                *x = *y;
                            }
                            Rows::Copy(c)
                        }
                    }
                }
            };
        }
        Ok(States {
            inputs: out,
            rows: self.rows,
            n: self.n,
        })
    }
}

/// The shape of a result: up to four dimensions, no allocation.
#[derive(Clone, Copy)]
pub struct Shape {
    dims: [usize; 4],
    len: usize,
}

impl Shape {
    /// The shape `dims` (at most four).
    pub fn of(dims: &[usize]) -> Shape {
        let mut s = Shape {
            dims: [0; 4],
            len: dims.len(),
        };
        s.dims[..dims.len()].copy_from_slice(dims);
        s
    }

    /// `one` for one state, (N, *one) for N states.
    pub fn rows(rows: Option<usize>, one: &[usize]) -> Shape {
        match rows {
            None => Shape::of(one),
            Some(r) => {
                let mut s = Shape::of(&[r]);
                s.dims[1..=one.len()].copy_from_slice(one);
                s.len = 1 + one.len();
                s
            }
        }
    }

    /// The result of a call: `rows` as [`Shape::rows`], or with `stacked` the N results
    /// stacked (the regressor: (N n, p) for one-state results (n, p)).
    pub fn result(rows: Option<usize>, one: &[usize], stacked: bool) -> Shape {
        match (rows, stacked) {
            // an overflowing count is refused by `size` (MemoryError)
            (Some(r), true) => Shape::of(&[r.saturating_mul(one[0]), one[1]]),
            (rows, _) => Shape::rows(rows, one),
        }
    }

    /// The dimensions.
    pub fn dims(&self) -> &[usize] {
        &self.dims[..self.len]
    }

    /// Number of entries, or MemoryError when it does not fit in memory's addresses.
    pub fn size(&self) -> PyResult<usize> {
        self.dims()
            .iter()
            .try_fold(1usize, |a, &d| a.checked_mul(d))
            .filter(|&s| s <= isize::MAX as usize / 8)
            .ok_or_else(|| {
                PyMemoryError::new_err(format!(
                    "a result of shape {} does not fit in memory",
                    shape_text(self.dims())
                ))
            })
    }
}

/// Where the results of a call go.
pub enum Output<'py> {
    /// A new NumPy array (one state: made directly).
    Array(Bound<'py, PyArrayDyn<f64>>),
    /// A new buffer, handed to NumPy at the end (N states).
    Buffer(Vec<f64>, Shape),
    /// The caller's `out`, checked.
    Given(Bound<'py, PyArrayDyn<f64>>),
}

impl<'py> Output<'py> {
    /// The caller's `out` if given (checked against `shape`), else a new result.
    pub fn new(
        py: Python<'py>,
        out: Option<&Bound<'py, PyAny>>,
        shape: Shape,
        batch: bool,
    ) -> PyResult<Output<'py>> {
        if let Some(o) = out {
            return given(o, shape).map(Output::Given);
        }
        if batch {
            return Ok(Output::Buffer(try_zeros(shape.size()?)?, shape));
        }
        // SAFETY: uninitialized float64 memory of a fresh C-order array: every entry is written
        // by the model before the array is returned (an error drops it unread)
        let a = unsafe { PyArrayDyn::<f64>::new(py, shape.dims(), false) };
        Ok(Output::Array(a))
    }

    /// The byte span of the caller's `out` (inputs there are copied before it is written).
    pub fn span(&self) -> Option<(usize, usize)> {
        match self {
            Output::Given(a) => {
                let len = a.len();
                let p = a.data() as usize;
                (len > 0).then(|| (p, p + 8 * len - 1))
            }
            _ => None,
        }
    }

    /// The result's entries (C order).
    pub fn slice(&mut self) -> &mut [f64] {
        match self {
            // SAFETY: a fresh array (no other reference yet) or the caller's `out`, checked
            // C-contiguous, aligned and writeable, and not overlapping an input read in place
            Output::Array(a) | Output::Given(a) => unsafe {
                a.as_slice_mut().expect("C-contiguous (checked)")
            },
            Output::Buffer(v, _) => v,
        }
    }

    /// The result as a Python object (the caller's `out` itself when given).
    pub fn finish(self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        match self {
            Output::Array(a) | Output::Given(a) => Ok(a.into_any()),
            Output::Buffer(v, shape) => {
                Ok(PyArray1::from_vec(py, v).reshape(shape.dims())?.into_any())
            }
        }
    }
}

/// The caller's `out`: a float64, C-contiguous, aligned, writeable array of `shape`.
fn given<'py>(o: &Bound<'py, PyAny>, shape: Shape) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let Ok(a) = o.cast::<PyArrayDyn<f64>>() else {
        let dtype = o
            .getattr("dtype")
            .map(|d| d.to_string())
            .unwrap_or_else(|_| o.get_type().to_string());
        return Err(InputError::new_err(format!(
            "out must be a float64 NumPy array, got {dtype}"
        )));
    };
    if a.shape() != shape.dims() {
        return Err(DimensionError::new_err(format!(
            "out has shape {}, the result has shape {}",
            shape_text(a.shape()),
            shape_text(shape.dims())
        )));
    }
    // SAFETY: the array object is alive (borrowed); its flags field is plain data
    let flags = unsafe { (*a.as_array_ptr()).flags };
    if !a.is_c_contiguous() || flags & npyffi::NPY_ARRAY_ALIGNED == 0 {
        return Err(InputError::new_err(
            "out must be C-contiguous (and aligned): the result is written in place, row by row",
        ));
    }
    if flags & npyffi::NPY_ARRAY_WRITEABLE == 0 {
        return Err(InputError::new_err("out is read-only"));
    }
    Ok(a.clone())
}

/// Run `f(first, out_block)` on blocks of the rows `0..rows` of `out` (`width` entries per
/// row) with the GIL released, checking the signals between blocks (Ctrl-C raises
/// KeyboardInterrupt): blocks grow or shrink to take about [`SIGNAL_INTERVAL`]. `first` is the
/// block's first row.
pub fn in_blocks<F>(
    py: Python<'_>,
    rows: usize,
    out: &mut [f64],
    width: usize,
    mut f: F,
) -> PyResult<()>
where
    F: FnMut(usize, &mut [f64]) -> robodyn::Result<()> + Send,
{
    let mut start = 0;
    let mut block = 256usize;
    while start < rows {
        let end = rows.min(start + block);
        let t = Instant::now();
        let o = &mut out[start * width..end * width];
        py.detach(|| f(start, o)).py()?;
        py.check_signals()?;
        let took = t.elapsed().as_secs_f64().max(1e-6);
        let scale = (SIGNAL_INTERVAL.as_secs_f64() / took).clamp(0.25, 4.0);
        block = ((block as f64 * scale) as usize).clamp(1, 1 << 22);
        start = end;
    }
    Ok(())
}

/// The library's error of a row of a block starting at `first`, renumbered in the whole batch.
pub fn shift_row(e: robodyn::Error, first: usize) -> robodyn::Error {
    match e {
        robodyn::Error::Row { row, source } => robodyn::Error::Row {
            row: row + first,
            source,
        },
        e => e,
    }
}
