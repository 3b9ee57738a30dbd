//! `robodyn.Robot`: the tree model (a closed robot's equivalent tree) with its model functions
//! as methods on one state (1-D arrays) or N states (2-D arrays, evaluated over all cores with
//! the GIL released).

use crate::arrays::{in_blocks, inputs_sized, shift_row, Output, Shape, States};
use crate::errors::{InputError, IntoPy};
use nalgebra::DMatrix;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use robodyn::algorithms::base_parameters::{base_columns, standard_columns};
use robodyn::algorithms::regressor::{
    parameter_count, regressor_into, Friction, ParameterSelection, RotorMode, ZeroParameters,
};
use robodyn::batch::for_each_row;
use robodyn::KinematicsData;
use robodyn::{
    direct_dynamics_derivatives_into, direct_dynamics_into, h_vector_into, inertia_matrix_into,
    inverse_dynamics_derivatives_into, inverse_dynamics_into, Data, DdmDerivatives,
    DerivativesData, IdmDerivatives, Method,
};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock, RwLock};

/// Per-thread buffers of a tree evaluation: the library's `Data`, its `KinematicsData` and a
/// matrix output.
pub struct Work {
    pub data: Data,
    pub kin: KinematicsData,
    pub m: DMatrix<f64>,
    /// The derivatives' buffers and outputs, made at the first derivatives call.
    pub deriv: Option<Box<(DerivativesData, IdmDerivatives, DdmDerivatives)>>,
}

impl Work {
    pub fn new(robot: &robodyn::Robot) -> Work {
        Work {
            data: Data::new(robot),
            kin: KinematicsData::new(robot),
            m: DMatrix::zeros(0, 0),
            deriv: None,
        }
    }

    /// The derivatives' buffers for `robot` (made once).
    pub fn deriv(
        &mut self,
        robot: &robodyn::Robot,
    ) -> &mut (DerivativesData, IdmDerivatives, DdmDerivatives) {
        self.deriv.get_or_insert_with(|| {
            Box::new((
                DerivativesData::new(robot),
                IdmDerivatives::new(robot),
                DdmDerivatives::new(robot),
            ))
        })
    }

    /// The library's `Data` and the matrix buffer with shape (r, c), borrowed together.
    pub fn split(&mut self, r: usize, c: usize) -> (&mut Data, &mut DMatrix<f64>) {
        if self.m.shape() != (r, c) {
            self.m = DMatrix::zeros(r, c);
        }
        (&mut self.data, &mut self.m)
    }

    /// The kinematics data and the matrix buffer with shape (r, c), borrowed together.
    pub fn kin_split(&mut self, r: usize, c: usize) -> (&mut KinematicsData, &mut DMatrix<f64>) {
        if self.m.shape() != (r, c) {
            self.m = DMatrix::zeros(r, c);
        }
        (&mut self.kin, &mut self.m)
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

/// The N x N matrices `m` one after the other into `out`, each row-major.
pub(crate) fn copy_matrices(m: &[&DMatrix<f64>], out: &mut [f64]) {
    let mut k = 0;
    for a in m {
        for r in 0..a.nrows() {
            for c in 0..a.ncols() {
                out[k] = a[(r, c)];
                k += 1;
            }
        }
    }
}

/// An array of shape (3, n, n) or (N, 3, n, n) as a tuple of three C-contiguous arrays of
/// shape (n, n) or (N, n, n).
pub(crate) fn split_three<'py>(
    py: Python<'py>,
    r: Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let np = py.import("numpy")?;
    let moved = np.getattr("moveaxis")?.call1((r, -3, 0))?;
    let parts: Vec<Bound<'py, PyAny>> = (0..3)
        .map(|i| {
            np.getattr("ascontiguousarray")?
                .call1((moved.get_item(i)?,))
        })
        .collect::<PyResult<_>>()?;
    Ok(pyo3::types::PyTuple::new(py, parts)?.into_any())
}

/// `x` or its alias `y` (Pinocchio's spelling: `v` for `qd`, `a` for `qdd`), not both.
pub fn alias<'a, 'py>(
    name: &str,
    x: Option<&'a Bound<'py, PyAny>>,
    other: &str,
    y: Option<&'a Bound<'py, PyAny>>,
) -> PyResult<Option<&'a Bound<'py, PyAny>>> {
    match (x, y) {
        (Some(_), Some(_)) => Err(InputError::new_err(format!(
            "{name} and {other} are the same argument ({other} is Pinocchio's name for {name}): \
             give one of them"
        ))),
        (x, y) => Ok(x.or(y)),
    }
}

/// The model of a `Robot` and, made on first use, the same robot without friction (FS = FV =
/// 0 on every joint: what Pinocchio's `rnea` and `aba` compute).
pub struct Models {
    pub full: Arc<robodyn::Robot>,
    frictionless: OnceLock<Result<robodyn::Robot, robodyn::Error>>,
}

impl Models {
    fn new(robot: robodyn::Robot) -> Models {
        Models {
            full: Arc::new(robot),
            frictionless: OnceLock::new(),
        }
    }

