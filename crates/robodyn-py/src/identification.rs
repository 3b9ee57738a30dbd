//! Identification from Python: `identify(robot, logs, **options)`, the sufficient statistics of
//! one log (`ident_statistics`, picklable: the map of a map-reduce) and the identification from
//! merged statistics (`identify_from_statistics`, the reduce), on the library's
//! `robodyn::identification` (the same numbers as `robodyn identify`).
//!
//! A log is a CSV path, a dict of arrays named as the CSV's columns (`t`, `q1`, `tau1`, ...), a
//! pandas DataFrame with those columns, or a list of these (several logs of one robot). Arrays
//! are written as CSV text in memory (shortest round-trip digits: the same doubles) and read by
//! the library's CSV reader, so that columns, sample times and values are checked as for a file.

use crate::errors::{InputError, IntoPy};
use crate::robot::Robot;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use robodyn::identification::data::{CsvLog, JointLabels, LogSource};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::statistics::StatisticsBuilder;
use robodyn::identification::{
    self as ident, report, statistics, EssentialOptions, Estimator, Options, Statistics,
};
use robodyn::RobotDescription;
use std::path::PathBuf;
use std::sync::Mutex;

/// The option names of `identify` (the fields of the library's `identification::Options`).
const OPTIONS: [&str; 23] = [
    "estimator",
    "consistent",
    "standard",
    "rotor",
    "friction",
    "offsets",
    "joint_drives",
    "seed",
    "essential",
    "essential_max_std",
    "essential_tolerance",
    "bandwidth",
    "cutoff",
    "filter_order",
    "decimation",
    "border",
    "validation",
    "use_log_derivatives",
    "gains",
    "min_speed",
    "coulomb_band",
    "iv_iterations",
    "iv_bandwidth",
];

/// The library's options from the keyword arguments (unknown names refused with the list).
pub(crate) fn options(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Options> {
    let mut o = Options::default();
    let mut essential: Option<EssentialOptions> = None;
    let Some(kw) = kwargs else {
        return Ok(o);
    };
    for (k, v) in kw.iter() {
        let key: String = k.extract()?;
        let none = v.is_none();
        match key.as_str() {
            "estimator" => {
                let s: String = v.extract()?;
                o.estimator = Estimator::from_key(&s).ok_or_else(|| {
                    InputError::new_err(format!(
                        "estimator {s:?}: one of \"ols\", \"wls\", \"iv\" expected"
                    ))
                })?;
            }
            "consistent" => o.consistent = v.extract()?,
            "standard" => o.standard = v.extract()?,
            "rotor" => o.parameters.rotors = crate::robot::parse_rotor(&v.extract::<String>()?)?,
            "friction" => o.parameters.friction = v.extract()?,
            "offsets" => o.parameters.offsets = v.extract()?,
            "joint_drives" => o.parameters.joint_drives = v.extract()?,
            "seed" => o.parameters.seed = v.extract()?,
            "essential" => {
                if v.extract::<bool>()? {
                    essential.get_or_insert_with(EssentialOptions::default);
                }
            }
            "essential_max_std" => {
                essential
                    .get_or_insert_with(EssentialOptions::default)
                    .max_relative_std = v.extract()?
            }
            "essential_tolerance" => {
                essential
                    .get_or_insert_with(EssentialOptions::default)
                    .tolerance = v.extract()?
            }
            "bandwidth" => o.bandwidth = v.extract()?,
            "cutoff" => o.cutoff = v.extract()?,
            "filter_order" => o.filter_order = v.extract()?,
            "decimation" => o.decimation = v.extract()?,
            "border" => o.border = v.extract()?,
            "validation" => o.validation = if none { None } else { Some(v.extract()?) },
            "use_log_derivatives" => o.use_log_derivatives = v.extract()?,
            "gains" => o.gains = v.extract()?,
            "min_speed" => o.min_speed = v.extract()?,
            "coulomb_band" => o.coulomb_band = v.extract()?,
            "iv_iterations" => o.iv_iterations = v.extract()?,
            "iv_bandwidth" => o.iv_bandwidth = v.extract()?,
            _ => {
                return Err(InputError::new_err(format!(
                    "unknown option {key:?}: the options are {}",
                    OPTIONS.join(", ")
                )))
            }
        }
    }
    o.essential = essential;
    o.validate().py()?;
    Ok(o)
}

/// The robot's description: a `Robot` or the path of a robot file.
pub(crate) fn description(robot: &Bound<'_, PyAny>) -> PyResult<RobotDescription> {
    if let Ok(r) = robot.extract::<PyRef<'_, Robot>>() {
        return Ok(r.model().description().clone());
    }
    let path: PathBuf = robot.extract().map_err(|_| {
        InputError::new_err("robot: a robodyn.Robot or the path of a robot file expected")
    })?;
    robodyn::io::load_description(&path).py()
}

