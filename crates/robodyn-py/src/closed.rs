//! `robodyn.ClosedChain`: the closed-chain models on the actuated joints, with the branch
//! tracker held by the object. The rows of a batch are evaluated in order on one assembly
//! branch (each row reached from the previous one), with the GIL released.

use crate::arrays::{in_blocks, inputs, Output, Shape};
use crate::errors::{InputError, IntoPy};
use crate::robot::{alias, copy_matrices, copy_rows, split_three, Call, Robot};
use nalgebra::DMatrix;
use numpy::PyArrayMethods;
use pyo3::create_exception;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::algorithms::kinematics::{closed_frame_drift, closed_frame_jacobian};
use robodyn::algorithms::regressor::PARAMS_PER_LINK;
use robodyn::{
    closed_direct_dynamics_derivatives_into, closed_direct_dynamics_into,
    closed_inverse_dynamics_derivatives_into, closed_inverse_dynamics_into, closed_regressor_into,
    loop_closure, loop_closure_into, Branch, ClosedData, ClosedDdmDerivatives,
    ClosedDerivativesData, ClosedIdmDerivatives, Conditioning,
};
use std::sync::{Arc, Mutex};

create_exception!(
    robodyn,
    SingularityWarning,
    PyUserWarning,
    "A result near a singular configuration (reciprocal condition number below the soft limit)."
);

struct Tracker {
    branch: Branch,
    data: ClosedData,
    phi: DMatrix<f64>,
    tau_e: Vec<f64>,
    /// The derivatives' buffers and outputs, made at the first derivatives call.
    deriv: Option<Box<Derivatives>>,
}

/// The closed-chain derivatives' buffers and outputs.
struct Derivatives {
    data: ClosedDerivativesData,
    idm: ClosedIdmDerivatives,
    ddm: ClosedDdmDerivatives,
}

impl Tracker {
    /// The derivatives' buffers for `chain` (made once) and the branch.
    fn deriv(&mut self, chain: &robodyn::ClosedChain) -> (&mut Derivatives, &mut Branch) {
        let d = self.deriv.get_or_insert_with(|| {
            Box::new(Derivatives {
                data: ClosedDerivativesData::new(chain),
                idm: ClosedIdmDerivatives::new(chain),
                ddm: ClosedDdmDerivatives::new(chain),
            })
        });
        (d, &mut self.branch)
    }
}

/// A closed-chain robot: vectors over the actuated joints (`joint_names`), the passive ones
/// solved by loop closure on the tracker's assembly branch.
#[pyclass(module = "robodyn", frozen)]
pub struct ClosedChain {
    chain: Arc<robodyn::ClosedChain>,
    tracker: Mutex<Tracker>,
    source: Option<std::path::PathBuf>,
}

/// The worst-conditioned row that warned (0-based) and its conditioning.
type Worst = Option<(usize, Conditioning)>;

/// Whether `c` is worse conditioned than the row kept in `worst`.
fn worse(worst: &Worst, c: &Conditioning) -> bool {
    match worst {
        None => true,
        Some((_, w)) => c.wp < w.wp || c.a_cl.unwrap_or(1.0) < w.a_cl.unwrap_or(1.0),
    }
}

