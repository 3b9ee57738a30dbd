//! The kinematics of `robodyn.Robot` (frames by name): placements, frame Jacobians in the three
//! references, frame velocities and classical accelerations, the centre of mass and its
//! Jacobian, each on one state or N states; and the closed-form inverse geometric model.

use crate::arrays::values;
use crate::errors::{DimensionError, IntoPy};
use crate::robot::{quoted, Call, Robot, Work};
use nalgebra::{DMatrix, Matrix4};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::algorithms::inverse_geometry::{
    numeric_igm_batch, ClosedFormIgm, NumericIgm, NumericOptions, NumericSolution,
};
use robodyn::algorithms::kinematics::{
    center_of_mass, center_of_mass_jacobian_into, forward_kinematics_into,
    frame_classical_acceleration, frame_jacobian_into, frame_jacobian_time_variation_into,
    frame_placement, frame_velocity, placements_into, total_mass, Motion, Reference,
};
use robodyn::error::check_finite_result;

/// The library's reference of its name; ValueError listing the names otherwise.
pub fn parse_reference(reference: &str) -> PyResult<Reference> {
    Reference::from_name(reference).ok_or_else(|| {
        PyValueError::new_err(format!(
            "reference = {reference:?}: expected {}",
            quoted(Reference::ALL.map(Reference::name).as_slice())
        ))
    })
}

/// Row-major copy of a matrix into `out`.
pub fn write_matrix(m: &DMatrix<f64>, out: &mut [f64]) {
    let c = m.ncols();
    for r in 0..m.nrows() {
        for k in 0..c {
            out[r * c + k] = m[(r, k)];
        }
    }
}

fn write_motion(m: &Motion, out: &mut [f64]) {
    out.copy_from_slice(m.to_vector().as_slice());
}

