//! Base parameters, code generation and simulation for Python.

use crate::arrays::SIGNAL_INTERVAL;
use crate::errors::{InputError, IntoPy};
use crate::robot::{parse_method, parse_rotor, Robot};
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use robodyn::algorithms::base_parameters::symbolic::standard_index;
use robodyn::algorithms::base_parameters::{
    compare_methods, generic_values_note, geometry_robot, numeric_base_parameters_auto,
    standard_values, symbolic_base_parameters, NumericBase, NumericOptions, ParameterNames,
    Summary, SymbolicBase,
};
use robodyn::algorithms::regressor::{
    parameter_name, Friction, ParameterSelection, ZeroParameters,
};
use robodyn::codegen::{generate as gen, BaseParameters as GenBase, GenOptions, ModelKind};
use robodyn::simulation::{
    simulate as sim, Dynamics, Integrator, Recorder, SimOptions, TimeSeries, TorqueInput,
    TreeDynamics, Wrapper,
};
use robodyn_symbolic::{emit, Lang};
use std::collections::HashMap;
use std::time::Instant;

/// Base inertial parameters of a robot by one method (§10.2.4, §10.3.4–10.3.6).
#[pyclass(module = "robodyn", frozen, get_all)]
pub struct BaseParameters {
    /// "symbolic" or "numeric".
    pub method: String,
    /// Names of the base parameters (the robot's names, `R` suffix when grouped: `XXR2`).
    pub names: Vec<String>,
    /// Their indices in K (13 per link, 0-based).
    pub indices: Vec<usize>,
    /// Whether each is a combination of standard parameters.
    pub regrouped: Vec<bool>,
    /// Grouping equations (right-hand sides) as text in the robot's names.
    pub equations: Vec<String>,
    /// Values for the robot's numbers (None where a parameter involved has no value).
    pub values: Vec<Option<f64>>,
    /// Names of the standard parameters of the model (selected and existing): the columns of
    /// `coefficients`.
    pub columns: Vec<String>,
    /// Coefficient table (n_base x len(columns)): K_base = coefficients @ K[columns] for the
    /// robot's geometry (None when a geometry symbol has no value).
    pub coefficients: Option<Py<PyAny>>,
    /// Parameters with no effect on the dynamics.
    pub no_effect: Vec<String>,
    /// Parameters grouped into base parameters.
    pub grouped: Vec<String>,
    /// Notes (method details, loops, comparison of the methods).
    pub notes: Vec<String>,
    /// The per-link table like Table 10.2 (rows of strings).
    pub table: Vec<Vec<String>>,
    /// The report as text (what `robodyn base-params` prints).
    pub report: String,
    /// The report as JSON text (the CLI's `--format json`).
    pub json: String,
}

#[pymethods]
impl BaseParameters {
    fn __len__(&self) -> usize {
        self.names.len()
    }
    fn __repr__(&self) -> String {
        format!(
            "BaseParameters(method={:?}, count={}, names={:?})",
            self.method,
            self.names.len(),
            self.names
        )
    }
}

impl BaseParameters {
    fn from_summary(
        py: Python<'_>,
        s: &Summary,
        coefficients: Option<Vec<Vec<f64>>>,
    ) -> PyResult<BaseParameters> {
        let coefficients = match coefficients {
            Some(rows) if !rows.is_empty() => {
                Some(PyArray2::from_vec2(py, &rows)?.into_any().unbind())
            }
            Some(_) => Some(
                PyArray2::<f64>::zeros(py, [0, s.columns.len()], false)
                    .into_any()
                    .unbind(),
            ),
            None => None,
        };
        Ok(BaseParameters {
            method: s.method.to_string(),
            names: s.base.iter().map(|b| b.name.clone()).collect(),
            indices: s.base.iter().map(|b| b.index).collect(),
            regrouped: s.base.iter().map(|b| b.regrouped).collect(),
            equations: s.base.iter().map(|b| b.equation.clone()).collect(),
            values: s.base.iter().map(|b| b.value).collect(),
            columns: s
                .columns
                .iter()
                .map(|&i| s.names.name(i).to_string())
                .collect(),
            coefficients,
            no_effect: s.no_effect.clone(),
            grouped: s.grouped.clone(),
            notes: s.notes.clone(),
            table: s.table(),
            report: robodyn::report::base_parameters::text(s),
            json: serde_json::to_string_pretty(&robodyn::report::base_parameters::json(s))
                .unwrap_or_default(),
        })
    }
}