    /// The robot, or (friction = false) the robot with FS = FV = 0.
    pub fn select(&self, friction: bool) -> PyResult<&robodyn::Robot> {
        if friction {
            return Ok(&self.full);
        }
        self.frictionless
            .get_or_init(|| {
                let mut d = self.full.description().clone();
                for l in &mut d.links {
                    l.params[robodyn::model::param::FS] = robodyn::Expr::zero();
                    l.params[robodyn::model::param::FV] = robodyn::Expr::zero();
                }
                robodyn::Robot::new(d)
            })
            .as_ref()
            .map_err(|e| crate::errors::to_py(e.clone()))
    }
}

/// The library's direct-dynamics method of its name (`"composite"`, `"aba"` or
/// `"articulated"`).
pub fn parse_method(method: &str) -> PyResult<Method> {
    Method::from_name(method).ok_or_else(|| {
        InputError::new_err(format!(
            "method = {method:?}: expected {}",
            quoted(Method::ALL.map(Method::name).as_slice())
        ))
    })
}

/// What a literal 0 means: `zeros` ("absent" or "value"), else by the file it came from.
pub fn parse_zeros(
    zeros: Option<&str>,
    source: Option<&std::path::Path>,
) -> PyResult<ZeroParameters> {
    match zeros {
        None => Ok(source.map_or(ZeroParameters::Value, ZeroParameters::for_path)),
        Some(z) => ZeroParameters::from_name(z).ok_or_else(|| {
            InputError::new_err(format!(
                "zeros = {z:?}: expected {}",
                quoted(ZeroParameters::ALL.map(ZeroParameters::name).as_slice())
            ))
        }),
    }
}

/// The library's rotor mode of its name (`"actuated"`, `"all"`, `"none"`).
pub fn parse_rotor(rotor: &str) -> PyResult<RotorMode> {
    RotorMode::from_name(rotor).ok_or_else(|| {
        InputError::new_err(format!(
            "rotor = {rotor:?}: expected {}",
            quoted(RotorMode::ALL.map(RotorMode::name).as_slice())
        ))
    })
}

/// `"a", "b" or "c"`.
pub fn quoted(names: &[&str]) -> String {
    let q: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
    match q.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => q.join(""),
    }
}

/// A robot model: a tree, or the equivalent tree of a closed chain (use `ClosedChain(robot)`
/// for the closed-chain models).
#[pyclass(module = "robodyn", frozen)]
pub struct Robot {
    inner: RwLock<Arc<Models>>,
    /// Buffers of single-state calls (made for the models they hold; the frictionless robot
    /// has the same structure and shares them).
    cache: Mutex<Option<(Arc<Models>, Work)>>,
    /// The file it was read from (decides what a literal 0 means for base parameters).
    pub source: Option<PathBuf>,
}

/// A call of a model function: the inputs (name, array), the result's shape for one state,
/// whether N states stack their rows (the regressor: (N n, p)) or add a leading N, and the
/// caller's `out`.
pub struct Call<'a, 'py> {
    pub inputs: &'a [(&'a str, Option<&'a Bound<'py, PyAny>>)],
    pub one: &'a [usize],
    pub stacked: bool,
    pub out: Option<&'a Bound<'py, PyAny>>,
}

