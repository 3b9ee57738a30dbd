//! `robodyn.Robot`: the tree model (a closed robot's equivalent tree) with its model functions
//! as methods on one state (1-D arrays) or N states (2-D arrays, evaluated over all cores with
//! the GIL released).

use crate::arrays::{output, states, States};
use crate::errors::{InputError, IntoPy};
use nalgebra::DMatrix;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use robodyn::algorithms::regressor::{
    base_columns, regressor_into, standard_columns, ParameterSelection, RotorMode, ZeroParameters,
    PARAMS_PER_LINK,
};
use robodyn::batch::for_each_row;
use robodyn::{
    direct_dynamics_into, h_vector_into, inertia_matrix_into, inverse_dynamics_into, Data, Method,
};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, RwLock};

/// Per-thread buffers of a tree evaluation: the library's `Data` and a matrix output.
pub struct Work {
    pub data: Data,
    pub m: DMatrix<f64>,
}

impl Work {
    pub fn new(robot: &robodyn::Robot) -> Work {
        Work {
            data: Data::new(robot),
            m: DMatrix::zeros(0, 0),
        }
    }

    /// The library's `Data` and the matrix buffer with shape (r, c), borrowed together.
    pub fn split(&mut self, r: usize, c: usize) -> (&mut Data, &mut DMatrix<f64>) {
        if self.m.shape() != (r, c) {
            self.m = DMatrix::zeros(r, c);
        }
        (&mut self.data, &mut self.m)
    }
}

/// Rows of `m` (columns `cols`) into `out`, row-major.
pub fn copy_rows(m: &DMatrix<f64>, cols: &[usize], out: &mut [f64]) {
    let w = cols.len();
    for r in 0..m.nrows() {
        for (k, &c) in cols.iter().enumerate() {
            out[r * w + k] = m[(r, c)];
        }
    }
}

pub fn parse_method(method: &str) -> PyResult<Method> {
    match method {
        "composite" => Ok(Method::Composite),
        "aba" | "articulated" => Ok(Method::ArticulatedBody),
        _ => Err(InputError::new_err(format!(
            "method = {method:?}: expected \"composite\" (tree L'DL of A) or \"aba\" (articulated bodies)"
        ))),
    }
}

/// What a literal 0 means: `zeros` ("absent" or "value"), else by the file it came from.
pub fn parse_zeros(
    zeros: Option<&str>,
    source: Option<&std::path::Path>,
) -> PyResult<ZeroParameters> {
    Ok(match zeros {
        Some("absent") => ZeroParameters::Absent,
        Some("value") => ZeroParameters::Value,
        None => source.map_or(ZeroParameters::Value, ZeroParameters::for_path),
        Some(z) => {
            return Err(InputError::new_err(format!(
                "zeros = {z:?}: expected \"absent\" (a literal 0 is no parameter, SYMORO's \
                 meaning) or \"value\""
            )))
        }
    })
}

pub fn parse_rotor(rotor: &str) -> PyResult<RotorMode> {
    match rotor {
        "actuated" => Ok(RotorMode::Actuated),
        "all" => Ok(RotorMode::All),
        "none" => Ok(RotorMode::None),
        _ => Err(InputError::new_err(format!(
            "rotor = {rotor:?}: expected \"actuated\", \"all\" or \"none\""
        ))),
    }
}

/// A robot model: a tree, or the equivalent tree of a closed chain (use `ClosedChain(robot)`
/// for the closed-chain models).
#[pyclass(module = "robodyn", frozen)]
pub struct Robot {
    inner: RwLock<Arc<robodyn::Robot>>,
    /// Buffers of single-state calls (made for the model they hold).
    cache: Mutex<Option<(Arc<robodyn::Robot>, Work)>>,
    /// The file it was read from (decides what a literal 0 means for base parameters).
    pub source: Option<PathBuf>,
}

impl Robot {
    pub fn wrap(robot: robodyn::Robot, source: Option<PathBuf>) -> Robot {
        Robot {
            inner: RwLock::new(Arc::new(robot)),
            cache: Mutex::new(None),
            source,
        }
    }

    /// The current model (shared).
    pub fn model(&self) -> Arc<robodyn::Robot> {
        self.inner.read().unwrap().clone()
    }

