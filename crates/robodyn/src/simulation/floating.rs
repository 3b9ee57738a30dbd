//! The floating base in the simulation: its pose integrated on the group, not as q + v dt.
//!
//! The integrators work on vectors, so the base pose is carried in local coordinates of a chart
//! anchored at a pose (p_a, R_a): x = (delta, phi) with p = p_a + delta (world) and
//! R = R_a exp(phi^) (phi a rotation vector in the base frame). In the chart the base's
//! kinematics are exact ODEs: delta' = R v (v the base-frame linear velocity) and
//! phi' = J_r(phi)^-1 w (J_r the right Jacobian of SO(3), w the base-frame angular velocity).
//! After an accepted step whose rotation vector exceeds [`REANCHOR_ANGLE`] the chart moves to
//! the current pose (phi = 0 again): the quaternion of every output row is exp of a rotation
//! vector, unit to rounding, and never renormalized after the fact.
//!
//! Energy and momenta: T = 1/2 v' A v, U = -M g' c with the mass, the centre of mass and the
//! momenta of [`centroidal_momentum`] (the base rows of A).

use crate::algorithms::centroidal::centroidal_momentum;
use crate::algorithms::inertia_matrix::inertia_matrix_into;
use crate::data::Data;
use crate::error::Result;
use crate::model::Robot;
use nalgebra::{DMatrix, Matrix3, UnitQuaternion, Vector3};

/// Largest rotation (rad) of the chart's coordinates before the chart moves to the current
/// pose (J_r^-1 is singular at 2 pi; well conditioned below 1 rad).
pub const REANCHOR_ANGLE: f64 = 1.0;

/// Names of the floating base's columns: position and quaternion, twist, its derivative,
/// wrench (base frame).
pub const BASE_COLUMNS: [[&str; 7]; 4] = [
    [
        "base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz", "base_qw",
    ],
    [
        "base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz", "",
    ],
    [
        "base_ax", "base_ay", "base_az", "base_dwx", "base_dwy", "base_dwz", "",
    ],
    [
        "base_fx", "base_fy", "base_fz", "base_mx", "base_my", "base_mz", "",
    ],
];

/// Extra columns of a floating robot: the centre of mass (world), the linear momentum (world)
/// and the angular momentum about the centre of mass (world axes).
pub const MOMENTUM_COLUMNS: [&str; 9] = [
    "com_x",
    "com_y",
    "com_z",
    "momentum_x",
    "momentum_y",
    "momentum_z",
    "angular_momentum_x",
    "angular_momentum_y",
    "angular_momentum_z",
];

/// The chart of the base pose.
#[derive(Clone, Debug)]
pub(crate) struct BaseChart {
    p: Vector3<f64>,
    r: UnitQuaternion<f64>,
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    v.cross_matrix()
}

/// J_r(phi)^-1 w: the rate of the rotation vector for the body angular velocity w.
fn inverse_right_jacobian(phi: &Vector3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
    let th = phi.norm();
    let k = skew(phi);
    // 1/th^2 - (1 + cos th) / (2 th sin th), its series below 1e-4 rad
    let c = if th < 1e-4 {
        1.0 / 12.0 + th * th / 720.0
    } else {
        1.0 / (th * th) - (1.0 + th.cos()) / (2.0 * th * th.sin())
    };
    w + 0.5 * (k * w) + c * (k * (k * w))
}

impl BaseChart {
    /// The chart anchored at the pose of q (nq: position, quaternion x y z w, joints): the
    /// chart coordinates x (nv: delta = 0, phi = 0, joints).
    pub(crate) fn anchored(q: &[f64], x: &mut [f64]) -> Result<BaseChart> {
        let rot = crate::algorithms::floating_base::base_rotation(q)?;
        x[..6].fill(0.0);
        x[6..].copy_from_slice(&q[7..]);
        Ok(BaseChart {
            p: Vector3::new(q[0], q[1], q[2]),
            r: rot,
        })
    }

    fn rotation(&self, phi: &Vector3<f64>) -> UnitQuaternion<f64> {
        self.r * UnitQuaternion::from_scaled_axis(*phi)
    }

    /// q (nq) of the chart coordinates x (nv).
    pub(crate) fn configuration(&self, x: &[f64], q: &mut [f64]) {
        let rot = self.rotation(&Vector3::new(x[3], x[4], x[5]));
        let p = self.p + Vector3::new(x[0], x[1], x[2]);
        q[..3].copy_from_slice(p.as_slice());
        let c = rot.quaternion().coords; // (i, j, k, w)
        q[3..7].copy_from_slice(c.as_slice());
        q[7..].copy_from_slice(&x[6..]);
    }

    /// dx/dt (nv) for the velocity v (nv) at chart coordinates x.
    pub(crate) fn rate(&self, x: &[f64], v: &[f64], dx: &mut [f64]) {
        let phi = Vector3::new(x[3], x[4], x[5]);
        let lin = self.rotation(&phi) * Vector3::new(v[0], v[1], v[2]);
        let dphi = inverse_right_jacobian(&phi, &Vector3::new(v[3], v[4], v[5]));
        dx[..3].copy_from_slice(lin.as_slice());
        dx[3..6].copy_from_slice(dphi.as_slice());
        dx[6..].copy_from_slice(&v[6..]);
    }