/// Base parameters of `robot` (see `Robot.base_parameters`).
pub fn base_parameters(
    py: Python<'_>,
    robot: &Robot,
    method: &str,
    friction: bool,
    rotor: &str,
    zeros: Option<&str>,
    seed: u64,
) -> PyResult<BaseParameters> {
    let model = robot.model();
    let zeros = robot.zeros(zeros)?;
    base_parameters_of(
        py,
        model.description(),
        Some(&model),
        zeros,
        method,
        friction,
        rotor,
        seed,
    )
}

/// `robodyn.base_parameters(path, ...)`: the base parameters of a robot file, values or not
/// (as `robodyn base-params`): the symbolic method works on the symbols, the numerical one on
/// the geometry with generic values for symbols without one (the count and grouping then hold
/// for generic values, said in the notes; no coefficient table is given for such geometry).
#[pyfunction]
#[pyo3(name = "base_parameters", signature = (path, method="symbolic", friction=true, rotor="actuated", zeros=None, seed=1, **values))]
#[allow(clippy::too_many_arguments)]
pub fn base_parameters_of_file(
    py: Python<'_>,
    path: std::path::PathBuf,
    method: &str,
    friction: bool,
    rotor: &str,
    zeros: Option<&str>,
    seed: u64,
    values: Option<&Bound<'_, PyDict>>,
) -> PyResult<BaseParameters> {
    let mut desc = robodyn::io::load_description(&path).py()?;
    let values = crate::robot::kwargs_values(values)?;
    crate::robot::check_finite(&values)?;
    robodyn::io::set_values(&mut desc, &values).py()?;
    let zeros = crate::robot::parse_zeros(zeros, Some(&path))?;
    base_parameters_of(py, &desc, None, zeros, method, friction, rotor, seed)
}

/// Base parameters of `desc`; the numerical method on `model`, or (None) on its geometry with
/// generic values for symbols without one (the CLI's `base-params`).
#[allow(clippy::too_many_arguments)]
fn base_parameters_of(
    py: Python<'_>,
    desc: &robodyn::RobotDescription,
    model: Option<&robodyn::Robot>,
    zeros: ZeroParameters,
    method: &str,
    friction: bool,
    rotor: &str,
    seed: u64,
) -> PyResult<BaseParameters> {
    desc.require_no_motor_drive_parameters("base_parameters")
        .py()?;
    let (symbolic, numeric) = match method {
        "symbolic" => (true, false),
        "numeric" => (false, true),
        "both" => (true, true),
        _ => {
            return Err(InputError::new_err(format!(
                "method = {method:?}: expected \"symbolic\", \"numeric\" or \"both\""
            )))
        }
    };
    let friction = if friction {
        Friction::Actuated
    } else {
        Friction::None
    };
    let sel = ParameterSelection::from_description(desc, parse_rotor(rotor)?, friction)
        .with_zero_parameters(desc, zeros);
    let names = ParameterNames::of(desc);
    let (summary, coef) = py
        .detach(|| -> robodyn::Result<(Summary, Option<Vec<Vec<f64>>>)> {
            let sb = symbolic
                .then(|| symbolic_base_parameters(desc, &sel))
                .transpose()?;
            let mut generic = Vec::new();
            let nb = numeric
                .then(|| {
                    let opt = NumericOptions {
                        selection: sel.clone(),
                        samples: None,
                        seed,
                    };
                    match model {
                        Some(m) => numeric_base_parameters_auto(m, &opt),
                        None => {
                            let (g, values) = geometry_robot(desc)?;
                            generic = values;
                            numeric_base_parameters_auto(&g, &opt)
                        }
                    }
                })
                .transpose()?;
            let mut s = match (&sb, &nb) {
                (Some(sb), _) => Summary::from_symbolic(desc, sb, &names),
                (None, Some((nb, _))) => {
                    Summary::from_numeric(desc, nb, &names, &standard_values(desc))
                }
                _ => unreachable!("a method is chosen"),
            };
            if let Some((nb, start)) = &nb {
                if let Some(start) = start {
                    s.notes.push(format!("closed chain: {}", start.describe()));
                }
                if let Some(note) = generic_values_note(&generic) {
                    s.notes
                        .push(format!("{note} (give values as keyword arguments)"));
                }
                if let Some(sb) = &sb {
                    s.add_comparison(&compare_methods(sb, nb, &names));
                }
            }
            let coef = coefficients(
                desc,
                &s,
                sb.as_ref(),
                nb.as_ref().map(|(nb, _)| nb),
                &generic,
            );
            Ok((s, coef))
        })
        .py()?;
    BaseParameters::from_summary(py, &summary, coef)
}

