//! `robodyn.excite(robot, period, harmonics, **options)`: an exciting trajectory for
//! identification (the library's `identification::excitation::design`, the CLI's `robodyn
//! excite`), returned as NumPy arrays sampled as the CLI's CSV.

use crate::errors::{InputError, IntoPy};
use crate::identification::description;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::identification::excitation::{design, Design, DesignOptions, Limits};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::parameters::{ParameterModel, ParameterOptions};

/// Rows of the sampled trajectory at most (as the CLI).
const MAX_ROWS: f64 = 1e8;

/// One value for every joint, or one per joint (None: not given).
fn per_joint(name: &str, v: Option<&Bound<'_, PyAny>>, n: usize) -> PyResult<Option<Vec<f64>>> {
    let Some(v) = v.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    if let Ok(x) = v.extract::<f64>() {
        return Ok(Some(vec![x; n]));
    }
    let (vals, shape) = crate::arrays::values(v)?;
    if shape.len() != 1 || vals.len() != n {
        return Err(InputError::new_err(format!(
            "{name}: one number or one per actuated joint ({n}) expected, got shape {shape:?}"
        )));
    }
    Ok(Some(vals))
}

/// The limits of each actuated joint: the arguments', else the robot file's; velocity and
/// acceleration limits required.
fn limits(access: &ModelAccess, given: [Option<Vec<f64>>; 5]) -> PyResult<Vec<Limits>> {
    let [qmin, qmax, qd, qdd, tau] = given;
    let mut out = Vec::new();
    for (k, &j) in access.actuated_joints().iter().enumerate() {
        let f = access.limits(j);
        let pick = |c: &Option<Vec<f64>>, file: Option<f64>| c.as_ref().map(|v| v[k]).or(file);
        let need = |v: Option<f64>, what: &str, arg: &str| -> PyResult<f64> {
            v.ok_or_else(|| {
                InputError::new_err(format!(
                    "joint {j}: no {what} limit: give {arg} or `limits` in the robot file's \
                     frame {j}"
                ))
            })
        };
        out.push(Limits {
            q_min: pick(&qmin, f.q_min),
            q_max: pick(&qmax, f.q_max),
            qd: need(pick(&qd, f.qd), "velocity", "qd_max")?,
            qdd: need(pick(&qdd, f.qdd), "acceleration", "qdd_max")?,
            tau: pick(&tau, f.tau),
        });
    }
    Ok(out)
}

/// The designed trajectory sampled at `rate` over `periods` periods: t and q, qd, qdd (rows of
/// N), as the CLI's CSV rows (t = k / rate, k = 0..=period periods rate).
fn sampled(d: &Design, period: f64, rate: f64, rows: usize) -> (Vec<f64>, [Vec<f64>; 3]) {
    let mut t = Vec::with_capacity(rows + 1);
    let mut v: [Vec<f64>; 3] = Default::default();
    for k in 0..=rows {
        let tk = k as f64 / rate;
        let s = d.trajectory.eval(tk % period);
        for (out, s) in v.iter_mut().zip(s) {
            out.extend(s);
        }
        t.push(tk);
    }
    (t, v)
}

/// Design an exciting trajectory for identifying `robot` (a `Robot` or a robot file's path): a
/// finite Fourier series of `harmonics` harmonics and period `period` (s) per actuated joint,
/// at rest at t = 0 and T, whose coefficients minimize the condition number of the
/// base-parameter observation matrix (random starts, then Nelder–Mead), every candidate scaled
/// to its binding limit — the CLI's `robodyn excite`, the same numbers.
///
/// Options: `start` (start and end positions; default the assembly's, else zeros), `q_min`,
/// `q_max`, `qd_max`, `qdd_max`, `tau_max` (one number or one per actuated joint; default the
/// robot file's `limits`; velocity and acceleration limits required), `samples` (100, points
/// of the period where W is evaluated), `iterations` (1500), `restarts` (20), `seed` (1),
/// `rotor` ("actuated"), `friction` (True), `offsets` (False) — the parameters, as
/// `identify` — and `rate` (200 Hz), `periods` (1): the sampling of the returned arrays.
///
/// Returns a dict: `t` (M,), `q`, `qd`, `qdd` (M, nq) at t = k / rate (the CLI's CSV rows),
/// `condition_number` (unit-column W over the period), `initial_condition_number` (the best
/// random start's), `binding` ((what, joint): the limit reached, what one of "velocity",
/// "acceleration", "position", "torque", "none"), `peaks` (nq, 4: largest |q - start|, |qd|,
/// |qdd|, |tau| per joint), `joints` (frame numbers), `evaluations`. Runs with the GIL
/// released.
#[pyfunction]
#[pyo3(signature = (robot, period, harmonics, *, start=None, q_min=None, q_max=None,
                    qd_max=None, qdd_max=None, tau_max=None, samples=100, iterations=1500,
                    restarts=20, seed=1, rotor="actuated", friction=true, offsets=false,
                    rate=200.0, periods=1))]