/// A 4x4 matrix of `obj` (any layout), DimensionError otherwise.
fn matrix4(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<Matrix4<f64>> {
    let (v, shape) = values(obj)?;
    if shape != [4, 4] {
        return Err(DimensionError::new_err(format!(
            "{what} has shape {shape:?}, expected (4, 4) (a homogeneous placement)"
        )));
    }
    Ok(Matrix4::from_row_slice(&v))
}

impl Robot {
    /// `ik(frame, target, q0)`: the numeric inverse geometric model from q0, one target (4, 4)
    /// with q0 (nq,), or N targets (N, 4, 4) with q0 (N, nq) over the cores.
    fn numeric_ik<'py>(
        &self,
        py: Python<'py>,
        frame: &str,
        target: &Bound<'py, PyAny>,
        q0: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let robot = self.model();
        let f = robot.frame_id(frame).py()?;
        let igm = NumericIgm::new(&robot, f, NumericOptions::default()).py()?;
        let n = robot.dof();
        let (t, t_shape) = values(target)?;
        let (start, s_shape) = values(q0)?;
        let rows = match (t_shape.as_slice(), s_shape.as_slice()) {
            ([4, 4], [k]) if *k == n => None,
            ([m, 4, 4], [r, k]) if *k == n && m == r => Some(*m),
            _ => {
                return Err(DimensionError::new_err(format!(
                    "target has shape {t_shape:?} and q0 {s_shape:?}: expected (4, 4) with \
                     ({n},), or (N, 4, 4) with (N, {n}) ({n} movable joints)"
                )))
            }
        };
        let targets: Vec<Matrix4<f64>> = t.chunks(16).map(Matrix4::from_row_slice).collect();
        let sols = py
            .detach(|| numeric_igm_batch(&robot, &igm, &targets, &start))
            .py()?;
        let d = PyDict::new(py);
        let q: Vec<f64> = sols.iter().flat_map(|s| s.q.iter().copied()).collect();
        let col = |g: &dyn Fn(&NumericSolution) -> f64| sols.iter().map(g).collect::<Vec<f64>>();
        let converged: Vec<bool> = sols.iter().map(|s| s.converged).collect();
        let counts = |g: &dyn Fn(&NumericSolution) -> usize| sols.iter().map(g).collect::<Vec<_>>();
        match rows {
            None => {
                let s = &sols[0];
                d.set_item("q", PyArray1::from_vec(py, q))?;
                d.set_item("converged", s.converged)?;
                d.set_item("position_error", s.position_error)?;
                d.set_item("rotation_error", s.rotation_error)?;
                d.set_item("iterations", s.iterations)?;
                d.set_item("starts", s.starts)?;
            }
            Some(m) => {
                d.set_item("q", PyArray1::from_vec(py, q).reshape([m, n])?)?;
                d.set_item("converged", PyArray1::from_vec(py, converged))?;
                d.set_item(
                    "position_error",
                    PyArray1::from_vec(py, col(&|s| s.position_error)),
                )?;
                d.set_item(
                    "rotation_error",
                    PyArray1::from_vec(py, col(&|s| s.rotation_error)),
                )?;
                d.set_item(
                    "iterations",
                    PyArray1::from_vec(py, counts(&|s| s.iterations)),
                )?;
                d.set_item("starts", PyArray1::from_vec(py, counts(&|s| s.starts)))?;
            }
        }
        Ok(d)
    }

    /// `f` on the model over one state or N states of `inputs` (up to three: q with nq
    /// entries, qd and qdd with nv, the base first on a floating robot), `one` the result's
    /// shape for one state: the call every kinematic function makes.
    #[allow(clippy::too_many_arguments)]
    fn kinematics<'py, F>(
        &self,
        py: Python<'py>,
        inputs: &[(&str, Option<&Bound<'py, PyAny>>)],
        one: &[usize],
        out: Option<&Bound<'py, PyAny>>,
        f: F,
    ) -> PyResult<Bound<'py, PyAny>>
    where
        F: Fn(&robodyn::Robot, &mut Work, [&[f64]; 3], &mut [f64]) -> robodyn::Result<()>
            + Sync
            + Send,
    {
        let models = self.models();
        let call = Call {
            inputs,
            one,
            stacked: false,
            out,
        };
        self.eval_state(py, &models, &models.full, call, f)
    }
}

#[pymethods]
impl Robot {
    /// Total mass (kg) of the links a joint moves (what `com` weighs; Pinocchio's
    /// computeTotalMass on a fixed-base URDF).
    #[getter]
    fn mass(&self) -> f64 {
        total_mass(&self.model())
    }

    /// Placement 0T_f of the frame named `frame` (a name of `frame_names`: URDF link or joint,
    /// tool, link, or a frame number "0".."NF"): a 4 x 4 homogeneous matrix (metres) for q
    /// (rad, m) of shape (nq,), (N, 4, 4) for (N, nq) (Pinocchio's data.oMf after
    /// updateFramePlacements). Raises InputError for an unknown frame (with the near names).
    /// out: as for idm.
    #[pyo3(signature = (q, frame, *, out=None))]
    fn placement<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let f = self.model().frame_id(frame).py()?;
        self.kinematics(py, &[("q", Some(q))], &[4, 4], out, move |r, w, x, o| {
            placements_into(r, &mut w.kin, x[0])?;
            let m = frame_placement(r, &w.kin, &f)?.matrix();
            for a in 0..4 {
                for b in 0..4 {
                    o[4 * a + b] = m[(a, b)];
                }
            }
            check_finite_result("placement", o)
        })
    }

    /// Jacobian of the frame named `frame` (as `placement`) in `reference`: "world" (spatial
    /// velocity in the base frame), "local" (at the frame's origin, in its axes) or
    /// "local_world_aligned" (at its origin, in the base axes: Khalil's 0J_n), Pinocchio's
    /// WORLD, LOCAL, LOCAL_WORLD_ALIGNED. Rows [linear; angular] (m/s, rad/s per unit of qd):
    /// shape (6, nq) for q of shape (nq,), (N, 6, nq) for (N, nq). An unknown reference raises
    /// ValueError. out: as for idm.
    #[pyo3(signature = (q, frame, reference="world", *, out=None))]
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rf = parse_reference(reference)?;
        let f = self.model().frame_id(frame).py()?;
        let n = self.model().nv();
        self.kinematics(py, &[("q", Some(q))], &[6, n], out, move |r, w, x, o| {
            let (kin, j) = w.kin_split(6, n);
            placements_into(r, kin, x[0])?;
            frame_jacobian_into(r, kin, &f, rf, j)?;
            write_matrix(j, o);
            check_finite_result("J", o)
        })
    }

    /// Time variation J̇ = dJ/dt of the Jacobian of the frame named `frame` in `reference` (as
    /// `jacobian`) at q and qd (Pinocchio's getFrameJacobianTimeVariation): J̇ qd + J qdd is
    /// the frame's acceleration in that reference. Shape (6, nq) for one state, (N, 6, nq) for
    /// (N, nq). out: as for idm.
    #[pyo3(signature = (q, qd, frame, reference="world", *, out=None))]
    fn jacobian_time_variation<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rf = parse_reference(reference)?;
        let f = self.model().frame_id(frame).py()?;
        let n = self.model().nv();
        let inputs = [("q", Some(q)), ("qd", Some(qd)), ("qdd", None)];
        self.kinematics(py, &inputs, &[6, n], out, move |r, w, x, o| {
            let (kin, dj) = w.kin_split(6, n);
            forward_kinematics_into(r, kin, x[0], x[1], x[2])?;
            frame_jacobian_time_variation_into(r, kin, &f, rf, dj)?;
            write_matrix(dj, o);
            check_finite_result("dJ", o)
        })
    }

    /// Velocity of the frame named `frame` in `reference` (as `jacobian`): [linear; angular]
    /// (m/s, rad/s) for q (rad, m) and qd (rad/s, m/s), J(q) qd (Pinocchio's
    /// getFrameVelocity). Shape (6,) for one state, (N, 6) for N states (N, nq). out: as for
    /// idm.
    #[pyo3(signature = (q, qd, frame, reference="world", *, out=None))]
    fn frame_velocity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rf = parse_reference(reference)?;
        let f = self.model().frame_id(frame).py()?;
        self.kinematics(
            py,
            &[("q", Some(q)), ("qd", Some(qd)), ("qdd", None)],
            &[6],
            out,
            move |r, w, x, o| {
                forward_kinematics_into(r, &mut w.kin, x[0], x[1], x[2])?;
                write_motion(&frame_velocity(r, &w.kin, &f, rf)?, o);
                check_finite_result("frame velocity", o)
            },
        )
    }

    /// Classical acceleration of the frame named `frame` in `reference` (as `jacobian`):
    /// [linear; angular] (m/s², rad/s²) for q, qd, qdd (Pinocchio's
    /// getFrameClassicalAcceleration; in "local_world_aligned" the acceleration of the frame's
    /// origin and the angular acceleration in the base axes). Shape (6,) for one state, (N, 6)
    /// for N states (N, nq). out: as for idm.
    #[pyo3(signature = (q, qd, qdd, frame, reference="world", *, out=None))]
    #[allow(clippy::too_many_arguments)]
    fn frame_acceleration<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        qd: &Bound<'py, PyAny>,
        qdd: &Bound<'py, PyAny>,
        frame: &str,
        reference: &str,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let rf = parse_reference(reference)?;
        let f = self.model().frame_id(frame).py()?;
        self.kinematics(
            py,
            &[("q", Some(q)), ("qd", Some(qd)), ("qdd", Some(qdd))],
            &[6],
            out,
            move |r, w, x, o| {
                forward_kinematics_into(r, &mut w.kin, x[0], x[1], x[2])?;
                write_motion(&frame_classical_acceleration(r, &w.kin, &f, rf)?, o);
                check_finite_result("frame acceleration", o)
            },
        )
    }

    /// Centre of mass 0P_G (m, in the base frame) of the links a joint moves, for q (rad, m):
    /// shape (3,) for q of shape (nq,), (N, 3) for (N, nq) (Pinocchio's centerOfMass). out: as
    /// for idm.
    #[pyo3(signature = (q, *, out=None))]
    fn com<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        self.kinematics(
            py,
            &[("q", Some(q)), ("qd", None), ("qdd", None)],
            &[3],
            out,
            |r, w, x, o| {
                forward_kinematics_into(r, &mut w.kin, x[0], x[1], x[2])?;
                let g = center_of_mass(r, &mut w.kin, None)?;
                o.copy_from_slice(g.position.as_slice());
                check_finite_result("com", o)
            },
        )
    }

    /// Jacobian of the centre of mass (m per unit of qd): its velocity is com_jacobian(q) qd;
    /// shape (3, nq) for q of shape (nq,), (N, 3, nq) for (N, nq) (Pinocchio's
    /// jacobianCenterOfMass). out: as for idm.
    #[pyo3(signature = (q, *, out=None))]
    fn com_jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let n = self.model().nv();
        self.kinematics(py, &[("q", Some(q))], &[3, n], out, move |r, w, x, o| {
            let (kin, j) = w.kin_split(3, n);
            placements_into(r, kin, x[0])?;
            center_of_mass_jacobian_into(r, kin, None, j)?;
            write_matrix(j, o);
            check_finite_result("Jcom", o)
        })
    }

    /// Inverse geometric model of the frame named `frame` (as `placement`) for `target` (4 x 4
    /// homogeneous placement in the base frame, m).
    ///
    /// Without `q0`: the closed form (Paul's method; 6R chains with a spherical wrist or axes
    /// 2, 3, 4 parallel), every solution. Returns a dict: "q" (S, nq), one row per solution
    /// (S <= 8, 0 when out of reach; joints off the chain to the frame are 0),
    /// "within_limits" (S,) bool (every joint within the description's limits), "singular"
    /// (S,) bool (any singular case), "shoulder", "elbow", "wrist" (S,) bool (which case),
    /// "joints" (the 6 indices of the chain's joints in q) and "class". Raises InputError when
    /// the chain has no closed form.
    ///
    /// With `q0` (nq,): the numeric model (Levenberg-Marquardt on the placement error, joint
    /// limits kept, from q0 then seeded random starts), any robot. Returns a dict: "q" (nq,),
    /// "converged" bool, "position_error" (m), "rotation_error" (rad), "iterations",
    /// "starts". Batched: `target` (N, 4, 4) with `q0` (N, nq) gives arrays with a leading N
    /// (the targets over the cores).
    ///
    /// NotFiniteError / InputError for a target that is not a placement.
    #[pyo3(signature = (frame, target, q0=None))]
    fn ik<'py>(
        &self,
        py: Python<'py>,
        frame: &str,
        target: &Bound<'py, PyAny>,
        q0: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let robot = self.model();
        if robot.is_floating() {
            return Err(crate::errors::InputError::new_err(format!(
                "Robot.ik: robot `{}` has a floating base, whose pose no joint sets: a frame's \
                 world pose is reached by moving the base alone, so the inverse geometric \
                 model (which solves the joints) is not defined for it; for a target given in \
                 the base frame, load the robot without floating=True",
                robot.name()
            )));
        }
        if let Some(q0) = q0 {
            return self.numeric_ik(py, frame, target, q0);
        }
        let robot = self.model();
        let t = matrix4("target", target)?;
        let f = robot.frame_id(frame).py()?;
        let mut igm = ClosedFormIgm::for_frame(&robot, f.parent()).py()?;
        if *f.offset() != robodyn::geometry::Transform::identity() {
            igm = igm.with_tool(&f.offset().matrix()).py()?;
        }
        let sols = igm.solve(&t).py()?;
        let (n, s) = (robot.dof(), sols.len());
        let joints = igm.joints();
        let mut q = vec![0.0; s * n];
        for (k, sol) in sols.as_slice().iter().enumerate() {
            for (i, &j) in joints.iter().enumerate() {
                q[k * n + j] = sol.q[i];
            }
        }
        let flags = |g: &dyn Fn(&robodyn::algorithms::inverse_geometry::IgmSolution) -> bool| {
            PyArray1::from_vec(py, sols.as_slice().iter().map(g).collect::<Vec<bool>>())
        };
        let d = PyDict::new(py);
        d.set_item("q", PyArray1::from_vec(py, q).reshape([s, n])?)?;
        d.set_item("within_limits", flags(&|x| x.within_limits))?;
        d.set_item("singular", flags(&|x| x.singular.any()))?;
        d.set_item("shoulder", flags(&|x| x.singular.shoulder))?;
        d.set_item("elbow", flags(&|x| x.singular.elbow))?;
        d.set_item("wrist", flags(&|x| x.singular.wrist))?;
        d.set_item("joints", joints.to_vec())?;
        d.set_item("class", igm.class().name())?;
        Ok(d)
    }
}