/// The coefficient table K_base = coefficients @ K[columns] of a summary: the symbolic
/// method's equations at unit parameters, or the numerical method's K1 + beta K2 for the
/// robot's geometry (None when that geometry took generic values, or a value is missing).
fn coefficients(
    desc: &robodyn::RobotDescription,
    s: &Summary,
    sb: Option<&SymbolicBase>,
    nb: Option<&NumericBase>,
    generic: &[(String, f64)],
) -> Option<Vec<Vec<f64>>> {
    let position: HashMap<usize, usize> =
        s.columns.iter().enumerate().map(|(c, &i)| (i, c)).collect();
    match (sb, nb) {
        // K_base = K1 + beta K2, beta for the robot's geometry (not a generic one)
        (None, Some(nb)) if generic.is_empty() => Some(
            (0..nb.count())
                .map(|r| {
                    let mut row = vec![0.0; s.columns.len()];
                    if let Some(&c) = position.get(&nb.base[r]) {
                        row[c] = 1.0;
                    }
                    for (g, &i) in nb.grouped.iter().enumerate() {
                        if let Some(&c) = position.get(&i) {
                            row[c] += nb.beta[(r, g)];
                        }
                    }
                    row
                })
                .collect(),
        ),
        // the equations are linear in the standard parameters: the coefficient of column c is
        // the equation at K = e_c
        (Some(sb), _) => sb
            .equations
            .iter()
            .map(|eq| {
                s.columns
                    .iter()
                    .map(|&c| {
                        let unit = parameter_name(c);
                        eq.eval(&|name: &str| {
                            if name == unit {
                                Some(1.0)
                            } else if standard_index(name, desc.nl).is_some() {
                                Some(0.0)
                            } else {
                                desc.symbols.get(name).copied()
                            }
                        })
                        .ok()
                    })
                    .collect::<Option<Vec<f64>>>()
            })
            .collect::<Option<Vec<_>>>(),
        _ => None,
    }
}

/// A generated customized model.
#[pyclass(module = "robodyn", frozen, get_all)]
pub struct Generated {
    /// Function name.
    pub name: String,
    /// The code (or SYMORO-style text / LaTeX).
    pub code: String,
    /// Multiplications and divisions.
    pub multiplications: usize,
    /// Additions and subtractions.
    pub additions: usize,
    /// Elementary function calls (sin, cos...).
    pub functions: usize,
    /// The values of the code's parameters `p`, as (name, value) pairs in the order of its
    /// header (`None` for a symbol the robot file leaves free; empty with `numeric=True`): the
    /// generated Python takes `dict(parameters)`.
    pub parameters: Vec<(String, Option<f64>)>,
}

#[pymethods]
impl Generated {
    fn __repr__(&self) -> String {
        format!(
            "Generated({:?}, {} multiplications, {} additions)",
            self.name, self.multiplications, self.additions
        )
    }
    fn __str__(&self) -> String {
        self.code.clone()
    }
}