    fn with_work<T>(&self, robot: &Arc<robodyn::Robot>, f: impl FnOnce(&mut Work) -> T) -> T {
        if let Ok(mut g) = self.cache.try_lock() {
            match g.as_mut() {
                Some((r, w)) if Arc::ptr_eq(r, robot) => return f(w),
                _ => {
                    *g = Some((robot.clone(), Work::new(robot)));
                    return f(&mut g.as_mut().unwrap().1);
                }
            }
        }
        f(&mut Work::new(robot))
    }

    fn joint_text(robot: &robodyn::Robot) -> String {
        format!(
            "movable joints [{}]",
            robot.coordinates().names().join(", ")
        )
    }

    /// Evaluate `f(robot, work, row inputs, out)` on one state or on every row of N states.
    pub fn eval<'py, F>(
        &self,
        py: Python<'py>,
        inputs: &[(&str, Option<&Bound<'py, PyAny>>)],
        shape_one: &[usize],
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        let robot = self.model();
        let n = robot.dof();
        let st = states(inputs, n, &|| Self::joint_text(&robot))?;
        let (v, rows) = self.run(py, &robot, &st, shape_one.iter().product(), f)?;
        output(py, v, rows, shape_one)
    }

    fn run<F>(
        &self,
        py: Python<'_>,
        robot: &Arc<robodyn::Robot>,
        st: &States,
        width: usize,
        f: F,
    ) -> PyResult<(Vec<f64>, Option<usize>)>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        let k = st.data.len();
        let row = |r: usize| -> [&[f64]; 3] {
            std::array::from_fn(|i| if i < k { st.row(i, r) } else { &[][..] })
        };
        match st.rows {
            None => {
                let mut out = vec![0.0; width];
                self.with_work(robot, |w| f(robot, w, row(0), &mut out))
                    .py()?;
                Ok((out, None))
            }
            Some(n) => {
                let r: &robodyn::Robot = robot;
                let mut v = vec![0.0; n * width];
                py.detach(|| {
                    for_each_row(
                        n,
                        &mut v,
                        width,
                        || Work::new(r),
                        |w, i, o| f(r, w, row(i), o),
                    )
                })
                .py()?;
                Ok((v, Some(n)))
            }
        }
    }

    /// The regressor columns (K indices, names) of a selection.
    pub fn columns(
        &self,
        robot: &robodyn::Robot,
        columns: &str,
        friction: bool,
        rotor: &str,
        seed: u64,
    ) -> PyResult<(Vec<usize>, Vec<String>)> {
        let sel = ParameterSelection::new(robot, parse_rotor(rotor)?, friction)
            .with_zero_parameters(robot.description(), self.zeros(None)?);
        let c = match columns {
            "standard" => standard_columns(robot, &sel),
            "base" => base_columns(robot, &sel, seed).py()?,
            _ => {
                return Err(InputError::new_err(format!(
                    "columns = {columns:?}: expected \"standard\" or \"base\""
                )))
            }
        };
        Ok((c.indices, c.names))
    }

    pub fn zeros(&self, zeros: Option<&str>) -> PyResult<ZeroParameters> {
        parse_zeros(zeros, self.source.as_deref())
    }

    fn with_symbols(&self, values: BTreeMap<String, f64>) -> PyResult<robodyn::Robot> {
        let robot = self.model();
        let mut d = robot.description().clone();
        for (k, v) in &values {
            if !v.is_finite() {
                return Err(crate::errors::NotFiniteError::new_err(format!(
                    "{k} = {v} is not a finite number"
                )));
            }
        }
        d.symbols.extend(values);
        robodyn::Robot::new(d).py()
    }
}

