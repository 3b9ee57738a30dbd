//! `robodyn.identify(..., estimate_gains=True, reference=..., known_payload=...)` and
//! `robodyn.identify(..., payload=LINK, before=...)`: the drive gains and a payload identified
//! with the library's `identification::gains` and `identification::payload` (the CLI's
//! `identify --estimate-gains` and `--payload`), their results as the CLI's JSON report.

use crate::errors::{InputError, IntoPy};
use crate::identification::{description, labels, logs, options, py_json};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::identification::data::{CsvLog, LogSource};
use robodyn::identification::gains::{self, GainReference};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::payload::{self, PayloadLogs, PAYLOAD_PARAMETERS};

/// The keywords of the joint problems (taken out of `identify`'s options).
const KEYS: [&str; 5] = [
    "estimate_gains",
    "reference",
    "known_payload",
    "payload",
    "before",
];

/// Options of `identify` the joint problems do not take (the CLI's conflicts).
const NOT_WITH: [&str; 4] = ["gains", "consistent", "standard", "essential"];

/// A joint problem asked by `identify`'s keywords.
pub enum JointProblem<'py> {
    /// Drive gains: the reference logs, and the known payload they carry (link, parameters).
    Gains {
        reference: Bound<'py, PyAny>,
        known_payload: Option<(usize, [f64; 10])>,
    },
    /// A payload on `link`, with the logs without it when given.
    Payload {
        link: usize,
        before: Option<Bound<'py, PyAny>>,
    },
}

/// Split `identify`'s keywords into the joint problem (if any) and the other options.
#[allow(clippy::type_complexity)]
pub fn split<'py>(
    py: Python<'py>,
    kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Option<JointProblem<'py>>, Option<Bound<'py, PyDict>>)> {
    let Some(kw) = kwargs else {
        return Ok((None, None));
    };
    let rest = PyDict::new(py);
    let mut got: Vec<(String, Bound<'py, PyAny>)> = Vec::new();
    for (k, v) in kw.iter() {
        let key: String = k.extract()?;
        if KEYS.contains(&key.as_str()) {
            if !v.is_none() {
                got.push((key, v));
            }
        } else {
            rest.set_item(k, v)?;
        }
    }
    let take = |name: &str| got.iter().find(|(k, _)| k == name).map(|(_, v)| v.clone());
    let estimate_gains = match take("estimate_gains") {
        Some(v) => v.extract::<bool>()?,
        None => false,
    };
    let payload = take("payload").map(|v| v.extract::<usize>()).transpose()?;
    let (reference, known, before) = (take("reference"), take("known_payload"), take("before"));
    let refuse = |m: &str| Err(InputError::new_err(m.to_string()));
    if estimate_gains && payload.is_some() {
        return refuse("estimate_gains and payload are two identifications: give one of them");
    }
    if !estimate_gains && (reference.is_some() || known.is_some()) {
        return refuse("reference and known_payload go with estimate_gains=True");
    }
    if payload.is_none() && before.is_some() {
        return refuse("before (logs without the payload) goes with payload=LINK");
    }
    let problem = if estimate_gains {
        let Some(reference) = reference else {
            return refuse(
                "estimate_gains=True needs reference: logs fixing the gains' scale (joint \
                 torques tau<j>, or currents i<j> with known_payload)",
            );
        };
        let known_payload = known.map(|v| known_payload(&v)).transpose()?;
        JointProblem::Gains {
            reference,
            known_payload,
        }
    } else if let Some(link) = payload {
        JointProblem::Payload { link, before }
    } else {
        return Ok((None, Some(rest)));
    };
    if let Some(k) = NOT_WITH
        .iter()
        .find(|k| rest.contains(**k).unwrap_or(false))
    {
        return Err(InputError::new_err(format!(
            "{k} is not an option of the identification of drive gains or of a payload"
        )));
    }
    Ok((Some(problem), Some(rest)))
}

/// `known_payload=(link, [XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M])`.
fn known_payload(v: &Bound<'_, PyAny>) -> PyResult<(usize, [f64; 10])> {
    let (link, values): (usize, Vec<f64>) = v.extract().map_err(|_| {
        InputError::new_err(
            "known_payload: (link, [XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M]) expected",
        )
    })?;
    let n = values.len();
    let parameters: [f64; 10] = values.try_into().map_err(|_| {
        InputError::new_err(format!(
            "known_payload: {n} values, 10 expected (XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M)"
        ))
    })?;
    if let Some(x) = parameters.iter().find(|x| !x.is_finite()) {
        return Err(InputError::new_err(format!(
            "known_payload: {x} is not a finite number"
        )));
    }
    Ok((link, parameters))
}

fn refs(logs: &[CsvLog]) -> Vec<&dyn LogSource> {
    logs.iter().map(|l| l as &dyn LogSource).collect()
}

impl<'py> JointProblem<'py> {
    /// Identify from `logs` (the CLI's `--data`) with the other `options` of `identify`; the
    /// result object of the problem. Runs with the GIL released.
    pub fn run(
        self,
        py: Python<'py>,
        robot: &Bound<'py, PyAny>,
        data: &Bound<'py, PyAny>,
        options_dict: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let opt = options(options_dict)?;
        let mut access = ModelAccess::new(description(robot)?).py()?;
        let labels = labels(&access);
        let data = logs(data, &labels)?;
        match self {
            JointProblem::Gains {
                reference,
                known_payload,
            } => {
                let reference = logs(&reference, &labels)?;
                let id = py
                    .detach(|| {
                        let r = refs(&reference);
                        let reference = match known_payload {
                            Some((link, parameters)) => GainReference::Payload {
                                link,
                                parameters,
                                logs: r,
                            },
                            None => GainReference::Torques(r),
                        };
                        gains::identify_gains(&mut access, &refs(&data), &reference, &opt)
                    })
                    .py()?;
                Ok(Bound::new(py, GainIdentification { id })?.into_any())
            }
            JointProblem::Payload { link, before } => {
                let before = before.map(|b| logs(&b, &labels)).transpose()?;
                let id = py
                    .detach(|| {
                        let logs = match &before {
                            None => PayloadLogs::Known(refs(&data)),
                            Some(b) => PayloadLogs::BeforeAfter {
                                before: refs(b),
                                after: refs(&data),
                            },
                        };
                        payload::identify_payload(&mut access, link, &logs, &opt)
                    })
                    .py()?;
                Ok(Bound::new(py, PayloadIdentification { id })?.into_any())
            }
        }
    }
}

/// The result of `identify(..., estimate_gains=True, reference=...)`: the drive gains
/// (torque per unit of current) and the dynamic parameters identified with them.
#[pyclass(module = "robodyn", frozen)]
pub struct GainIdentification {
    id: gains::GainIdentification,
}

#[pymethods]
impl GainIdentification {
    /// The JSON report of `robodyn identify --estimate-gains --format json`, as a dict.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &self.id.to_json())
    }

    /// The gains: a list of dicts `joint`, `name`, `value`, `std`, as the JSON report.
    #[getter]
    fn gains<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &self.id.to_json()["gains"])
    }

    /// The gains' values, one per motor (N m or N per unit of the `i<j>` columns).
    #[getter]
    fn gain_values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.gains)
    }

    /// The gains' standard deviations.
    #[getter]
    fn gain_std<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.gains_std)
    }

    /// The parameters identified with the gains: dicts `name`, `equation`, `value`, `std`.
    #[getter]
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &self.id.to_json()["parameters"])
    }

    /// The parameters' values (the order of `parameters`).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.x)
    }

    /// The parameters' standard deviations.
    #[getter]
    fn std<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.id.std)
    }

    /// What fixed the scale, in words.
    #[getter]
    fn reference(&self) -> String {
        self.id.reference.clone()
    }

    /// Condition number of the stacked equations (unit-norm columns).
    #[getter]
    fn condition_number(&self) -> f64 {
        self.id.condition_number
    }

    /// RMS of the residual of the stacked equations (N m or N).
    #[getter]
    fn residual_rms(&self) -> f64 {
        self.id.residual_rms
    }

    fn __repr__(&self) -> String {
        format!(
            "GainIdentification({}: {} gains, {} parameters, {})",
            self.id.robot,
            self.id.gains.len(),
            self.id.x.len(),
            self.id.estimator
        )
    }
}