impl ClosedChain {
    /// Evaluate `f` on one state or on the N rows in order (one branch, the tracker moving
    /// from row to row), in blocks with the GIL released, the signals checked between blocks;
    /// a SingularityWarning names the worst row near a singularity.
    fn eval<'py, F>(
        &self,
        py: Python<'py>,
        name: &str,
        call: Call<'_, 'py>,
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(
                &robodyn::ClosedChain,
                &mut Tracker,
                [&[f64]; 3],
                &mut [f64],
            ) -> robodyn::Result<Conditioning>
            + Send
            + Sync,
    {
        let chain = &self.chain;
        let inp = inputs(call.inputs, chain.dof(), &|| {
            format!(
                "actuated joints [{}]",
                chain.coordinates().names().join(", ")
            )
        })?;
        let shape = Shape::result(inp.rows, call.one, call.stacked);
        let mut out = Output::new(py, call.out, shape, inp.rows.is_some())?;
        let st = inp.states(out.span())?;
        let width: usize = call.one.iter().product();
        let mut worst: Worst = None;
        in_blocks(py, st.count(), out.slice(), width, |first, o| {
            let mut t = self.tracker.lock().unwrap();
            for (i, row) in o.chunks_mut(width.max(1)).enumerate() {
                let r = first + i;
                let c = f(chain, &mut t, st.rows3(r), row)
                    .and_then(|c| {
                        // the library's rule for results (finite inputs can overflow), which
                        // the closed-chain functions do not apply themselves yet
                        robodyn::error::check_finite_result(name, row)?;
                        Ok(c)
                    })
                    .map_err(|e| {
                        if st.rows.is_some() {
                            e.in_row(r + 1)
                        } else {
                            e
                        }
                    })?;
                if c.warning && worse(&worst, &c) {
                    worst = Some((r, c));
                }
            }
            Ok(())
        })?;
        if let Some((r, c)) = worst {
            let at = if st.rows.is_some() {
                format!(" (worst at row {})", r + 1)
            } else {
                String::new()
            };
            let msg = format!(
                "near a singular configuration{at}: {}",
                c.describe(chain.limits())
            );
            py.import("warnings")?
                .call_method1("warn", (msg, py.get_type::<SingularityWarning>(), 1))?;
        }
        out.finish(py)
    }
}

/// A closed-chain model over the actuated joints, three vectors in and one out
/// (`closed_inverse_dynamics_into`, `closed_direct_dynamics_into`).
type JointModel = fn(
    &robodyn::ClosedChain,
    &mut ClosedData,
    &mut Branch,
    &robodyn::Environment,
    &[f64],
    &[f64],
    &[f64],
    &mut [f64],
) -> robodyn::Result<Conditioning>;