pub fn kwargs_values(kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<BTreeMap<String, f64>> {
    let mut m = BTreeMap::new();
    if let Some(k) = kwargs {
        for (name, v) in k.iter() {
            m.insert(name.extract::<String>()?, v.extract::<f64>()?);
        }
    }
    Ok(m)
}

#[pymethods]
impl Robot {
    /// Read a robot from TOML text (the format of `docs/robot-format.md`).
    #[staticmethod]
    fn from_toml_str(text: &str) -> PyResult<Robot> {
        let r = robodyn::io::toml_format::parse_robot(text, None).py()?;
        Ok(Robot::wrap(r, None))
    }

    /// Robot name.
    #[getter]
    fn name(&self) -> String {
        self.model().name().to_string()
    }

    /// Number of movable joints: the length of every joint vector (q, qd, qdd, tau).
    #[getter]
    fn nq(&self) -> usize {
        self.model().dof()
    }

    /// NL, number of links (and of tree joints).
    #[getter]
    fn nl(&self) -> usize {
        self.model().nl()
    }

    /// NJ, number of joints (NJ - NL cut joints).
    #[getter]
    fn nj(&self) -> usize {
        self.model().nj()
    }

    /// NF, number of frames (2 NJ - NL).
    #[getter]
    fn nf(&self) -> usize {
        self.model().nf()
    }

    /// Names of the movable joints, in the order of every joint vector.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.model().coordinates().names().to_vec()
    }

    /// Frame numbers (1-based) of the movable joints, in vector order.
    #[getter]
    fn joint_frames(&self) -> Vec<usize> {
        self.model().coordinates().frames().to_vec()
    }

    /// Names of the frames 1..NF (joint names; fixed frames and cut-joint twins included).
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        let r = self.model();
        (1..=r.nf()).map(|j| r.frame(j).name.clone()).collect()
    }

    /// Names of the links 1..NL.
    #[getter]
    fn link_names(&self) -> Vec<String> {
        let r = self.model();
        (1..=r.nl()).map(|j| r.link(j).name.clone()).collect()
    }

    /// Antecedents a(j) of the frames 1..NF (0 is the base).
    #[getter]
    fn antecedents(&self) -> Vec<usize> {
        let r = self.model();
        (1..=r.nf()).map(|j| r.ant(j)).collect()
    }

    /// Frame numbers of the actuated joints.
    #[getter]
    fn actuated(&self) -> Vec<usize> {
        self.model().actuated_joints()
    }

    /// Frame numbers of the passive joints (tree joints and cut joints).
    #[getter]
    fn passive(&self) -> Vec<usize> {
        self.model().passive_joints()
    }

    /// Whether the structure is a tree (no closed loop).
    #[getter]
    fn is_tree(&self) -> bool {
        self.model().is_tree()
    }

    /// The closed loops: one dict per cut joint (`cut`, `twin`, `link_i`, `link_j`, `root`,
    /// `branch_i`, `branch_j`).
    #[getter]
    fn loops<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let r = self.model();
        let out = PyList::empty(py);
        for l in &r.structure().loops {
            let d = PyDict::new(py);
            d.set_item("cut", l.cut)?;
            d.set_item("twin", l.twin)?;
            d.set_item("link_i", l.link_i)?;
            d.set_item("link_j", l.link_j)?;
            d.set_item("root", l.root)?;
            d.set_item("branch_i", l.branch_i.clone())?;
            d.set_item("branch_j", l.branch_j.clone())?;
            out.append(d)?;
        }
        Ok(out)
    }

    /// The symbols of the description and their values.
    #[getter]
    fn symbols(&self) -> BTreeMap<String, f64> {
        self.model().description().symbols.clone()
    }

    /// The assembly configuration (tree joints 1..NL) of a closed robot, or None.
    #[getter]
    fn assembly(&self) -> Option<Vec<f64>> {
        self.model().assembly()
    }

    /// Standard parameters K (13 per link: XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV), numbers.
    #[getter]
    fn standard_parameters(&self) -> Vec<f64> {
        self.model().standard_parameters()
    }

    /// Names of the standard parameters (the robot file's own names), in K order.
    #[getter]
    fn parameter_names(&self) -> Vec<String> {
        let r = self.model();
        let names = robodyn::algorithms::base_parameters::ParameterNames::of(r.description());
        (0..PARAMS_PER_LINK * r.nl())
            .map(|k| names.name(k).to_string())
            .collect()
    }

    /// Give or change symbol values in place: `robot.set(d3=0.45, M2=10.0)`.
    #[pyo3(signature = (**values))]
    fn set(&self, values: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        let r = self.with_symbols(kwargs_values(values)?)?;
        *self.inner.write().unwrap() = Arc::new(r);
        Ok(())
    }

    /// A new robot with symbol values given or changed (this one unchanged).
    #[pyo3(signature = (**values))]
    fn with_values(&self, values: Option<&Bound<'_, PyDict>>) -> PyResult<Robot> {
        let r = self.with_symbols(kwargs_values(values)?)?;
        Ok(Robot::wrap(r, self.source.clone()))
    }

    /// Write the description (format by extension: .toml or .par).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        robodyn::io::save_description(self.model().description(), &path).py()
    }

    /// The description as TOML text.
    fn to_toml(&self) -> String {
        robodyn::io::toml_format::write_description(self.model().description())
    }

    fn __repr__(&self) -> String {
        let r = self.model();
        format!(
            "Robot({:?}, nq={}, NL={}, NJ={}, loops={})",
            r.name(),
            r.dof(),
            r.nl(),
            r.nj(),
            r.n_loops()
        )
    }

    /// Inverse dynamic model (Newton–Euler, 10.3–10.12): torques of the movable joints.
    #[pyo3(signature = (q, qd=None, qdd=None))]
    fn idm<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        qdd: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model().dof();
        self.eval(
            py,
            &[("q", Some(q)), ("qd", qd), ("qdd", qdd)],
            &[n],
            |r, w, x, o| {
                inverse_dynamics_into(r, &mut w.data, r.environment(), x[0], x[1], x[2], o)
            },
        )
    }

    /// Inertia matrix A(q) by composite links (n x n, or N x n x n).
    fn inertia<'py>(&self, py: Python<'py>, q: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model().dof();
        self.eval(py, &[("q", Some(q))], &[n, n], |r, w, x, o| {
            let (data, a) = w.split(n, n);
            inertia_matrix_into(r, data, x[0], a)?;
            let all: Vec<usize> = (0..n).collect();
            copy_rows(&w.m, &all, o);
            Ok(())
        })
    }

    /// H(q, qd): centrifugal, Coriolis, gravity, friction and external-wrench torques.
    #[pyo3(signature = (q, qd=None))]
    fn h<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model().dof();
        self.eval(py, &[("q", Some(q)), ("qd", qd)], &[n], |r, w, x, o| {
            h_vector_into(r, &mut w.data, r.environment(), x[0], x[1], o)
        })
    }

    /// Direct dynamic model qdd = A^-1 (tau - H); method "composite" or "aba".
    #[pyo3(signature = (q, qd=None, tau=None, method="composite"))]
    fn ddm<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        tau: Option<&Bound<'py, PyAny>>,
        method: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = parse_method(method)?;
        let n = self.model().dof();
        self.eval(
            py,
            &[("q", Some(q)), ("qd", qd), ("tau", tau)],
            &[n],
            move |r, w, x, o| {
                direct_dynamics_into(r, &mut w.data, r.environment(), x[0], x[1], x[2], m, o)
            },
        )
    }

    /// Geometric model: 0T_j (4 x 4 homogeneous matrices) of the frames 1..NF for the movable
    /// joints' values q (cut-joint variables taken as 0): shape (NF, 4, 4) or (N, NF, 4, 4).
    fn forward_kinematics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let nf = self.model().nf();
        self.eval(py, &[("q", Some(q))], &[nf, 4, 4], |r, _w, x, o| {
            let mut tree = vec![0.0; r.nl()];
            for (k, &j) in r.coordinates().frames().iter().enumerate() {
                tree[j - 1] = x[0][k];
            }
            if let Some(k) = x[0].iter().position(|v| !v.is_finite()) {
                return Err(robodyn::Error::NotFinite {
                    what: "q".into(),
                    index: k,
                    value: x[0][k],
                });
            }
            for (j, t) in robodyn::geometry::frame_transforms(r, &tree)
                .iter()
                .enumerate()
            {
                let m = t.matrix();
                for a in 0..4 {
                    for b in 0..4 {
                        o[16 * j + 4 * a + b] = m[(a, b)];
                    }
                }
            }
            Ok(())
        })
    }

    /// Names of the regressor's columns for `columns` ("standard" or "base").
    #[pyo3(signature = (columns="standard", friction=true, rotor="actuated", seed=1))]
    fn regressor_columns(
        &self,
        columns: &str,
        friction: bool,
        rotor: &str,
        seed: u64,
    ) -> PyResult<Vec<String>> {
        Ok(self
            .columns(&self.model(), columns, friction, rotor, seed)?
            .1)
    }

    /// Regressor Phi with Gamma = Phi K (+ external-wrench torques): (n, p) for one state,
    /// stacked (N n, p) for N states (state after state), columns those of
    /// `regressor_columns(columns, ...)`: the standard parameters or the base parameters.
    #[pyo3(signature = (q, qd=None, qdd=None, columns="standard", friction=true, rotor="actuated", seed=1))]
    #[allow(clippy::too_many_arguments)]
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        qdd: Option<&Bound<'py, PyAny>>,
        columns: &str,
        friction: bool,
        rotor: &str,
        seed: u64,
    ) -> PyResult<Bound<'py, PyAny>> {
        let robot = self.model();
        let (cols, _) = self.columns(&robot, columns, friction, rotor, seed)?;
        let n = robot.dof();
        let p = cols.len();
        let nk = PARAMS_PER_LINK * robot.nl();
        let st = states(&[("q", Some(q)), ("qd", qd), ("qdd", qdd)], n, &|| {
            Self::joint_text(&robot)
        })?;
        let (v, rows) = self.run(py, &robot, &st, n * p, |r, w, x, o| {
            let (data, phi) = w.split(n, nk);
            regressor_into(r, data, r.environment(), x[0], x[1], x[2], phi)?;
            copy_rows(&w.m, &cols, o);
            Ok(())
        })?;
        let stacked = rows.map(|k| k * n).unwrap_or(n);
        output(py, v, None, &[stacked, p])
    }
}