    /// Move the anchor to the pose of x when its rotation exceeds [`REANCHOR_ANGLE`]; true when
    /// x was rewritten.
    pub(crate) fn reanchor(&mut self, x: &mut [f64]) -> bool {
        let phi = Vector3::new(x[3], x[4], x[5]);
        if phi.norm() <= REANCHOR_ANGLE {
            return false;
        }
        self.p += Vector3::new(x[0], x[1], x[2]);
        self.r = self.rotation(&phi);
        x[..6].fill(0.0);
        true
    }
}

/// Energy and momenta of a floating robot at (q, v): T + U, and the centre of mass, the linear
/// momentum and the angular momentum about the centre of mass (world).
pub(crate) struct FloatingBalance {
    a: DMatrix<f64>,
    /// The last state evaluated (q then v) and its results: an output row asks for the energy
    /// and for the momenta at the same state, so the second request is a copy.
    state: Vec<f64>,
    energy: f64,
    momenta: Option<[f64; 9]>,
}

impl FloatingBalance {
    pub(crate) fn new(robot: &Robot) -> Self {
        FloatingBalance {
            a: DMatrix::zeros(robot.nv(), robot.nv()),
            state: Vec::with_capacity(robot.nq() + robot.nv()),
            energy: 0.0,
            momenta: None,
        }
    }

    /// T + U and the 9 momentum columns ([`MOMENTUM_COLUMNS`]) at (q, v): T = 1/2 v' A v,
    /// U = -M g' c, the momenta from [`centroidal_momentum`].
    pub(crate) fn evaluate(
        &mut self,
        robot: &Robot,
        data: &mut Data,
        q: &[f64],
        v: &[f64],
        out: &mut [f64; 9],
    ) -> Result<f64> {
        let same = self.state.len() == q.len() + v.len()
            && self.state[..q.len()] == *q
            && self.state[q.len()..] == *v;
        if let (true, Some(m)) = (same, self.momenta) {
            *out = m;
            return Ok(self.energy);
        }
        self.momenta = None;
        let m = centroidal_momentum(robot, data, q, v)?;
        inertia_matrix_into(robot, data, q, &mut self.a)?;
        let nv = v.len();
        let kinetic = 0.5
            * (0..nv)
                .map(|r| v[r] * (0..nv).map(|k| self.a[(r, k)] * v[k]).sum::<f64>())
                .sum::<f64>();
        let potential = -m.mass * robot.environment().gravity.dot(&m.com);
        for (k, x) in m.com.iter().chain(&m.linear).chain(&m.angular).enumerate() {
            out[k] = *x;
        }
        self.state.clear();
        self.state.extend_from_slice(q);
        self.state.extend_from_slice(v);
        self.energy = kinetic + potential;
        self.momenta = Some(*out);
        Ok(self.energy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Quaternion;

    /// The chart's rate equals the derivative of the configuration along the motion: finite
    /// differences of exp through the chart, against R v and the body angular velocity.
    #[test]
    fn chart_rate_is_the_derivative_of_the_pose() {
        let q = [0.1, -0.2, 0.3, 0.2, -0.1, 0.3, (1.0f64 - 0.14).sqrt(), 0.5];
        let mut x = [0.0; 7];
        let chart = BaseChart::anchored(&q, &mut x).unwrap();
        // a point of the chart far from the origin
        let x0 = [0.3, 0.1, -0.2, 0.4, -0.7, 0.5, 0.5];
        let v = [0.3, -0.5, 0.7, 1.1, -0.4, 0.9, 0.2];
        let mut dx = [0.0; 7];
        chart.rate(&x0, &v, &mut dx);
        let h = 1e-6;
        let at = |s: f64| {
            let xs: Vec<f64> = x0.iter().zip(&dx).map(|(a, b)| a + s * b).collect();
            let mut qs = [0.0; 8];
            chart.configuration(&xs, &mut qs);
            qs
        };
        let (qm, qp, q0) = (at(-h), at(h), at(0.0));
        let rot =
            |q: &[f64; 8]| UnitQuaternion::from_quaternion(Quaternion::new(q[6], q[3], q[4], q[5]));
        // body angular velocity: log(R0^T R(h)) / h, linear: (p(h) - p(-h)) / 2h = R v
        let w = (rot(&q0).inverse() * rot(&qp)).scaled_axis()
            - (rot(&q0).inverse() * rot(&qm)).scaled_axis();
        let w = w / (2.0 * h);
        let pdot = Vector3::new(qp[0] - qm[0], qp[1] - qm[1], qp[2] - qm[2]) / (2.0 * h);
        let expected = rot(&q0) * Vector3::new(v[0], v[1], v[2]);
        assert!((pdot - expected).norm() < 1e-8, "{pdot} vs {expected}");
        assert!((w - Vector3::new(v[3], v[4], v[5])).norm() < 1e-8, "{w}");
        // the quaternion stays unit
        assert!((Quaternion::new(q0[6], q0[3], q0[4], q0[5]).norm() - 1.0).abs() < 1e-15);
    }
}