impl Robot {
    pub fn wrap(robot: robodyn::Robot, source: Option<PathBuf>) -> Robot {
        Robot {
            inner: RwLock::new(Arc::new(Models::new(robot))),
            cache: Mutex::new(None),
            source,
        }
    }

    /// The current models (shared).
    pub fn models(&self) -> Arc<Models> {
        self.inner.read().unwrap().clone()
    }

    /// The current model (shared).
    pub fn model(&self) -> Arc<robodyn::Robot> {
        self.models().full.clone()
    }

    fn with_work<T>(&self, models: &Arc<Models>, f: impl FnOnce(&mut Work) -> T) -> T {
        if let Ok(mut g) = self.cache.try_lock() {
            match g.as_mut() {
                Some((m, w)) if Arc::ptr_eq(m, models) => return f(w),
                _ => {
                    *g = Some((models.clone(), Work::new(&models.full)));
                    return f(&mut g.as_mut().unwrap().1);
                }
            }
        }
        f(&mut Work::new(&models.full))
    }

    fn joint_text(robot: &robodyn::Robot) -> String {
        format!(
            "movable joints [{}]",
            robot.coordinates().names().join(", ")
        )
    }

    /// What the entries of a floating robot's state vectors are, for messages.
    fn state_text(robot: &robodyn::Robot) -> String {
        let n = robot.dof();
        format!(
            "q: nq = 7 + {n} entries (base position, quaternion x y z w, then the {}); \
             velocities, accelerations and forces: nv = 6 + {n} (base linear and angular \
             velocity in the base frame, then the joints)",
            Self::joint_text(robot)
        )
    }

    /// Evaluate `f` (on `robot`, one of `models`) on one state or on every row of N states:
    /// one state on this robot's kept buffers, N states over all cores in blocks with the GIL
    /// released (signals checked between blocks). Inputs are joint vectors (N entries each):
    /// a floating robot is refused (its functions go through [`Robot::eval_state`]).
    /// The three N x N matrices of a derivative model at each state, split into a tuple of
    /// arrays ((n, n) each for one state, (N, n, n) for N states): the shared frame of
    /// `idm_derivatives` and `ddm_derivatives`; `f` fills a state's 3 n^2 outputs.
    fn derivative_matrices<'py, F>(
        &self,
        py: Python<'py>,
        name: &str,
        friction: bool,
        inputs: [(&str, Option<&Bound<'py, PyAny>>); 3],
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        let models = self.models();
        let robot = models.select(friction)?;
        fixed_base_only(robot, name)?;
        // the derivatives read IA, FS, FV per joint: not a transmission's motors yet
        robot.require_no_motor_drives(name).py()?;
        let n = robot.dof();
        let call = Call {
            inputs: &inputs,
            one: &[3, n, n],
            stacked: false,
            out: None,
        };
        let r = self.eval(py, &models, robot, call, f)?;
        split_three(py, r)
    }

    pub fn eval<'py, F>(
        &self,
        py: Python<'py>,
        models: &Arc<Models>,
        robot: &robodyn::Robot,
        call: Call<'_, 'py>,
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        fixed_base_only(robot, "this function")?;
        let n = robot.dof();
        self.eval_sized(
            py,
            models,
            robot,
            call,
            [n; 3],
            &|| Self::joint_text(robot),
            f,
        )
    }