#[pymethods]
impl Robot {
    /// Base inertial parameters: method "symbolic" (rules, equations in the robot's symbols),
    /// "numeric" (stacked regressor, QR) or "both" (symbolic, checked against numeric).
    #[pyo3(signature = (method="symbolic", friction=true, rotor="actuated", zeros=None, seed=1))]
    fn base_parameters(
        &self,
        py: Python<'_>,
        method: &str,
        friction: bool,
        rotor: &str,
        zeros: Option<&str>,
        seed: u64,
    ) -> PyResult<crate::models::BaseParameters> {
        crate::models::base_parameters(py, self, method, friction, rotor, zeros, seed)
    }

    /// Customized symbolic model as code with its operation counts.
    #[pyo3(signature = (model="idm", lang="python", params="standard", symmetric=false, friction=true, rotor=true, numeric=false, name=None))]
    #[allow(clippy::too_many_arguments)]
    fn generate(
        &self,
        py: Python<'_>,
        model: &str,
        lang: &str,
        params: &str,
        symmetric: bool,
        friction: bool,
        rotor: bool,
        numeric: bool,
        name: Option<String>,
    ) -> PyResult<crate::models::Generated> {
        crate::models::generate(
            py,
            &self.model(),
            model,
            lang,
            params,
            symmetric,
            friction,
            rotor,
            numeric,
            name,
            self.zeros(None)?,
        )
    }