/// One log as the library's CSV reader sees it.
fn one_log(obj: &Bound<'_, PyAny>, labels: &JointLabels, k: usize) -> PyResult<CsvLog> {
    if let Ok(path) = obj.extract::<PathBuf>() {
        return CsvLog::open(&path, labels).py();
    }
    let columns: Vec<(String, Bound<'_, PyAny>)> = if let Ok(d) = obj.cast::<PyDict>() {
        d.iter()
            .map(|(k, v)| Ok((k.extract::<String>()?, v)))
            .collect::<PyResult<_>>()?
    } else if obj.hasattr("columns")? && obj.hasattr("to_numpy")? {
        // a pandas DataFrame (not imported: any object with columns and to_numpy)
        obj.getattr("columns")?
            .try_iter()?
            .map(|c| {
                let c = c?;
                Ok((
                    c.str()?.to_string(),
                    obj.get_item(&c)?.call_method0("to_numpy")?,
                ))
            })
            .collect::<PyResult<_>>()?
    } else {
        return Err(InputError::new_err(format!(
            "log {}: a CSV path, a dict of arrays (t, q<j>, tau<j>, ...) or a pandas DataFrame \
             expected, got {}",
            k + 1,
            obj.get_type().name()?
        )));
    };
    let name = format!("log {} (arrays)", k + 1);
    let text = csv_text(&columns, &name)?;
    CsvLog::from_reader(&name, std::io::Cursor::new(text.into_bytes()), labels).py()
}

