//! `robodyn.ClosedChain`: the closed-chain models on the actuated joints, with the branch
//! tracker held by the object. The rows of a batch are evaluated in order on one assembly
//! branch (each row reached from the previous one), with the GIL released.

use crate::arrays::{output, states};
use crate::errors::{InputError, IntoPy};
use crate::robot::{copy_rows, Robot};
use nalgebra::DMatrix;
use pyo3::create_exception;
use pyo3::exceptions::PyUserWarning;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::algorithms::regressor::PARAMS_PER_LINK;
use robodyn::{
    closed_direct_dynamics_into, closed_inverse_dynamics_into, closed_regressor_into, loop_closure,
    loop_closure_into, Branch, ClosedData, Conditioning,
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
}

/// A closed-chain robot: vectors over the actuated joints (`joint_names`), the passive ones
/// solved by loop closure on the tracker's assembly branch.
#[pyclass(module = "robodyn", frozen)]
pub struct ClosedChain {
    chain: Arc<robodyn::ClosedChain>,
    tracker: Mutex<Tracker>,
    source: Option<std::path::PathBuf>,
}

/// Results of the rows, and the worst-conditioned row that warned (0-based).
type RowsAndWorst = (Vec<f64>, Option<(usize, Conditioning)>);

impl ClosedChain {
    fn eval<'py, F>(
        &self,
        py: Python<'py>,
        inputs: &[(&str, Option<&Bound<'py, PyAny>>)],
        shape_one: &[usize],
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
        let st = states(inputs, chain.dof(), &|| {
            format!(
                "actuated joints [{}]",
                chain.coordinates().names().join(", ")
            )
        })?;
        let width: usize = shape_one.iter().product();
        let k = st.data.len();
        let rows = st.count();
        let (v, warn) = py
            .detach(|| -> robodyn::Result<RowsAndWorst> {
                let mut t = self.tracker.lock().unwrap();
                let mut out = vec![0.0; rows * width];
                let mut warn: Option<(usize, Conditioning)> = None;
                for r in 0..rows {
                    let x: [&[f64]; 3] =
                        std::array::from_fn(|i| if i < k { st.row(i, r) } else { &[][..] });
                    let c =
                        f(chain, &mut t, x, &mut out[r * width..(r + 1) * width]).map_err(|e| {
                            if st.rows.is_some() {
                                e.in_row(r + 1)
                            } else {
                                e
                            }
                        })?;
                    let worse = match &warn {
                        None => true,
                        Some((_, w)) => {
                            c.wp < w.wp || c.a_cl.unwrap_or(1.0) < w.a_cl.unwrap_or(1.0)
                        }
                    };
                    if c.warning && worse {
                        warn = Some((r, c));
                    }
                }
                Ok((out, warn))
            })
            .py()?;
        if let Some((r, c)) = warn {
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
                .call_method1("warn", (msg, py.get_type::<SingularityWarning>(), 2))?;
        }
        output(py, v, st.rows, shape_one)
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

    /// Loop closure: the passive tree variables q_p for the actuated q_a, (p,) or (N, p).
    fn solve_loops<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let p = self.chain.n_equations();
        self.eval(py, &[("q_a", Some(q_a))], &[p], |c, t, x, o| {
            loop_closure_into(c, &mut t.data, &mut t.branch, x[0], o)
        })
    }

    /// Loop closure at one q_a with everything: q_p, cut-joint variables q_c, the tree's
    /// movable-joint vector q_tree, W = d q_p / d q_a (10.30), residual and rcond of Wp.
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
        d.set_item("W", output(py, w, None, &[r, c])?)?;
        d.set_item("residual", s.residual)?;
        d.set_item("rcond_wp", s.conditioning.wp)?;
        d.set_item("warning", s.conditioning.warning)?;
        Ok(d)
    }

    /// Closed-chain inverse dynamic model Γ_cl = G^T Γ_tr (10.40) on the actuated joints.
    #[pyo3(signature = (q_a, qd_a=None, qdd_a=None))]
    fn idm<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        qdd_a: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.chain.dof();
        self.eval(
            py,
            &[("q_a", Some(q_a)), ("qd_a", qd_a), ("qdd_a", qdd_a)],
            &[n],
            |c, t, x, o| {
                closed_inverse_dynamics_into(
                    c,
                    &mut t.data,
                    &mut t.branch,
                    c.robot().environment(),
                    x[0],
                    x[1],
                    x[2],
                    o,
                )
            },
        )
    }

    /// Closed-chain direct dynamic model qdd_a = A_cl^-1 (Γ_cl - H_cl) (10.46–10.48).
    #[pyo3(signature = (q_a, qd_a=None, tau_a=None))]
    fn ddm<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        tau_a: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.chain.dof();
        self.eval(
            py,
            &[("q_a", Some(q_a)), ("qd_a", qd_a), ("tau_a", tau_a)],
            &[n],
            |c, t, x, o| {
                closed_direct_dynamics_into(
                    c,
                    &mut t.data,
                    &mut t.branch,
                    c.robot().environment(),
                    x[0],
                    x[1],
                    x[2],
                    o,
                )
            },
        )
    }

    /// Regressor of the closed chain, G^T Φ over all 13 NL standard parameters (K order):
    /// (n, 13 NL) for one state, stacked (N n, 13 NL) for N states.
    #[pyo3(signature = (q_a, qd_a=None, qdd_a=None))]
    fn regressor<'py>(
        &self,
        py: Python<'py>,
        q_a: &Bound<'py, PyAny>,
        qd_a: Option<&Bound<'py, PyAny>>,
        qdd_a: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.chain.dof();
        let nk = PARAMS_PER_LINK * self.chain.robot().nl();
        let cols: Vec<usize> = (0..nk).collect();
        let a = self.eval(
            py,
            &[("q_a", Some(q_a)), ("qd_a", qd_a), ("qdd_a", qdd_a)],
            &[n, nk],
            |c, t, x, o| {
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
                copy_rows(&t.phi, &cols, o);
                Ok(cond)
            },
        )?;
        a.call_method1("reshape", ((-1i64, nk),))
    }

    /// Simulate in the actuated coordinates from (q0, qd0) (default: the tracker's q_a, 0);
    /// the passive joints are re-solved at every evaluation. Returns a dict of arrays (t, q,
    /// qd, qdd, tau, energy, closure_residual, the passive joints' q<j>).
    #[pyo3(signature = (duration, q0=None, qd0=None, torque=None, dt=None, rtol=1e-8, atol=1e-10, output_dt=0.01, coulomb_smoothing=None, max_steps=None))]
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
        max_steps: Option<usize>,
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