/// Customized symbolic model of `robot` (see `Robot.generate`).
#[allow(clippy::too_many_arguments)]
pub fn generate(
    py: Python<'_>,
    robot: &robodyn::Robot,
    model: &str,
    lang: &str,
    params: &str,
    symmetric: bool,
    friction: bool,
    rotor: bool,
    numeric: bool,
    name: Option<String>,
    zeros: ZeroParameters,
) -> PyResult<Generated> {
    let kind = match model {
        "idm" => ModelKind::Idm,
        "idm_derivatives" => ModelKind::IdmDerivatives,
        "inertia" => ModelKind::Inertia,
        "h" => ModelKind::H,
        "ddm" => ModelKind::Ddm,
        "closed" => ModelKind::Closed,
        "w" => ModelKind::W,
        _ => {
            return Err(InputError::new_err(format!(
                "model = {model:?}: expected idm, idm_derivatives, inertia, h, ddm, closed or w"
            )))
        }
    };
    let lang = Lang::from_name(lang).ok_or_else(|| {
        InputError::new_err(format!(
            "lang = {lang:?}: expected {}",
            crate::robot::quoted(Lang::ALL.map(Lang::name).as_slice())
        ))
    })?;
    let desc = robot.description();
    let base = match params {
        "standard" => None,
        "base" => Some(GenBase::symbolic(desc, rotor, friction).py()?),
        _ => {
            return Err(InputError::new_err(format!(
                "params = {params:?}: expected \"standard\" or \"base\""
            )))
        }
    };
    let opt = GenOptions {
        model: kind,
        numeric,
        symmetric,
        friction,
        rotor,
        base,
        g: None,
        name,
        optimize: true,
        zeros,
    };
    let prog = py.detach(|| gen(desc, &opt)).py()?;
    let c = prog.count();
    Ok(Generated {
        code: emit(&prog, lang),
        name: prog.name.clone(),
        multiplications: c.mul,
        additions: c.add,
        functions: c.func,
        parameters: robodyn::codegen::parameter_values(desc, &opt, &prog),
    })
}

/// Torques from a Python callable `torque(t, q, qd) -> tau` around another system.
struct Callback<'a> {
    inner: &'a mut (dyn Dynamics + Send),
    f: Py<PyAny>,
    tau: Vec<f64>,
    widths: TorqueWidths,
    error: Option<PyErr>,
}

/// The callback's torques at (t, q, qd) into `out` (nv): nv values, or the joints' alone with
/// a floating base (its wrench zero).
fn call_torque(
    f: &Py<PyAny>,
    widths: TorqueWidths,
    t: f64,
    q: &[f64],
    qd: &[f64],
    out: &mut [f64],
) -> PyResult<()> {
    Python::attach(|py| {
        let r = f.call1(
            py,
            (t, PyArray1::from_slice(py, q), PyArray1::from_slice(py, qd)),
        )?;
        let (v, _) = crate::arrays::values(r.bind(py))?;
        if !widths.accepts(v.len()) {
            return Err(crate::errors::DimensionError::new_err(format!(
                "the torque callback returned {} values, {} expected",
                v.len(),
                widths.expected()
            )));
        }
        let base = out.len() - v.len();
        out[..base].fill(0.0);
        out[base..].copy_from_slice(&v);
        Ok(())
    })
}

impl Wrapper for Callback<'_> {
    fn inner(&self) -> &dyn Dynamics {
        &*self.inner
    }
    fn inner_mut(&mut self) -> &mut dyn Dynamics {
        &mut *self.inner
    }
    fn accel(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        _tau: &[f64],
        qdd: &mut [f64],
    ) -> robodyn::Result<()> {
        if let Err(e) = call_torque(&self.f, self.widths, t, q, qd, &mut self.tau) {
            self.error = Some(e);
            return Err(robodyn::Error::Input("the torque callback failed".into()));
        }
        self.inner.accel(t, q, qd, &self.tau, qdd)
    }
}

/// Another system whose evaluations check the Python signals about every
/// [`SIGNAL_INTERVAL`]: Ctrl-C stops a run (KeyboardInterrupt), however long.
struct Interruptible<'a> {
    inner: &'a mut (dyn Dynamics + Send),
    last: Instant,
    calls: u32,
    error: Option<PyErr>,
}