/// The columns as CSV text (numbers in shortest round-trip form: read back, the same doubles).
fn csv_text(columns: &[(String, Bound<'_, PyAny>)], name: &str) -> PyResult<String> {
    let mut values = Vec::with_capacity(columns.len());
    for (c, v) in columns {
        let (vals, shape) = crate::arrays::values(v)?;
        if shape.len() != 1 {
            return Err(InputError::new_err(format!(
                "{name}: column {c:?} has shape {shape:?}, a 1-D array expected"
            )));
        }
        values.push(vals);
    }
    let rows = values.first().map_or(0, |v| v.len());
    if let Some((k, v)) = values.iter().enumerate().find(|(_, v)| v.len() != rows) {
        return Err(InputError::new_err(format!(
            "{name}: column {:?} has {} values, column {:?} {rows}: columns of one length expected",
            columns[k].0,
            v.len(),
            columns[0].0
        )));
    }
    let mut s = columns
        .iter()
        .map(|(c, _)| c.as_str())
        .collect::<Vec<_>>()
        .join(",");
    s.push('\n');
    for r in 0..rows {
        for (k, v) in values.iter().enumerate() {
            if k > 0 {
                s.push(',');
            }
            s.push_str(&format!("{:?}", v[r]));
        }
        s.push('\n');
    }
    Ok(s)
}

/// The logs of `logs`: one log or a list of them.
pub(crate) fn logs(obj: &Bound<'_, PyAny>, labels: &JointLabels) -> PyResult<Vec<CsvLog>> {
    if let Ok(list) = obj.cast::<PyList>() {
        return list
            .iter()
            .enumerate()
            .map(|(k, o)| one_log(&o, labels, k))
            .collect();
    }
    if let Ok(t) = obj.cast::<PyTuple>() {
        return t
            .iter()
            .enumerate()
            .map(|(k, o)| one_log(&o, labels, k))
            .collect();
    }
    Ok(vec![one_log(obj, labels, 0)?])
}

pub(crate) fn labels(access: &ModelAccess) -> JointLabels {
    JointLabels {
        numbers: access.actuated_joints().to_vec(),
        names: access.joint_names(),
    }
}

/// Identify the base parameters (with friction, rotor inertias, offsets, drive parameters of a
/// transmission) of `robot` (a `Robot` or a robot file's path) from `logs`: a CSV path, a dict
/// of 1-D arrays named as the CSV columns (`t`, `q<j>`, `tau<j>` or `i<j>` with `gains`,
/// optionally `qd<j>`, `qdd<j>`), a pandas DataFrame of those columns, or a list of these
/// (several logs of the robot, identified together as the CLI's repeated `--data`).
///
/// Options (the library's `identification::Options`, the CLI's flags): `estimator` ("ols",
/// "wls" default, "iv"), `consistent`, `standard` (compute the consistent standard parameters
/// for `write_robot`/`robot()`), `rotor`, `friction`, `offsets`, `joint_drives`, `seed`, `essential`,
/// `essential_max_std`, `essential_tolerance`, `bandwidth`, `cutoff`, `filter_order`,
/// `decimation`, `border`, `validation` ((from, to) fractions, or None; default (0.8, 1.0)),
/// `use_log_derivatives`, `gains`, `min_speed`, `coulomb_band`, `iv_iterations`,
/// `iv_bandwidth`. Runs with the GIL released.
///
/// Drive gains and payloads (the CLI's `--estimate-gains`, `--payload`): with
/// `estimate_gains=True`, `logs` are logs of motor currents (`i<j>`) and `reference` the logs
/// fixing the scale (joint torques `tau<j>`, or currents carrying the payload
/// `known_payload=(link, [XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M])`): returns a
/// `GainIdentification`. With `payload=LINK`, the payload's 10 parameters on that link from
/// `logs` carrying it, the robot's parameters those of `robot`, or identified too from logs
/// without the payload given as `before`: returns a `PayloadIdentification`.
#[pyfunction]
#[pyo3(signature = (robot, logs, **options))]
pub fn identify<'py>(
    py: Python<'py>,
    robot: &Bound<'py, PyAny>,
    logs: &Bound<'py, PyAny>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyAny>> {
    let (joint, options) = crate::joint_problems::split(py, options)?;
    if let Some(joint) = joint {
        return joint.run(py, robot, logs, options.as_ref());
    }
    let id = identify_parameters(py, robot, logs, options.as_ref())?;
    Ok(Bound::new(py, id)?.into_any())
}

/// `identify` of the parameters (no gains, no payload).
fn identify_parameters(
    py: Python<'_>,
    robot: &Bound<'_, PyAny>,
    logs: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Identification> {
    let mut opt = self::options(options)?;
    opt.keep_validation_rows = true;
    let mut access = ModelAccess::new(description(robot)?).py()?;
    let many = logs.cast::<PyList>().is_ok() || logs.cast::<PyTuple>().is_ok();
    let logs = self::logs(logs, &labels(&access))?;
    let n = access.actuated_joints().len();
    let (id, predictions) = py
        .detach(|| -> robodyn::Result<_> {
            // each log read once, recorded: the identification and the predictions read the
            // recording (arrays are a stream read once)
            let recorded = logs
                .iter()
                .map(|l| robodyn::identification::data::record(l, n).map(|r| r.1))
                .collect::<robodyn::Result<Vec<_>>>()?;
            let refs: Vec<&dyn LogSource> = recorded.iter().map(|l| l as &dyn LogSource).collect();
            let id = ident::identify_logs(&mut access, &refs, &opt)?;
            let predictions = refs
                .iter()
                .map(|l| ident::predictions::predictions(&mut access, &id, *l, &opt))
                .collect::<robodyn::Result<Vec<_>>>()?;
            Ok((id, predictions))
        })
        .py()?;
    Ok(Identification {
        id,
        desc: access.description().clone(),
        predictions: Some((predictions, many)),
    })
}

/// The sufficient statistics of one log (path, dict of arrays or DataFrame) for `robot` with
/// `options` (those of `identify`): a picklable `IdentStatistics`. Statistics of many logs,
/// computed anywhere (processes, a Dask cluster), merge in `identify_from_statistics` into the
/// numbers of `identify` of all the logs.
#[pyfunction]
#[pyo3(signature = (robot, log, **options))]
pub fn ident_statistics(
    py: Python<'_>,
    robot: &Bound<'_, PyAny>,
    log: &Bound<'_, PyAny>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<IdentStatistics> {
    let opt = self::options(options)?;
    let desc = description(robot)?;
    let key = format!("{desc:?}\n{opt:?}");
    let mut builder = match take_builder(&key) {
        Some(b) => b,
        None => StatisticsBuilder::new(ModelAccess::new(desc).py()?, opt).py()?,
    };
    let labels = JointLabels {
        numbers: builder_joints(&builder),
        names: builder_names(&builder),
    };
    let log = one_log(log, &labels, 0);
    let stats = log.and_then(|log| py.detach(|| builder.statistics(&log)).py());
    put_builder(key, builder);
    Ok(IdentStatistics { stats: stats? })
}

/// The statistics builders of the robots and options this process has seen (a Dask worker
/// computes the statistics of many logs of one robot: the parameter model is built once per
/// process, not per log), at most [`CACHED_BUILDERS`], the oldest dropped.
static BUILDERS: Mutex<Vec<(String, StatisticsBuilder)>> = Mutex::new(Vec::new());

/// Builders kept by `ident_statistics`.
const CACHED_BUILDERS: usize = 8;

/// The cached builder of `key` (the robot's description and the options), taken out while in
/// use: two threads of one process each use their own.
fn take_builder(key: &str) -> Option<StatisticsBuilder> {
    let mut b = BUILDERS.lock().unwrap_or_else(|e| e.into_inner());
    let k = b.iter().position(|(k, _)| k == key)?;
    Some(b.remove(k).1)
}

fn put_builder(key: String, builder: StatisticsBuilder) {
    let mut b = BUILDERS.lock().unwrap_or_else(|e| e.into_inner());
    b.push((key, builder));
    if b.len() > CACHED_BUILDERS {
        b.remove(0);
    }
}

fn builder_joints(b: &StatisticsBuilder) -> Vec<usize> {
    b.access().actuated_joints().to_vec()
}

fn builder_names(b: &StatisticsBuilder) -> Vec<String> {
    b.access().joint_names()
}

/// `robodyn.IdentStatisticsBuilder(robot, **options)`: the statistics of many logs of one
/// robot with one set of options, the parameter model built once; called with a log (path,
/// dict of arrays, DataFrame) it returns that log's `IdentStatistics`, the numbers of
/// `ident_statistics(robot, log, **options)`. Not picklable: make one per worker (or use
/// `ident_statistics`, which keeps one per robot and options in each process).
#[pyclass(module = "robodyn", frozen)]
pub struct IdentStatisticsBuilder {
    builder: Mutex<StatisticsBuilder>,
    labels: JointLabels,
}

#[pymethods]
impl IdentStatisticsBuilder {
    #[new]
    #[pyo3(signature = (robot, **options))]
    fn new(robot: &Bound<'_, PyAny>, options: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let opt = self::options(options)?;
        let access = ModelAccess::new(description(robot)?).py()?;
        let labels = self::labels(&access);
        let builder = StatisticsBuilder::new(access, opt).py()?;
        Ok(IdentStatisticsBuilder {
            builder: Mutex::new(builder),
            labels,
        })
    }

    /// The statistics of one log (runs with the GIL released).
    fn __call__(&self, py: Python<'_>, log: &Bound<'_, PyAny>) -> PyResult<IdentStatistics> {
        let log = one_log(log, &self.labels, 0)?;
        let stats = py
            .detach(|| {
                let mut b = self.builder.lock().unwrap_or_else(|e| e.into_inner());
                b.statistics(&log)
            })
            .py()?;
        Ok(IdentStatistics { stats })
    }
}

/// Identify from the statistics of logs (a list of `IdentStatistics`, merged; of this robot,
/// computed with the same row-shaping options, checked): the numbers of `identify` of the logs.
/// IDIM-IV, which simulates the logs again, needs the logs.
#[pyfunction]
#[pyo3(signature = (robot, statistics, **options))]
pub fn identify_from_statistics(
    py: Python<'_>,
    robot: &Bound<'_, PyAny>,
    statistics: Vec<PyRef<'_, IdentStatistics>>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Identification> {
    let opt = self::options(options)?;
    let mut access = ModelAccess::new(description(robot)?).py()?;
    let parts: Vec<Statistics> = statistics.iter().map(|s| s.stats.clone()).collect();
    let id = py
        .detach(|| ident::identify_from_statistics(&mut access, &parts, &opt))
        .py()?;
    Ok(Identification {
        id,
        desc: access.description().clone(),
        predictions: None,
    })
}

/// The sufficient statistics of the identification from one log or several (merged): per
/// joint, the triangular factor of [W y] of the fit and validation rows, with the robot's
/// fingerprint and the options that shaped the rows. Picklable (as its JSON text).
#[pyclass(module = "robodyn", frozen)]
pub struct IdentStatistics {
    stats: Statistics,
}

#[pymethods]
impl IdentStatistics {
    /// Statistics from their JSON text (`to_json`, `robodyn identify --partial`).
    #[new]
    fn new(json: &str) -> PyResult<Self> {
        Ok(IdentStatistics {
            stats: Statistics::from_json(json, "the statistics").py()?,
        })
    }

    /// The JSON text (the file `robodyn identify --partial` writes; `--merge` reads it).
    fn to_json(&self) -> String {
        self.stats.to_json()
    }

    /// These statistics merged with `other`'s (of the same robot and row options).
    fn merge(&self, other: &IdentStatistics) -> PyResult<IdentStatistics> {
        let mut s = self.stats.clone();
        s.merge(&other.stats).py()?;
        Ok(IdentStatistics { stats: s })
    }

    /// Rows of the fit (all joints).
    #[getter]
    fn rows(&self) -> usize {
        self.stats.rows()
    }

    /// The logs' names.
    #[getter]
    fn logs(&self) -> Vec<String> {
        self.stats.logs.iter().map(|l| l.source.clone()).collect()
    }

    fn __getnewargs__(&self) -> (String,) {
        (self.stats.to_json(),)
    }

    fn __repr__(&self) -> String {
        format!(
            "IdentStatistics({}: {}, {} rows)",
            self.stats.fingerprint.robot,
            statistics::sources(&self.stats.logs),
            self.stats.rows()
        )
    }
}

/// The result of `identify`: parameters with their standard deviations, condition numbers,
/// per-joint and validation errors, warnings, the predicted torques of the validation segment,
/// and the identified robot.
#[pyclass(module = "robodyn", frozen)]
pub struct Identification {
    id: ident::Identification,
    /// The robot's description (the identified robot's geometry).
    desc: RobotDescription,
    /// The model's torques at every sample of each log, and whether the logs were given as a
    /// list (None from statistics: no log to predict).
    predictions: Option<(Vec<ident::predictions::Predictions>, bool)>,
}

/// t, measured and predicted torques of the validation segment.
type Prediction<'py> = (
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
);

/// A JSON value as a Python object.
pub(crate) fn py_json<'py>(py: Python<'py>, v: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (v.to_string(),))
}

