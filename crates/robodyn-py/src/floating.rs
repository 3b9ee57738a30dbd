//! The functions of `robodyn.Robot` proper to floating robots (docs/models/floating_base.md):
//! `integrate` on the configuration space (SE(3) for the base), the centroidal momentum and
//! the centroidal momentum matrix, each on one state or N states.

use crate::kinematics::write_matrix;
use crate::robot::{Call, Robot};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use robodyn::{centroidal_map_into, centroidal_momentum, integrate_into};

/// The (..., 10) rows [mass, com (3), linear (3), angular (3)] of a centroidal call as a dict
/// of C-contiguous arrays.
fn centroidal_dict<'py>(py: Python<'py>, r: Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
    let np = py.import("numpy")?;
    let slice = pyo3::types::PySlice::new;
    let d = PyDict::new(py);
    let ellipsis = py.Ellipsis().into_bound(py);
    let part = |lo: isize, hi: isize| -> PyResult<Bound<'py, PyAny>> {
        let idx =
            pyo3::types::PyTuple::new(py, [ellipsis.clone(), slice(py, lo, hi, 1).into_any()])?;
        np.getattr("ascontiguousarray")?.call1((r.get_item(idx)?,))
    };
    let mass = if r.getattr("ndim")?.extract::<usize>()? == 1 {
        r.get_item(0)?
            .extract::<f64>()?
            .into_pyobject(py)?
            .into_any()
    } else {
        part(0, 1)?.call_method1("reshape", (-1,))?
    };
    d.set_item("mass", mass)?;
    d.set_item("com", part(1, 4)?)?;
    d.set_item("linear", part(4, 7)?)?;
    d.set_item("angular", part(7, 10)?)?;
    Ok(d)
}

#[pymethods]
impl Robot {
    /// The configuration reached from q (nq,) moving at the constant velocity v (nv,) for dt
    /// seconds (Pinocchio's integrate(model, q, v dt)): a floating base moves on SE(3), its
    /// placement M exp(v dt) with the twist in the base frame, so the quaternion stays a unit
    /// quaternion; the joints move by v dt (on a fixed base, q + v dt). Shapes (nq,) and
    /// (nv,), or (N, nq) and (N, nv) for N states; the result has q's shape. out: as for idm.
    #[pyo3(signature = (q, v, dt, *, out=None))]
    fn integrate<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        dt: f64,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let models = self.models();
        let nq = models.full.nq();
        let call = Call {
            inputs: &[("q", Some(q)), ("v", Some(v))],
            one: &[nq],
            stacked: false,
            out,
        };
        self.eval_state(py, &models, &models.full, call, move |r, _w, x, o| {
            integrate_into(r, x[0], x[1], dt, o)
        })
    }

    /// Mass, centre of mass and centroidal momentum of a floating robot at q (nq,) and v (nv,):
    /// a dict with "mass" (kg), "com" (3,) (m, world), "linear" (3,) (kg m/s) and "angular"
    /// (3,) (kg m²/s, about the centre of mass), in world components (Pinocchio's
    /// computeCentroidalMomentum: data.com[0], data.hg.linear, data.hg.angular). N states (N,
    /// nq), (N, nv) give arrays with a leading N. InputError on a robot that does not float.
    #[pyo3(signature = (q, v=None))]
    fn centroidal_momentum<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        v: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let models = self.models();
        let call = Call {
            inputs: &[("q", Some(q)), ("v", v)],
            one: &[10],
            stacked: false,
            out: None,
        };
        let r = self.eval_state(py, &models, &models.full, call, |r, w, x, o| {
            let c = centroidal_momentum(r, &mut w.data, x[0], x[1])?;
            o[0] = c.mass;
            o[1..4].copy_from_slice(c.com.as_slice());
            o[4..7].copy_from_slice(c.linear.as_slice());
            o[7..10].copy_from_slice(c.angular.as_slice());
            Ok(())
        })?;
        centroidal_dict(py, r)
    }

    /// The centroidal momentum matrix A_G(q) of a floating robot (Orin's CMM; Pinocchio's
    /// computeCentroidalMap / ccrba's data.Ag): h_G = A_G v, rows [linear momentum; angular
    /// momentum about the centre of mass] in world components, columns over v (base linear,
    /// angular velocity in the base frame, joints). Shape (6, nv) for q of shape (nq,),
    /// (N, 6, nv) for (N, nq). InputError on a robot that does not float. out: as for idm.
    #[pyo3(signature = (q, *, out=None))]
    fn centroidal_map<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        out: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let models = self.models();
        let nv = models.full.nv();
        let call = Call {
            inputs: &[("q", Some(q))],
            one: &[6, nv],
            stacked: false,
            out,
        };
        self.eval_state(py, &models, &models.full, call, move |r, w, x, o| {
            let (data, ag) = w.split(6, nv);
            centroidal_map_into(r, data, x[0], ag)?;
            write_matrix(ag, o);
            Ok(())
        })
    }
}