impl Wrapper for Interruptible<'_> {
    fn inner(&self) -> &dyn Dynamics {
        &*self.inner
    }
    fn inner_mut(&mut self) -> &mut dyn Dynamics {
        &mut *self.inner
    }
    fn accel(
        &mut self,
        t: f64,
        q: &[f64],
        qd: &[f64],
        tau: &[f64],
        qdd: &mut [f64],
    ) -> robodyn::Result<()> {
        self.calls = self.calls.wrapping_add(1);
        if self.calls.is_multiple_of(16) && self.last.elapsed() >= SIGNAL_INTERVAL {
            self.last = Instant::now();
            if let Err(e) = Python::attach(|py| py.check_signals()) {
                self.error = Some(e);
                return Err(robodyn::Error::Input("interrupted".into()));
            }
        }
        self.inner.accel(t, q, qd, tau, qdd)
    }
}

// the default of `max_steps` in the signatures of `simulate` (a literal, so that Python's
// `inspect.signature` shows it) is the library's, the CLI's
const _: () = assert!(robodyn::simulation::DEFAULT_MAX_STEPS == 5_000_000);

/// Simulation settings shared by trees and closed chains.
pub struct SimArgs<'py> {
    pub duration: f64,
    pub q0: Vec<f64>,
    pub qd0: Vec<f64>,
    pub torque: Option<Bound<'py, PyAny>>,
    pub dt: Option<f64>,
    pub rtol: f64,
    pub atol: f64,
    pub output_dt: f64,
    pub max_steps: usize,
}

/// The torque input of a simulation of `nv` coordinates whose first `base` are a floating
/// base's (a callable is returned apart: it is called from the run). Joint torques alone (nv -
/// base columns) leave the base free ([`TorqueInput::with_free_base`]).
fn torque_input(
    torque: Option<&Bound<'_, PyAny>>,
    nv: usize,
    base: usize,
) -> PyResult<(TorqueInput, Option<Py<PyAny>>)> {
    let widths = TorqueWidths { nv, base };
    let input = match torque {
        None => return Ok((TorqueInput::Constant(vec![0.0; nv]), None)),
        Some(t) if t.is_callable() => {
            return Ok((
                TorqueInput::Constant(vec![0.0; nv]),
                Some(t.clone().unbind()),
            ))
        }
        Some(t) if t.is_instance_of::<PyTuple>() => {
            let (times, values): (Bound<PyAny>, Bound<PyAny>) = t.extract()?;
            let (times, _) = crate::arrays::values(&times)?;
            let (flat, shape) = crate::arrays::values(&values)?;
            if shape.len() != 2 || !widths.accepts(shape[1]) || shape[0] != times.len() {
                return Err(crate::errors::DimensionError::new_err(format!(
                    "torque = (times, values): values has shape {shape:?}, expected ({}, {})",
                    times.len(),
                    widths.expected()
                )));
            }
            let rows = flat.chunks(shape[1].max(1)).map(|c| c.to_vec()).collect();
            TorqueInput::Series(TimeSeries::new(times, rows).py()?)
        }
        Some(t) => {
            let v = crate::arrays::values(t)?.0;
            if !widths.accepts(v.len()) {
                return Err(crate::errors::DimensionError::new_err(format!(
                    "torque has {} values, {} expected",
                    v.len(),
                    widths.expected()
                )));
            }
            TorqueInput::Constant(v)
        }
    };
    Ok((widths.widen(input), None))
}

/// The accepted widths of a torque input: nv, or the joints' nv - base with a floating base.
#[derive(Clone, Copy)]
struct TorqueWidths {
    nv: usize,
    base: usize,
}

impl TorqueWidths {
    fn accepts(self, w: usize) -> bool {
        w == self.nv || (self.base > 0 && w == self.nv - self.base)
    }
    /// What the messages say is expected.
    fn expected(self) -> String {
        match self.base {
            0 => self.nv.to_string(),
            b => format!("{} joints or {} with the base wrench", self.nv - b, self.nv),
        }
    }
    /// Joint torques alone widened with a free base's zero wrench.
    fn widen(self, input: TorqueInput) -> TorqueInput {
        let width = match &input {
            TorqueInput::Constant(v) => v.len(),
            TorqueInput::Series(s) => s.width(),
            TorqueInput::Pd { .. } => self.nv,
        };
        if self.base > 0 && width == self.nv - self.base {
            input.with_free_base(self.base)
        } else {
            input
        }
    }
}