/// The result of `identify(..., payload=LINK)`: the payload's 10 standard parameters on the
/// link (about its origin, in its frame), those the logs determine.
#[pyclass(module = "robodyn", frozen)]
pub struct PayloadIdentification {
    id: payload::PayloadIdentification,
}

#[pymethods]
impl PayloadIdentification {
    /// The JSON report of `robodyn identify --payload LINK --format json`, as a dict.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &self.id.to_json())
    }

    /// The payload's parameters: dicts `name` (XX .. M), `value`, `std` (None where the logs
    /// do not determine it on its own), as the JSON report.
    #[getter]
    fn payload<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &self.id.to_json()["payload"])
    }

    /// The payload's values XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M (NaN where not determined).
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .id
            .payload
            .iter()
            .map(|e| e.value.unwrap_or(f64::NAN))
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// The payload's standard deviations (NaN where not determined).
    #[getter]
    fn std<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let v: Vec<f64> = self
            .id
            .payload
            .iter()
            .map(|e| e.std.unwrap_or(f64::NAN))
            .collect();
        PyArray1::from_vec(py, v)
    }

    /// The names of `values`: XX, XY, XZ, YY, YZ, ZZ, MX, MY, MZ, M.
    #[getter]
    fn names(&self) -> Vec<&'static str> {
        PAYLOAD_PARAMETERS.to_vec()
    }

    /// The other unknowns (torque offsets, or the robot's parameters before/after): dicts
    /// `name`, `value`, `std`.
    #[getter]
    fn others<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py_json(py, &self.id.to_json()["others"])
    }

    /// The link carrying the payload.
    #[getter]
    fn link(&self) -> usize {
        self.id.link
    }

    /// How many combinations of the payload's parameters the logs determine (of 10).
    #[getter]
    fn rank(&self) -> usize {
        self.id.rank
    }

    /// How many change the torques at all (of 10).
    #[getter]
    fn structural_rank(&self) -> usize {
        self.id.structural_rank
    }

    /// The combinations not determined, in words.
    #[getter]
    fn undetermined(&self) -> Vec<String> {
        self.id.undetermined.clone()
    }

    /// ||tau - predicted|| / ||tau|| over the fit rows.
    #[getter]
    fn relative_error(&self) -> f64 {
        self.id.relative_error
    }

    /// Condition number of the determined directions (unit-norm columns).
    #[getter]
    fn condition_number(&self) -> f64 {
        self.id.condition_number
    }

    fn __repr__(&self) -> String {
        format!(
            "PayloadIdentification({}: link {}, {} of 10 determined, {})",
            self.id.robot, self.id.link, self.id.rank, self.id.estimator
        )
    }
}

/// Register the result classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<GainIdentification>()?;
    m.add_class::<PayloadIdentification>()?;
    Ok(())
}