impl ClosedChain {
    /// The three N x N matrices of a derivative model at each state (one state, or N rows
    /// followed in order on the branch), split into a tuple of arrays ((n, n) each, or
    /// (N, n, n)): what `idm_derivatives` and `ddm_derivatives` share.
    fn derivative_matrices<'py, F>(
        &self,
        py: Python<'py>,
        name: &str,
        inputs: [(&str, Option<&Bound<'py, PyAny>>); 3],
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(
                &robodyn::ClosedChain,
                &mut Derivatives,
                &mut Branch,
                [&[f64]; 3],
                &mut [f64],
            ) -> robodyn::Result<Conditioning>
            + Send
            + Sync,
    {
        let n = self.chain.dof();
        let call = Call {
            inputs: &inputs,
            one: &[3, n, n],
            stacked: false,
            out: None,
        };
        let r = self.eval(py, name, call, |c, t, x, o| {
            let (d, b) = t.deriv(c);
            f(c, d, b, x, o)
        })?;
        split_three(py, r)
    }

    /// `model` on one state or N states of the three named `inputs` (over the actuated
    /// joints), its result named `result` in messages: what `idm` and `ddm` share.
    fn dynamics<'py>(
        &self,
        py: Python<'py>,
        result: &str,
        inputs: [(&str, Option<&Bound<'py, PyAny>>); 3],
        out: Option<&Bound<'py, PyAny>>,
        model: JointModel,
    ) -> PyResult<Bound<'py, PyAny>> {
        let call = Call {
            inputs: &inputs,
            one: &[self.chain.dof()],
            stacked: false,
            out,
        };
        self.eval(py, result, call, |c, t, x, o| {
            let env = c.robot().environment();
            model(c, &mut t.data, &mut t.branch, env, x[0], x[1], x[2], o)
        })
    }
}

#[pymethods]
impl ClosedChain {
    /// The closed-chain model of `robot`, its tracker on the branch of the robot's `assembly`
    /// (or, with `q_a` and `q_p_guess`, on the branch through that configuration).
    #[new]
    #[pyo3(signature = (robot, q_a=None, q_p_guess=None))]
    fn new(robot: &Robot, q_a: Option<Vec<f64>>, q_p_guess: Option<Vec<f64>>) -> PyResult<Self> {
        let chain = robodyn::ClosedChain::new(&robot.model()).py()?;
        let branch = match (q_a, q_p_guess) {
            (Some(a), Some(p)) => chain.branch_from(&a, &p),
            (None, None) => chain.assembly_branch(),
            _ => {
                return Err(InputError::new_err(
                    "give both q_a and q_p_guess, or neither (the robot's assembly)",
                ))
            }
        }
        .py()?;
        let data = ClosedData::new(&chain);
        Ok(ClosedChain {
            tracker: Mutex::new(Tracker {
                branch,
                data,
                phi: DMatrix::zeros(0, 0),
                tau_e: vec![0.0; chain.dof()],
                deriv: None,
            }),
            chain: Arc::new(chain),
            source: robot.source.clone(),
        })
    }

    /// Names of the actuated joints: the order of every vector of the closed-chain models.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.chain.coordinates().names().to_vec()
    }

    /// Frame numbers of the actuated joints.
    #[getter]
    fn joint_frames(&self) -> Vec<usize> {
        self.chain.coordinates().frames().to_vec()
    }

    /// Names of the passive tree joints (the order of q_p).
    #[getter]
    fn passive_names(&self) -> Vec<String> {
        self.chain.passive_coordinates().names().to_vec()
    }

    /// Degrees of freedom (actuated joints).
    #[getter]
    fn nq(&self) -> usize {
        self.chain.dof()
    }

    /// Number of independent closure equations (= passive tree joints).
    #[getter]
    fn n_equations(&self) -> usize {
        self.chain.n_equations()
    }

    /// The equivalent tree as a `Robot`.
    #[getter]
    fn robot(&self) -> Robot {
        Robot::wrap(self.chain.robot().clone(), self.source.clone())
    }

    /// The tracker's point: dict with q_a, q_p, det_sign (the branch) and rcond of Wp.
    #[getter]
    fn branch<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let t = self.tracker.lock().unwrap();
        let d = PyDict::new(py);
        d.set_item("q_a", t.branch.q_a().to_vec())?;
        d.set_item("q_p", t.branch.q_p().to_vec())?;
        d.set_item("det_sign", t.branch.det_sign())?;
        d.set_item("rcond", t.branch.rcond())?;
        Ok(d)
    }

    /// Put the tracker back on the assembly branch (or on the branch through (q_a, q_p_guess)).
    #[pyo3(signature = (q_a=None, q_p_guess=None))]
    fn reset(
        &self,
        py: Python<'_>,
        q_a: Option<Vec<f64>>,
        q_p_guess: Option<Vec<f64>>,
    ) -> PyResult<()> {
        let chain = &self.chain;
        let b = py
            .detach(|| match (q_a, q_p_guess) {
                (Some(a), Some(p)) => chain.branch_from(&a, &p),
                (None, None) => chain.assembly_branch(),
                _ => Err(robodyn::Error::Input(
                    "give both q_a and q_p_guess, or neither (the robot's assembly)".into(),
                )),
            })
            .py()?;
        self.tracker.lock().unwrap().branch = b;
        Ok(())
    }