/// Run a simulation of `dynamics` and return the trajectory as a dict of arrays.
pub fn run_simulation<'py>(
    py: Python<'py>,
    dynamics: &mut (dyn Dynamics + Send),
    a: SimArgs<'py>,
) -> PyResult<Bound<'py, PyDict>> {
    let (nq, n) = (dynamics.nq(), dynamics.dof());
    let widths = TorqueWidths {
        nv: n,
        base: n - dynamics.labels().len(),
    };
    if a.max_steps == 0 {
        return Err(InputError::new_err("max_steps = 0: must be at least 1"));
    }
    let (input, callback) = torque_input(a.torque.as_ref(), n, widths.base)?;
    let opts = SimOptions {
        duration: a.duration,
        integrator: Integrator::fixed_or_adaptive(a.dt, a.rtol, a.atol),
        output_dt: a.output_dt,
        max_steps: Some(a.max_steps),
    };
    let mut rec = Recorder::default();
    let mut cb = None;
    let inner: &mut (dyn Dynamics + Send) = match &callback {
        Some(f) => cb.insert(Callback {
            inner: dynamics,
            f: f.clone_ref(py),
            tau: vec![0.0; n],
            widths,
            error: None,
        }),
        None => dynamics,
    };
    let mut run = Interruptible {
        inner,
        last: Instant::now(),
        calls: 0,
        error: None,
    };
    let result = py.detach(|| {
        sim(
            &mut run,
            &input,
            &a.q0,
            &a.qd0,
            &opts,
            &mut rec,
            &mut |_| {},
        )
    });
    let interrupted = run.error.take();
    if let Some(e) = interrupted.or_else(|| cb.as_mut().and_then(|c| c.error.take())) {
        return Err(e);
    }
    if let Some(f) = &callback {
        // the recorded torques are the callback's at each output row
        for row in rec.rows.iter_mut() {
            let (t, rest) = row.split_at_mut(1);
            let (q, rest) = rest.split_at_mut(nq);
            let (qd, rest) = rest.split_at_mut(n);
            call_torque(f, widths, t[0], q, qd, &mut rest[n..2 * n])?;
        }
    }
    result.py()?;
    trajectory(py, &rec, nq, n, widths)
}

/// The recorded trajectory as a dict of arrays: its rows are t, q (nq), qd, qdd, tau (nv),
/// energy, extras.
fn trajectory<'py>(
    py: Python<'py>,
    rec: &Recorder,
    nq: usize,
    nv: usize,
    widths: TorqueWidths,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let rows = rec.rows.len();
    let col = |c: usize| -> Vec<f64> { rec.rows.iter().map(|r| r[c]).collect() };
    let block = |c0: usize, w: usize| -> Vec<f64> {
        rec.rows
            .iter()
            .flat_map(|r| r[c0..c0 + w].iter().copied())
            .collect()
    };
    out.set_item("t", PyArray1::from_vec(py, col(0)))?;
    let mut c0 = 1;
    for (name, w) in [("q", nq), ("qd", nv), ("qdd", nv), ("tau", nv)] {
        out.set_item(
            name,
            PyArray1::from_vec(py, block(c0, w)).reshape([rows, w])?,
        )?;
        c0 += w;
    }
    out.set_item("energy", PyArray1::from_vec(py, col(c0)))?;
    for (k, h) in rec.headers.iter().enumerate().skip(c0 + 1) {
        out.set_item(h, PyArray1::from_vec(py, col(k)))?;
    }
    // the joints' labels (after a floating base's 7 configuration columns)
    let joints = &rec.headers[1 + nq - (nv - widths.base)..1 + nq];
    out.set_item(
        "joint_labels",
        joints
            .iter()
            .map(|h| h[1..].to_string())
            .collect::<Vec<_>>(),
    )?;
    out.set_item("q_columns", rec.headers[1..1 + nq].to_vec())?;
    out.set_item("v_columns", rec.headers[1 + nq..1 + nq + nv].to_vec())?;
    Ok(out)
}

/// A tree's simulated system.
pub fn tree_dynamics<'a>(
    robot: &'a robodyn::Robot,
    method: &str,
    coulomb_smoothing: Option<f64>,
) -> PyResult<TreeDynamics<'a>> {
    Ok(TreeDynamics::new(robot, parse_method(method)?).with_coulomb_smoothing(coulomb_smoothing))
}