    /// Simulate from (q0, qd0) over [0, duration]; returns a dict of arrays (t, q, qd, qdd,
    /// tau, energy). `torque`: None (zero), a constant vector, a (times, values) series or a
    /// callable torque(t, q, qd) -> tau. RK4 with `dt`, else Dormand–Prince 5(4).
    #[pyo3(signature = (duration, q0=None, qd0=None, torque=None, dt=None, rtol=1e-8, atol=1e-10, output_dt=0.01, method="aba", coulomb_smoothing=None, max_steps=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        duration: f64,
        q0: Option<Vec<f64>>,
        qd0: Option<Vec<f64>>,
        torque: Option<Bound<'py, PyAny>>,
        dt: Option<f64>,
        rtol: f64,
        atol: f64,
        output_dt: f64,
        method: &str,
        coulomb_smoothing: Option<f64>,
        max_steps: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let robot = self.model();
        let n = robot.dof();
        let mut dynamics = crate::models::tree_dynamics(&robot, method, coulomb_smoothing)?;
        let args = crate::models::SimArgs {
            duration,
            q0: q0.unwrap_or_else(|| vec![0.0; n]),
            qd0: qd0.unwrap_or_else(|| vec![0.0; n]),
            torque,
            dt,
            rtol,
            atol,
            output_dt,
            max_steps,
        };
        crate::models::run_simulation(py, &mut dynamics, args)
    }
}