    /// [`Robot::eval`] on the state vectors of a floating robot too: the first input is a
    /// configuration (nq entries), the others velocities, accelerations or forces (nv).
    pub fn eval_state<'py, F>(
        &self,
        py: Python<'py>,
        models: &Arc<Models>,
        robot: &robodyn::Robot,
        call: Call<'_, 'py>,
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        let lens = [robot.nq(), robot.nv(), robot.nv()];
        let text = || {
            if robot.is_floating() {
                Self::state_text(robot)
            } else {
                Self::joint_text(robot)
            }
        };
        self.eval_sized(py, models, robot, call, lens, &text, f)
    }

    #[allow(clippy::too_many_arguments)]
    fn eval_sized<'py, F>(
        &self,
        py: Python<'py>,
        models: &Arc<Models>,
        robot: &robodyn::Robot,
        call: Call<'_, 'py>,
        lens: [usize; 3],
        what: &dyn Fn() -> String,
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        let inp = inputs_sized(call.inputs, lens, what)?;
        let shape = Shape::result(inp.rows, call.one, call.stacked);
        let mut out = Output::new(py, call.out, shape, inp.rows.is_some())?;
        let st = inp.states(out.span())?;
        let width: usize = call.one.iter().product();
        self.run(py, models, robot, &st, width, out.slice(), f)?;
        out.finish(py)
    }

    #[allow(clippy::too_many_arguments)]
    fn run<F>(
        &self,
        py: Python<'_>,
        models: &Arc<Models>,
        robot: &robodyn::Robot,
        st: &States<'_>,
        width: usize,
        out: &mut [f64],
        f: F,
    ) -> PyResult<()>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        match st.rows {
            None => self
                .with_work(models, |w| f(robot, w, st.rows3(0), out))
                .py(),
            Some(rows) => in_blocks(py, rows, out, width, |first, o| {
                for_each_row(
                    o.len() / width.max(1),
                    o,
                    width,
                    || Work::new(robot),
                    |w, i, row| f(robot, w, st.rows3(first + i), row),
                )
                .map_err(|e| shift_row(e, first))
            }),
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
        let friction = if friction {
            Friction::Actuated
        } else {
            Friction::None
        };
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

    /// The robot with values given by name (the library's rule, `robodyn::io::set_values`:
    /// symbols, and standard parameters written as numbers; an unknown name is an error).
    fn with_symbols(&self, values: BTreeMap<String, f64>) -> PyResult<robodyn::Robot> {
        let mut d = self.models().full.description().clone();
        check_finite(&values)?;
        robodyn::io::set_values(&mut d, &values).py()?;
        robodyn::Robot::new(d).py()
    }
}

/// [`Robot::forward_kinematics`] of a floating robot: every description frame's placement in
/// the world from the kinematics pass (its frames must all be tree frames: a cut joint's frame
/// is refused by `frame_id_of`).
fn floating_frames(
    r: &robodyn::Robot,
    w: &mut Work,
    x: [&[f64]; 3],
    o: &mut [f64],
) -> robodyn::Result<()> {
    robodyn::placements_into(r, &mut w.kin, x[0])?;
    for j in 1..=r.nf() {
        let m = robodyn::frame_placement(r, &w.kin, &r.frame_id_of(j)?)?.matrix();
        for a in 0..4 {
            for b in 0..4 {
                o[16 * (j - 1) + 4 * a + b] = m[(a, b)];
            }
        }
    }
    robodyn::error::check_finite_result("0T_j", o)
}

/// The functions of a `Robot` that take a floating robot's state (nq / nv vectors).
pub const FLOATING_FUNCTIONS: &str =
    "idm, h, inertia, ddm, integrate, centroidal_momentum, centroidal_map, simulate, placement, \
     jacobian, frame_velocity, frame_acceleration, com and com_jacobian";

/// The default initial configuration of a simulation: joints at zero and, for a floating
/// robot, the base at the world's origin with the identity orientation (nq entries).
fn neutral_configuration(robot: &robodyn::Robot) -> Vec<f64> {
    let mut q = vec![0.0; robot.nq()];
    if robot.is_floating() {
        q[6] = 1.0;
    }
    q
}

/// The refusal of a function (`what`, e.g. "Robot.jacobian") that does not support floating
/// robots: InputError naming it and the functions that do; Ok for a fixed or mobile base.
pub fn fixed_base_only(robot: &robodyn::Robot, what: &str) -> PyResult<()> {
    if !robot.is_floating() {
        return Ok(());
    }
    let n = robot.dof();
    Err(InputError::new_err(format!(
        "{what}: robot `{}` has a floating base (nq = 7 + {n}, nv = 6 + {n}), which {what} \
         does not support yet; on a floating robot use {FLOATING_FUNCTIONS}",
        robot.name()
    )))
}