#[allow(clippy::too_many_arguments)]
pub fn excite<'py>(
    py: Python<'py>,
    robot: &Bound<'py, PyAny>,
    period: f64,
    harmonics: usize,
    start: Option<&Bound<'py, PyAny>>,
    q_min: Option<&Bound<'py, PyAny>>,
    q_max: Option<&Bound<'py, PyAny>>,
    qd_max: Option<&Bound<'py, PyAny>>,
    qdd_max: Option<&Bound<'py, PyAny>>,
    tau_max: Option<&Bound<'py, PyAny>>,
    samples: usize,
    iterations: u64,
    restarts: usize,
    seed: u64,
    rotor: &str,
    friction: bool,
    offsets: bool,
    rate: f64,
    periods: usize,
) -> PyResult<Bound<'py, PyDict>> {
    if !(rate.is_finite() && rate > 0.0) || periods == 0 {
        return Err(InputError::new_err(format!(
            "rate {rate} and periods {periods}: a positive rate and at least 1 period expected"
        )));
    }
    let rows = period * periods as f64 * rate;
    if rows.is_nan() || rows > MAX_ROWS {
        return Err(InputError::new_err(format!(
            "period {period} x periods {periods} x rate {rate} = {rows:e} rows: at most \
             {MAX_ROWS:e}"
        )));
    }
    let mut access = ModelAccess::new(description(robot)?).py()?;
    let n = access.actuated_joints().len();
    let start = match per_joint("start", start, n)? {
        Some(v) => v,
        None => access.reference_actuated().py()?,
    };
    let given = [
        per_joint("q_min", q_min, n)?,
        per_joint("q_max", q_max, n)?,
        per_joint("qd_max", qd_max, n)?,
        per_joint("qdd_max", qdd_max, n)?,
        per_joint("tau_max", tau_max, n)?,
    ];
    let limits = limits(&access, given)?;
    let popt = ParameterOptions {
        rotors: crate::robot::parse_rotor(rotor)?,
        friction,
        offsets,
        seed,
        ..ParameterOptions::default()
    };
    let opt = DesignOptions {
        period,
        harmonics,
        start,
        limits,
        samples,
        iterations,
        restarts,
        seed,
    };
    let d = py
        .detach(|| {
            let mut params = ParameterModel::build(&mut access, &popt)?;
            design(&mut access, &mut params, &opt)
        })
        .py()?;
    let (t, [q, qd, qdd]) = sampled(&d, period, rate, rows.round() as usize);
    let m = t.len();
    let out = PyDict::new(py);
    out.set_item("t", PyArray1::from_vec(py, t))?;
    for (name, v) in [("q", q), ("qd", qd), ("qdd", qdd)] {
        out.set_item(name, PyArray1::from_vec(py, v).reshape([m, n])?)?;
    }
    out.set_item("condition_number", d.condition)?;
    out.set_item("initial_condition_number", d.initial_condition)?;
    let joint = access.actuated_joints()[d.binding.joint];
    out.set_item("binding", (d.binding.what, joint))?;
    let peaks: Vec<f64> = d.peaks.iter().flatten().copied().collect();
    out.set_item("peaks", PyArray1::from_vec(py, peaks).reshape([n, 4])?)?;
    out.set_item("joints", access.actuated_joints().to_vec())?;
    out.set_item("evaluations", d.evaluations)?;
    Ok(out)
}