    /// Loop closure: the passive tree variables q_p (rad, m) for the actuated q_a (rad, m):
    /// (p,) for q_a of shape (nq,), (N, p) for (N, nq), p = n_equations. out: as for idm.
    #[pyo3(signature = (q_a, *, out=None))]
    fn solve_loops<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let p = self.chain.n_equations();
        let call = Call {
            inputs: &[("q_a", Some(q_a))],
            one: &[p],
            stacked: false,
            out,
        };
        self.eval(py, "q_p", call, |c, t, x, o| {
            loop_closure_into(c, &mut t.data, &mut t.branch, x[0], o)
        })
    }

    /// Loop closure at one q_a (nq,): q_p, cut-joint variables q_c, the tree's movable-joint
    /// vector q_tree (rad, m), W = d q_p / d q_a (eq 10.30, (p, nq)), residual, rcond_wp,
    /// warning.
    fn closure<'py>(&self, py: Python<'py>, q_a: Vec<f64>) -> PyResult<Bound<'py, PyDict>> {
        let chain = &self.chain;
        let s = py
            .detach(|| {
                let mut t = self.tracker.lock().unwrap();
                loop_closure(chain, &mut t.branch, &q_a)
            })
            .py()?;
        let d = PyDict::new(py);
        let np = |v: &[f64]| numpy::PyArray1::from_slice(py, v);
        d.set_item("q_a", np(s.q_a.as_slice()))?;
        d.set_item("q_p", np(s.q_p.as_slice()))?;
        d.set_item("q_c", np(s.q_c.as_slice()))?;
        d.set_item("q_tree", np(s.q_tree.as_slice()))?;
        let (r, c) = s.w.shape();
        let mut w = vec![0.0; r * c];
        let all: Vec<usize> = (0..c).collect();
        copy_rows(&s.w, &all, &mut w);
        d.set_item("W", numpy::PyArray1::from_vec(py, w).reshape([r, c])?)?;
        d.set_item("residual", s.residual)?;
        d.set_item("rcond_wp", s.conditioning.wp)?;
        d.set_item("warning", s.conditioning.warning)?;
        Ok(d)
    }

    /// Jacobian J_a = J_tr G of the frame named `frame` (as `Robot.placement`) in the actuated
    /// coordinates, in `reference` ("world", "local", "local_world_aligned", as
    /// `Robot.jacobian`): the frame's velocity is J_a qd_a on the closure manifold, the
    /// passive joints solved by loop closure on the tracker's branch. Rows [linear; angular]:
    /// shape (6, nq) for q_a of shape (nq,), (N, 6, nq) for (N, nq) (rows followed in order on
    /// one branch). out: as for idm.
    #[pyo3(signature = (q_a, frame, reference="world", *, out=None))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rf = crate::kinematics::parse_reference(reference)?;
        let f = self.chain.robot().frame_id(frame).py()?;
        let n = self.chain.dof();
        let call = Call {
            inputs: &[("q_a", Some(q_a))],
            one: &[6, n],
            stacked: false,
            out,
        };
        self.eval(py, "J_a", call, move |c, t, x, o| {
            let j = closed_frame_jacobian(c, &mut t.branch, x[0], &f, rf)?;
            crate::kinematics::write_matrix(&j.j_a, o);
            Ok(j.state.conditioning)
        })
    }

    /// Drift J̇_a qd_a = J_tr Ġ qd_a + J̇_tr qd_tr of the frame named `frame` in `reference`
    /// (as `jacobian`): the derivative of the frame's velocity J_a qd_a on the closure
    /// manifold is J_a qdd_a + J̇_a qd_a ("local_world_aligned": the acceleration of the
    /// frame's origin and the angular acceleration in the base axes). [linear; angular]
    /// (m/s², rad/s²) for q_a (rad, m) and qd_a (rad/s, m/s): shape (6,) for one state,
    /// (N, 6) for (N, nq) (rows followed in order on one branch). out: as for idm.
    #[pyo3(signature = (q_a, qd_a, frame, reference="world", *, out=None))]
    fn drift<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rf = crate::kinematics::parse_reference(reference)?;
        let f = self.chain.robot().frame_id(frame).py()?;
        let call = Call {
            inputs: &[("q_a", Some(q_a)), ("qd_a", Some(qd_a))],
            one: &[6],
            stacked: false,
            out,
        };
        self.eval(py, "drift", call, move |c, t, x, o| {
            let d = closed_frame_drift(c, &mut t.branch, x[0], x[1], &f, rf)?;
            o.copy_from_slice(d.drift.to_vector().as_slice());
            Ok(d.jacobian.state.conditioning)
        })
    }

    /// Closed-chain inverse dynamic model Γ_cl = G^T Γ_tr (eq 10.40): the torques (N m) /
    /// forces (N) of the actuated joints for their positions q_a (rad, m), velocities qd_a and
    /// accelerations qdd_a (v, a: Pinocchio's names), the passive joints solved by loop
    /// closure. Shapes (nq,) or (N, nq) (rows followed in order on one branch). out: a float64
    /// C-contiguous writeable array of the result's shape to write into (returned).
    #[pyo3(signature = (q_a, qd_a=None, qdd_a=None, *, v=None, a=None, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn idm<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        qdd_a: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd_a = alias("qd_a", qd_a, "v", v)?;
        let qdd_a = alias("qdd_a", qdd_a, "a", a)?;
        let inputs = [("q_a", Some(q_a)), ("qd_a", qd_a), ("qdd_a", qdd_a)];
        self.dynamics(py, "tau_a", inputs, out, closed_inverse_dynamics_into)
    }

    /// Closed-chain direct dynamic model qdd_a = A_cl^-1 (Γ_cl - H_cl) (eqs 10.46–10.48): the
    /// accelerations (rad/s², m/s²) of the actuated joints for q_a, qd_a (v: Pinocchio's name)
    /// and their torques tau_a (N m, N). Shapes as idm. out: as for idm.
    #[pyo3(signature = (q_a, qd_a=None, tau_a=None, *, v=None, out=None))]
    fn ddm<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        tau_a: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd_a = alias("qd_a", qd_a, "v", v)?;
        let inputs = [("q_a", Some(q_a)), ("qd_a", qd_a), ("tau_a", tau_a)];
        self.dynamics(py, "qdd_a", inputs, out, closed_direct_dynamics_into)
    }

    /// Derivatives of the closed-chain inverse dynamic model (docs/models/derivatives.md,
    /// C1–C9): (dtau_dq, dtau_dqd, A_cl), the derivatives of Γ_cl with respect to q_a, qd_a and
    /// qdd_a with the loops kept closed on the branch (entry [j, k]: of tau_a,j with respect to
    /// joint k), exact (the tree's analytical derivatives and dual numbers through the closure).
    /// Shapes (nq, nq) each for one state, (N, nq, nq) for N states (rows followed in order on
    /// one branch). Arguments as idm.
    #[pyo3(signature = (q_a, qd_a=None, qdd_a=None, *, v=None, a=None))]
    #[allow(clippy::too_many_arguments)]
    fn idm_derivatives<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        qdd_a: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd_a = alias("qd_a", qd_a, "v", v)?;
        let qdd_a = alias("qdd_a", qdd_a, "a", a)?;
        let inputs = [("q_a", Some(q_a)), ("qd_a", qd_a), ("qdd_a", qdd_a)];
        self.derivative_matrices(py, "idm_derivatives", inputs, |c, d, b, x, o| {
            let env = c.robot().environment();
            let cond = closed_inverse_dynamics_derivatives_into(
                c,
                &mut d.data,
                b,
                env,
                x[0],
                x[1],
                x[2],
                &mut d.idm,
            )?;
            copy_matrices(&[&d.idm.dtau_dq, &d.idm.dtau_dqd, &d.idm.a], o);
            Ok(cond)
        })
    }

    /// Derivatives of the closed-chain direct dynamic model at qdd_a = ddm(q_a, qd_a, tau_a)
    /// (C10–C11): (dqdd_dq, dqdd_dqd, Ainv) with Ainv = dqdd_a/dtau_a = A_cl^-1, from the
    /// Cholesky factor of the closed direct model. Shapes as idm_derivatives; arguments as ddm.
    #[pyo3(signature = (q_a, qd_a=None, tau_a=None, *, v=None))]
    fn ddm_derivatives<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        tau_a: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd_a = alias("qd_a", qd_a, "v", v)?;
        let inputs = [("q_a", Some(q_a)), ("qd_a", qd_a), ("tau_a", tau_a)];
        self.derivative_matrices(py, "ddm_derivatives", inputs, |c, d, b, x, o| {
            let env = c.robot().environment();
            let cond = closed_direct_dynamics_derivatives_into(
                c,
                &mut d.data,
                b,
                env,
                x[0],
                x[1],
                x[2],
                &mut d.ddm,
            )?;
            copy_matrices(&[&d.ddm.dqdd_dq, &d.ddm.dqdd_dqd, &d.ddm.ainv], o);
            Ok(cond)
        })
    }

    /// Regressor of the closed chain, G^T Φ over all 13 NL standard parameters (K order,
    /// `robot.parameter_names`): (nq, 13 NL) for one state, stacked (N nq, 13 NL) for N states,
    /// for q_a, qd_a, qdd_a (v, a: Pinocchio's names). out: as for idm.
    #[pyo3(signature = (q_a, qd_a=None, qdd_a=None, *, v=None, a=None, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        qdd_a: Option<&Bound<'py, PyAny>>,
        v: Option<&Bound<'py, PyAny>>,
        a: Option<&Bound<'py, PyAny>>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let qd_a = alias("qd_a", qd_a, "v", v)?;
        let qdd_a = alias("qdd_a", qdd_a, "a", a)?;
        let n = self.chain.dof();
        let nk = PARAMS_PER_LINK * self.chain.robot().nl();
        let call = Call {
            inputs: &[("q_a", Some(q_a)), ("qd_a", qd_a), ("qdd_a", qdd_a)],
            one: &[n, nk],
            stacked: true,
            out,
        };
        self.eval(py, "Phi", call, |c, t, x, o| {
            if t.phi.shape() != (n, nk) {
                t.phi = DMatrix::zeros(n, nk);
            }
            let cond = closed_regressor_into(
                c,
                &mut t.data,
                &mut t.branch,
                c.robot().environment(),
                x,
                &mut t.phi,
                &mut t.tau_e,
            )?;
            for (k, o) in o.iter_mut().enumerate() {
                *o = t.phi[(k / nk, k % nk)];
            }
            Ok(cond)
        })
    }

    /// Simulate in the actuated coordinates from (q0, qd0) (rad, m; rad/s, m/s; default: the
    /// tracker's q_a, zeros) over [0, duration] (s); the passive joints are re-solved at every
    /// evaluation. Returns a dict of arrays: t (M,) s, q, qd, qdd, tau (M, nq) over the actuated
    /// joints, energy (M,) J, closure_residual (M,) and the passive joints' q<j> (M,). torque,
    /// dt, rtol, atol, output_dt, max_steps as for Robot.simulate; Ctrl-C stops the run.
    #[pyo3(signature = (duration, q0=None, qd0=None, torque=None, dt=None, rtol=1e-8, atol=1e-10, output_dt=0.01, coulomb_smoothing=None, max_steps=5_000_000))]
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
        coulomb_smoothing: Option<f64>,
        max_steps: usize,
    ) -> PyResult<Bound<'py, PyDict>> {
        let n = self.chain.dof();
        let branch = self.tracker.lock().unwrap().branch.clone();
        let q0 = q0.unwrap_or_else(|| branch.q_a().to_vec());
        let mut dynamics =
            robodyn::simulation::ClosedChainDynamics::new((*self.chain).clone(), branch)
                .with_coulomb_smoothing(coulomb_smoothing);
        let args = crate::models::SimArgs {
            duration,
            q0,
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