/// Values must be finite numbers (NotFiniteError naming the first that is not).
pub fn check_finite(values: &BTreeMap<String, f64>) -> PyResult<()> {
    for (k, v) in values {
        if !v.is_finite() {
            return Err(crate::errors::NotFiniteError::new_err(format!(
                "{k} = {v} is not a finite number"
            )));
        }
    }
    Ok(())
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

    /// nq, the length of a configuration q: the number of movable joints for a fixed (or
    /// mobile) base, 7 + that for a floating base (base position, quaternion x y z w, joints).
    #[getter]
    fn nq(&self) -> usize {
        self.model().nq()
    }

    /// nv, the length of a velocity, acceleration or generalized-force vector (qd, qdd, tau):
    /// the number of movable joints, 6 + that for a floating base (base linear and angular
    /// velocity in the base frame, joints).
    #[getter]
    fn nv(&self) -> usize {
        self.model().nv()
    }

    /// Number of movable joints (the length of the joint vectors; nq = nv = dof on a fixed
    /// base).
    #[getter]
    fn dof(&self) -> usize {
        self.model().dof()
    }

    /// Whether the base floats (a free body whose motion results from the dynamics: state
    /// vectors of nq / nv entries, Pinocchio's free-flyer).
    #[getter]
    fn is_floating(&self) -> bool {
        self.model().is_floating()
    }

    /// What moves the base: "fixed", "mobile" (its motion imposed) or "floating".
    #[getter]
    fn base_kind(&self) -> &'static str {
        self.model().base_kind().name()
    }

    /// Names of the nq entries of q (base_x .. base_qw first on a floating base, then the
    /// joint names).
    #[getter]
    fn configuration_names(&self) -> Vec<String> {
        self.model().configuration_names()
    }

    /// Names of the nv entries of qd, qdd and tau (base_vx .. base_wz first on a floating
    /// base, then the joint names).
    #[getter]
    fn velocity_names(&self) -> Vec<String> {
        self.model().velocity_names()
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

    /// Every frame name `placement`, `jacobian`, `frame_velocity`, ... accept, each once:
    /// tools (the body frames of URDF links), links, then the description's frames (joint
    /// names; cut-joint frames left out). The numbers "0".."NF" are accepted too.
    #[getter]
    fn frame_names(&self) -> Vec<String> {
        let r = self.model();
        r.frame_names().into_iter().map(str::to_string).collect()
    }

    /// Names of the description's frames 1..NF, in frame order (joint names; fixed frames,
    /// cut joints and their twins included): the frames of `forward_kinematics` and
    /// `antecedents`.
    #[getter]
    fn description_frame_names(&self) -> Vec<String> {
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

    /// Standard parameters K (13 per link: XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV), numbers;
    /// a floating robot's link 0 (XX0 .. M0) after the links: the columns of `regressor`.
    #[getter]
    fn standard_parameters(&self) -> Vec<f64> {
        robodyn::algorithms::regressor::regressor_parameters(&self.model())
    }

    /// Names of the standard parameters (the robot file's own names), in K order.
    #[getter]
    fn parameter_names(&self) -> Vec<String> {
        let r = self.model();
        let names = robodyn::algorithms::base_parameters::ParameterNames::of(r.description());
        (0..parameter_count(&r))
            .map(|k| names.name(k).to_string())
            .collect()
    }

    /// Give or change values by name, in place: symbols (`robot.set(d3=0.45)`) or standard
    /// parameters the file writes as numbers (`robot.set(M3=12.0, FS2=0.5)`: mass of link 3 in
    /// kg, Coulomb friction of joint 2 in N m; names as `parameter_names`). An unknown name
    /// raises InputError listing the known ones; nothing changes then.
    #[pyo3(signature = (**values))]
    fn set(&self, values: Option<&Bound<'_, PyDict>>) -> PyResult<()> {
        let r = self.with_symbols(kwargs_values(values)?)?;
        *self.inner.write().unwrap() = Arc::new(Models::new(r));
        Ok(())
    }

    /// A new robot with values given or changed by name as `set` does (this one unchanged):
    /// `urdf_robot.with_values(M3=12.0)` changes the mass of link 3 (kg).
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
        let base = if r.is_floating() {
            format!(", nv={}, floating", r.nv())
        } else {
            String::new()
        };
        format!(
            "Robot({:?}, nq={}{base}, NL={}, NJ={}, loops={})",
            r.name(),
            r.nq(),
            r.nl(),
            r.nj(),
            r.n_loops()
        )
    }

    /// Inverse dynamic model (Newton–Euler, eqs 10.3–10.12): the torques (N m) / forces (N)
    /// tau of the movable joints for positions q (rad, m), velocities qd (rad/s, m/s) and
    /// accelerations qdd (rad/s², m/s²), under the robot's gravity and wrenches.
    ///
    /// Shapes: (nq,) for one state, (N, nq) for N states (the result likewise). On a floating
    /// base q has nq entries, qd, qdd and the result nv (the result: the wrench on the base,
    /// force then moment about its origin in the base frame, then the joint torques;
    /// Pinocchio's rnea with a free-flyer root). Omitted qd,
    /// qdd are zeros; v and a are Pinocchio's names for qd and qdd. Friction Fv qd + Fs sign(qd)
    /// (URDF <dynamics damping friction>) and rotor inertias Ia qdd are included; friction=False
    /// leaves out Fv and Fs (Pinocchio's rnea). out: a float64 C-contiguous writeable array of
    /// the result's shape to write into (returned).
    #[pyo3(signature = (q, qd=None, qdd=None, *, v=None, a=None, friction=true, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn idm<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        qdd: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
        friction: bool,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd = alias("qd", qd, "v", v)?;
        let qdd = alias("qdd", qdd, "a", a)?;
        let models = self.models();
        let robot = models.select(friction)?;
        let n = robot.nv();
        let call = Call {
            inputs: &[("q", Some(q)), ("qd", qd), ("qdd", qdd)],
            one: &[n],
            stacked: false,
            out,
        };
        self.eval_state(py, &models, robot, call, |r, w, x, o| {
            inverse_dynamics_into(r, &mut w.data, r.environment(), x[0], x[1], x[2], o)
        })
    }

    /// Inertia matrix A(q) by composite links (kg m², kg, kg m): (nq, nq) for q of shape (nq,),
    /// (N, nq, nq) for (N, nq); rotor inertias on the diagonal. On a floating base (nv, nv)
    /// for q of nq entries: the base block, the base rows, the joints (Pinocchio's crba).
    /// out: as for idm.
    #[pyo3(signature = (q, *, out=None))]
    fn inertia<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let models = self.models();
        let n = models.full.nv();
        let call = Call {
            inputs: &[("q", Some(q))],
            one: &[n, n],
            stacked: false,
            out,
        };
        self.eval_state(py, &models, &models.full, call, |r, w, x, o| {
            let (data, a) = w.split(n, n);
            inertia_matrix_into(r, data, x[0], a)?;
            for (k, o) in o.iter_mut().enumerate() {
                *o = a[(k / n, k % n)];
            }
            Ok(())
        })
    }

    /// H(q, qd) (N m, N): centrifugal, Coriolis, gravity, friction and external-wrench torques,
    /// so that tau = A(q) qdd + H(q, qd). Shapes as idm (nv entries on a floating base); v is Pinocchio's name for qd
    /// (Pinocchio's nonLinearEffects, plus friction unless friction=False). out: as for idm.
    #[pyo3(signature = (q, qd=None, *, v=None, friction=true, out=None))]
    fn h<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        friction: bool,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd = alias("qd", qd, "v", v)?;
        let models = self.models();
        let robot = models.select(friction)?;
        let n = robot.nv();
        let call = Call {
            inputs: &[("q", Some(q)), ("qd", qd)],
            one: &[n],
            stacked: false,
            out,
        };
        self.eval_state(py, &models, robot, call, |r, w, x, o| {
            h_vector_into(r, &mut w.data, r.environment(), x[0], x[1], o)
        })
    }

    /// Direct dynamic model: accelerations qdd (rad/s², m/s²) = A^-1 (tau - H) for positions q,
    /// velocities qd and torques tau (N m, N); method "composite" (tree L'DL of A) or "aba"
    /// (articulated bodies). Shapes as idm (on a floating base: q nq entries, qd, tau and the
    /// result nv, tau's 6 first the wrench applied on the base, zero for a free robot, the
    /// result's 6 first the derivative of the base twist; Pinocchio's aba); v is Pinocchio's
    /// name for qd. friction=False
    /// leaves out Fv and Fs (Pinocchio's aba). Raises SingularConfiguration for a singular A.
    /// out: as for idm.
    #[pyo3(signature = (q, qd=None, tau=None, method="composite", *, v=None, friction=true, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn ddm<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        tau: Option<&Bound<'py, PyAny>>,
        method: &str,
        v: Option<&Bound<'py, PyAny>>,
        friction: bool,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let m = parse_method(method)?;
        let qd = alias("qd", qd, "v", v)?;
        let models = self.models();
        let robot = models.select(friction)?;
        let n = robot.nv();
        let call = Call {
            inputs: &[("q", Some(q)), ("qd", qd), ("tau", tau)],
            one: &[n],
            stacked: false,
            out,
        };
        self.eval_state(py, &models, robot, call, move |r, w, x, o| {
            direct_dynamics_into(r, &mut w.data, r.environment(), x[0], x[1], x[2], m, o)
        })
    }

    /// Derivatives of the inverse dynamic model (analytical, docs/models/derivatives.md):
    /// (dtau_dq, dtau_dqd, A) with A = dtau/dqdd the inertia matrix, each (nq, nq) for one
    /// state, (N, nq, nq) for N states (q, qd, qdd of shape (N, nq)); entry [j, k] is the
    /// derivative of tau_j with respect to joint k. Arguments as idm (Coulomb friction has a
    /// zero derivative, viscous friction adds Fv on dtau_dqd's diagonal; friction=False leaves
    /// both out: Pinocchio's computeRNEADerivatives).
    #[pyo3(signature = (q, qd=None, qdd=None, *, v=None, a=None, friction=true))]
    #[allow(clippy::too_many_arguments)]
    fn idm_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        qdd: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
        friction: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd = alias("qd", qd, "v", v)?;
        let qdd = alias("qdd", qdd, "a", a)?;
        let inputs = [("q", Some(q)), ("qd", qd), ("qdd", qdd)];
        self.derivative_matrices(
            py,
            "Robot.idm_derivatives",
            friction,
            inputs,
            |r, w, x, o| {
                let (data, d, _) = w.deriv(r);
                inverse_dynamics_derivatives_into(r, data, r.environment(), x[0], x[1], x[2], d)?;
                copy_matrices(&[&d.dtau_dq, &d.dtau_dqd, &d.a], o);
                Ok(())
            },
        )
    }

    /// Derivatives of the direct dynamic model at qdd = ddm(q, qd, tau) (composite method):
    /// (dqdd_dq, dqdd_dqd, Ainv) with Ainv = dqdd/dtau = A^-1, from the one L'DL factorization
    /// of A. Shapes as idm_derivatives; arguments as ddm (friction=False: Pinocchio's
    /// computeABADerivatives). Raises SingularConfiguration for a singular A.
    #[pyo3(signature = (q, qd=None, tau=None, *, v=None, friction=true))]
    fn ddm_derivatives<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: Option<&Bound<'py, PyAny>>,
        tau: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        friction: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd = alias("qd", qd, "v", v)?;
        let inputs = [("q", Some(q)), ("qd", qd), ("tau", tau)];
        self.derivative_matrices(
            py,
            "Robot.ddm_derivatives",
            friction,
            inputs,
            |r, w, x, o| {
                let (data, _, d) = w.deriv(r);
                direct_dynamics_derivatives_into(r, data, r.environment(), x[0], x[1], x[2], d)?;
                copy_matrices(&[&d.dqdd_dq, &d.dqdd_dqd, &d.ainv], o);
                Ok(())
            },
        )
    }

    /// Geometric model: 0T_j (4 x 4 homogeneous matrices, metres) of the frames 1..NF
    /// (description_frame_names) for the movable joints' values q (rad, m; cut-joint variables taken as
    /// 0): shape (NF, 4, 4) for q of shape (nq,), (N, NF, 4, 4) for (N, nq). A floating robot's
    /// q holds its base pose first (nq = 7 + N) and the placements are in the world frame.
    /// out: as for idm.
    #[pyo3(signature = (q, *, out=None))]
    fn forward_kinematics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let models = self.models();
        let nf = models.full.nf();
        let call = Call {
            inputs: &[("q", Some(q))],
            one: &[nf, 4, 4],
            stacked: false,
            out,
        };
        if models.full.is_floating() {
            return self.eval_state(py, &models, &models.full, call, floating_frames);
        }
        self.eval(py, &models, &models.full, call, |r, _w, x, o| {
            for (j, t) in robodyn::geometry::frame_transforms(r, x[0])?
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
            robodyn::error::check_finite_result("0T_j", o)
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
        let robot = self.model();
        Ok(self.columns(&robot, columns, friction, rotor, seed)?.1)
    }

    /// Regressor Phi with tau = Phi K (+ external-wrench torques) for q (rad, m), qd, qdd
    /// (v, a: Pinocchio's names): shape (nq, p) for one state, stacked (N nq, p) for N states
    /// (state after state); its columns are `regressor_columns(columns, ...)`, the standard
    /// parameters (K, 13 per link) or the base parameters; entries in N m (N) per unit of the
    /// parameter. friction=False leaves out the FS, FV columns. out: as for idm. A floating
    /// robot: q (nq,), v and a (nv,), Phi (nv, p) with the base wrench's 6 rows first and link
    /// 0's columns XX0 .. M0 after the links' (columns="base": the numerical base set).
    #[pyo3(signature = (q, qd=None, qdd=None, columns="standard", friction=true, rotor="actuated", seed=1, *, v=None, a=None, out=None))]
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
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd = alias("qd", qd, "v", v)?;
        let qdd = alias("qdd", qdd, "a", a)?;
        let models = self.models();
        let robot = &models.full;
        // its IA, FS, FV columns are joint-side: with motors' values Phi K is not idm
        robot.require_no_motor_drives("Robot.regressor").py()?;
        let (cols, _) = self.columns(robot, columns, friction, rotor, seed)?;
        let n = robot.nv();
        let nk = parameter_count(robot);
        let call = Call {
            inputs: &[("q", Some(q)), ("qd", qd), ("qdd", qdd)],
            one: &[n, cols.len()],
            stacked: true,
            out,
        };
        self.eval_state(py, &models, robot, call, |r, w, x, o| {
            let (data, phi) = w.split(n, nk);
            regressor_into(r, data, r.environment(), x[0], x[1], x[2], phi)?;
            copy_rows(&w.m, &cols, o);
            Ok(())
        })
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

    /// Customized symbolic model as code with its operation counts. On a floating robot the
    /// model is "idm" only: inputs q (nq), qd, qdd (nv), outputs the base wrench (force, moment
    /// about O_0, in the base frame) then the joint torques.
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

    /// Simulate from (q0, qd0) (rad, m; rad/s, m/s; default zeros) over [0, duration] (s);
    /// returns a dict of arrays: t (M,) s, q (M, nq), qd, qdd, tau (M, nv), energy (M,) J,
    /// joint_labels, q_columns and v_columns (the names of q's and of the others' columns).
    /// torque: None (zero), a constant vector (n,) N m / N, a (times, values) series ((K,),
    /// (K, n)) interpolated linearly, or a callable torque(t, q, qd) -> tau. A floating robot
    /// (docs/models/floating_base.md): q0 has nq entries (default: the base at the origin,
    /// identity quaternion, joints at zero), qd0 nv; the torques are the n joints' (the base
    /// free) or nv values whose first 6 are a wrench applied on the base (base frame); the
    /// base pose is integrated on SE(3), and the dict adds the centre of mass and momenta.
    /// RK4 with a fixed step dt (s), else Dormand–Prince 5(4) with rtol, atol; a row every
    /// output_dt (s). max_steps (the CLI's default, 5,000,000) bounds the integration steps: a
    /// run that needs more is an error, said before it starts when the step or the output step
    /// already needs more. Ctrl-C stops the run (KeyboardInterrupt).
    #[pyo3(signature = (duration, q0=None, qd0=None, torque=None, dt=None, rtol=1e-8, atol=1e-10, output_dt=0.01, method="aba", coulomb_smoothing=None, max_steps=5_000_000))]
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
        max_steps: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let robot = self.model();
        let mut dynamics = crate::models::tree_dynamics(&robot, method, coulomb_smoothing)?;
        let args = crate::models::SimArgs {
            duration,
            q0: q0.unwrap_or_else(|| neutral_configuration(&robot)),
            qd0: qd0.unwrap_or_else(|| vec![0.0; robot.nv()]),
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