#[pymethods]
impl Identification {
    /// The JSON report of `robodyn identify --format json`, as a dict.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &report::to_json(&self.id))
    }

    /// The parameters: a list of dicts `name`, `unit`, `equation`, `value`, `std`,
    /// `relative_std` (%, None when infinite), as the JSON report.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &report::to_json(&self.id)["parameters"])
    }

    /// Parameter names, in the order of `values`.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.id.parameters.iter().map(|p| p.name.clone()).collect()
    }

    /// The estimate (SI units of each parameter).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.x)
    }

    /// Standard deviations of the estimate.
    #[getter]
    fn std<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.std)
    }

    /// Relative standard deviations 100 std / |value| (%).
    #[getter]
    fn relative_std<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.relative_std)
    }

    /// The estimator used, in words.
    #[getter]
    fn estimator(&self) -> String {
        self.id.estimator.clone()
    }

    /// Condition number of W with unit-norm columns.
    #[getter]
    fn condition_number(&self) -> f64 {
        self.id.condition_number
    }

    /// Condition number of W as built (depends on the units).
    #[getter]
    fn condition_number_unscaled(&self) -> f64 {
        self.id.condition_number_unscaled
    }

    /// ||Y - W X|| / ||Y|| over the fit rows.
    #[getter]
    fn relative_error(&self) -> f64 {
        self.id.relative_error
    }

    /// Per joint: dicts `joint`, `name`, `rows`, `rms`, `relative_error`, `sigma` (the WLS
    /// weight is 1 / sigma).
    #[getter]
    fn per_joint<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &report::to_json(&self.id)["per_joint"])
    }

    /// The validation segment's errors (dict as the JSON report), or None without a segment.
    #[getter]
    fn validation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &report::to_json(&self.id)["validation"])
    }

    /// Warnings: dicts `kind`, `parameters`, `message`.
    #[getter]
    fn warnings<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &report::to_json(&self.id)["warnings"])
    }

    /// What the processing did that the user should know.
    #[getter]
    fn notes(&self) -> Vec<String> {
        self.id.notes.clone()
    }

    /// The decimated samples of the validation segment for a plot: (t (M,), measured (M, N),
    /// predicted (M, N)) torques, at most 20,000 samples evenly spaced.
    fn validation_prediction<'py>(&self, py: Python<'py>) -> PyResult<Prediction<'py>> {
        let rows = &self.id.validation_rows;
        let to2d = |v: &[Vec<f64>]| -> PyResult<Bound<'py, PyAny>> {
            let n = self.id.joints.len();
            let flat: Vec<f64> = v.iter().flatten().copied().collect();
            Ok(PyArray1::from_vec(py, flat)
                .reshape([v.len(), n])?
                .into_any())
        };
        Ok((
            PyArray1::from_slice(py, &rows.t),
            to2d(&rows.y)?,
            to2d(&self.id.predicted_validation())?,
        ))
    }

    /// The identified model's torques at every sample of the log (the samples between the
    /// borders the processing drops), to compare with the measured torques: a dict `t` (M,),
    /// `tau` (M, N) (joint side, N m or N), `joints` (frame numbers, the columns of `tau`);
    /// a list of such dicts when the logs were given as a list; None when identified from
    /// statistics (no log). `robodyn identify --predictions FILE`.
    #[getter]
    fn predictions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let Some((preds, many)) = &self.predictions else {
            return Ok(py.None().into_bound(py));
        };
        let one = |p: &ident::predictions::Predictions| -> PyResult<Bound<'py, PyAny>> {
            let d = PyDict::new(py);
            let flat: Vec<f64> = p.tau.iter().flatten().copied().collect();
            d.set_item("t", PyArray1::from_slice(py, &p.t))?;
            d.set_item(
                "tau",
                PyArray1::from_vec(py, flat).reshape([p.t.len(), p.joints.len()])?,
            )?;
            d.set_item("joints", p.joints.clone())?;
            Ok(d.into_any())
        };
        if *many {
            let items = preds.iter().map(one).collect::<PyResult<Vec<_>>>()?;
            Ok(PyList::new(py, items)?.into_any())
        } else {
            one(&preds[0])
        }
    }

    /// The report as `robodyn identify` prints it.
    fn text(&self) -> String {
        report::to_text(&self.id)
    }

    /// The parameters as a pandas DataFrame (pandas imported here; ImportError without it).
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = py.import("pandas")?;
        pd.call_method1("DataFrame", (self.parameters(py)?,))
    }

    /// The identified robot: physically consistent standard parameters reproducing the
    /// estimate (identify with `standard=True` or `consistent=True`).
    fn robot(&self) -> PyResult<Robot> {
        let desc = self.identified()?;
        Ok(Robot::wrap(robodyn::Robot::new(desc).py()?, None))
    }

    /// Write the identified robot (see `robot()`) to a file (.toml or .par).
    fn write_robot(&self, path: PathBuf) -> PyResult<()> {
        let desc = self.identified()?;
        robodyn::io::save_description(&desc, &path).py()
    }

    fn __repr__(&self) -> String {
        format!(
            "Identification({}: {} parameters, {}, relative error {:.4})",
            self.id.robot,
            self.id.x.len(),
            self.id.estimator,
            self.id.relative_error
        )
    }
}

impl Identification {
    fn identified(&self) -> PyResult<RobotDescription> {
        let Some(c) = &self.id.consistent else {
            return Err(InputError::new_err(
                "no physically consistent standard parameters: identify with standard=True (or \
                 consistent=True) for a robot to simulate",
            ));
        };
        let access = ModelAccess::new(self.desc.clone()).py()?;
        let mut desc = access.description_with(&c.standard).py()?;
        desc.name = format!("{} (identified)", desc.name);
        Ok(desc)
    }
}

/// Register the identification's functions and classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Identification>()?;
    m.add_class::<IdentStatistics>()?;
    m.add_class::<IdentStatisticsBuilder>()?;
    m.add_function(wrap_pyfunction!(identify, m)?)?;
    m.add_function(wrap_pyfunction!(ident_statistics, m)?)?;
    m.add_function(wrap_pyfunction!(identify_from_statistics, m)?)?;
    Ok(())
}
