//! The motors of a robot's motor–joint transmission ([`crate::model::Transmission`]), over its
//! joint vectors: the one place where the motor-side rotor inertia and friction are reflected to
//! the joint side. With motor positions m = R q over the transmission's joints, motor k's rotor
//! inertia Ia_k, viscous friction Fv_k and Coulomb friction Fs_k (IA, FV, FS of the link of
//! `joints[k]`, in motor units) add to the joint torques
//!
//! `tau_drive = R' (Ia m_dd + Fv m_d + Fs sign(m_d))`, with m_d = R qd, m_dd = R qdd,
//!
//! and `1/2 m_d' Ia m_d` to the kinetic energy (the reflected inertia R' Ia R in A(q)). The
//! torques of the models are joint-side (tau = R' tau_motor, the power balance the
//! identification uses for measured torques).
//!
//! [`crate::Robot::new`] builds the drives from the description and zeroes IA, FS, FV of the
//! transmission's links in the numeric models, so that the recursions (Newton–Euler, composite
//! links) carry the links alone and the checked functions (`inverse_dynamics_into`,
//! `h_vector_into`, `inertia_matrix_into`, `direct_dynamics_into`, the energies and the
//! simulation) add the drives through this module.

use crate::error::{Error, Item, Result};
use crate::model::{param, RobotDescription, PARAMS_PER_LINK};
use crate::scalar::DynScalar;
use nalgebra::DMatrix;

/// The motors of a transmission: R, their drive parameters and where their joints sit in the
/// joint vectors.
#[derive(Clone, Debug)]
pub struct MotorDrives {
    /// Entry of each of R's columns in a joint vector (the movable-joint coordinates).
    cols: Vec<usize>,
    /// R (motors x joints).
    r: DMatrix<f64>,
    /// Rotor inertia of each motor (kg m², motor side).
    ia: Vec<f64>,
    /// Coulomb friction of each motor (N m, motor side).
    fs: Vec<f64>,
    /// Viscous friction of each motor (N m s/rad, motor side).
    fv: Vec<f64>,
    /// max_c |R_kc| of each motor: its velocity scale relative to its joints (for the smoothed
    /// Coulomb friction of the simulation).
    ratio: Vec<f64>,
    /// R' diag(Ia) R (joints x joints).
    inertia: DMatrix<f64>,
}

/// Relative size of R's smallest singular value under which R counts as singular.
const SINGULAR_TOL: f64 = 1e-12;

impl MotorDrives {
    /// The drives of `desc`'s transmission, with the standard parameters `k` (13 per link) and
    /// the movable joints `movable` (frame numbers, the joint vectors' entries). `None` without
    /// a transmission. Errors: a joint that is not an actuated movable tree joint or appears
    /// twice, a matrix that is not square over the joints, not finite or singular.
    pub(crate) fn new(
        desc: &RobotDescription,
        k: &[f64],
        movable: &[usize],
    ) -> Result<Option<MotorDrives>> {
        let Some(t) = &desc.transmission else {
            return Ok(None);
        };
        let item = || Item::Base("transmission".into());
        let invalid = |reason: String| Err(Error::invalid(item(), reason));
        let n = t.joints.len();
        let mut cols = Vec::with_capacity(n);
        for (c, &j) in t.joints.iter().enumerate() {
            let pos = movable.iter().position(|&m| m == j);
            match pos {
                Some(p) if j <= desc.nl && desc.frame(j).actuated => cols.push(p),
                _ => {
                    return invalid(format!(
                        "joint {j} is not an actuated movable joint of the tree (1..{})",
                        desc.nl
                    ))
                }
            }
            if t.joints[..c].contains(&j) {
                return invalid(format!("joint {j} is listed twice"));
            }
        }
        if t.matrix.len() != n || t.matrix.iter().any(|row| row.len() != n) {
            return invalid(format!(
                "the matrix must be {n} x {n} (one row per motor, one column per joint of \
                 {:?})",
                t.joints
            ));
        }
        if let Some(x) = t.matrix.iter().flatten().find(|x| !x.is_finite()) {
            return invalid(format!("the matrix has a non-finite entry ({x})"));
        }
        let r = DMatrix::from_fn(n, n, |i, j| t.matrix[i][j]);
        let sv = r.clone().svd(false, false).singular_values;
        let (hi, lo) = (sv.max(), sv.min());
        let regular = lo > SINGULAR_TOL * hi; // false for NaN
        if n > 0 && !regular {
            return invalid(format!(
                "the matrix R is singular (singular values {hi:e} .. {lo:e}): the motor \
                 positions m = R q must determine the joint positions"
            ));
        }
        let drive = |j: usize, p: usize| k[PARAMS_PER_LINK * (j - 1) + p];
        let ia: Vec<f64> = t.joints.iter().map(|&j| drive(j, param::IA)).collect();
        let fs = t.joints.iter().map(|&j| drive(j, param::FS)).collect();
        let fv = t.joints.iter().map(|&j| drive(j, param::FV)).collect();
        let ratio = (0..n).map(|m| r.row(m).amax()).collect();
        let inertia = r.transpose() * DMatrix::from_diagonal(&ia.clone().into()) * &r;
        Ok(Some(MotorDrives {
            cols,
            r,
            ia,
            fs,
            fv,
            ratio,
            inertia,
        }))
    }

    /// The transmission's links (frame numbers) in R's column order are those of the
    /// description; this is the entry of column c in a joint vector.
    pub fn coordinate(&self, c: usize) -> usize {
        self.cols[c]
    }

    /// Number of motors.
    pub fn len(&self) -> usize {
        self.cols.len()
    }

    /// True when the transmission has no joint.
    pub fn is_empty(&self) -> bool {
        self.cols.is_empty()
    }

    /// True when every motor's IA, FS and FV is zero (the transmission changes no torque).
    pub fn is_inert(&self) -> bool {
        self.ia
            .iter()
            .chain(&self.fs)
            .chain(&self.fv)
            .all(|&x| x == 0.0)
    }

    /// R (motors x joints).
    pub fn matrix(&self) -> &DMatrix<f64> {
        &self.r
    }

    /// The reflected rotor inertia R' diag(Ia) R (joints x joints, R's column order).
    pub fn reflected_inertia(&self) -> &DMatrix<f64> {
        &self.inertia
    }

    /// Motor k's velocity (R x)_k for a joint vector x.
    #[inline]
    fn motor(&self, k: usize, x: &[f64]) -> f64 {
        self.cols
            .iter()
            .enumerate()
            .map(|(c, &i)| self.r[(k, c)] * x[i])
            .sum()
    }

    /// Add R' f to the joint vector `tau` for motor-side torques f_k = `f(k, m_d_k, m_dd_k)`.
    #[inline]
    fn add_reflected(
        &self,
        qd: &[f64],
        qdd: Option<&[f64]>,
        tau: &mut [f64],
        f: impl Fn(usize, f64, f64) -> f64,
    ) {
        for k in 0..self.cols.len() {
            let md = self.motor(k, qd);
            let mdd = qdd.map_or(0.0, |a| self.motor(k, a));
            let fk = f(k, md, mdd);
            if fk != 0.0 {
                for (c, &i) in self.cols.iter().enumerate() {
                    tau[i] += self.r[(k, c)] * fk;
                }
            }
        }
    }

    /// Add the drives' joint torques R' (Ia m_dd + Fv m_d + Fs sign(m_d)) to `tau` (joint
    /// vectors over the movable joints; `qdd` `None` for the bias H, qdd = 0).
    pub fn add_torques(&self, qd: &[f64], qdd: Option<&[f64]>, tau: &mut [f64]) {
        self.add_reflected(qd, qdd, tau, |k, md, mdd| {
            self.ia[k] * mdd + self.fv[k] * md + self.fs[k] * md.sign()
        });
    }

    /// Add Fs_k (sign(m_d) - tanh(m_d / (v r_k))) reflected by R' to `tau`: what turns the
    /// motors' exact Coulomb friction into the smoothed one of the simulation when added to the
    /// torque given to the direct model (v in joint units, r_k = max_c |R_kc| the motor's
    /// largest ratio).
    pub fn add_coulomb_smoothing(&self, qd: &[f64], v: f64, tau: &mut [f64]) {
        self.add_reflected(qd, None, tau, |k, md, _| {
            self.fs[k] * (md.sign() - (md / (v * self.ratio[k])).tanh())
        });
    }

    /// Add R' diag(Ia) R to the inertia matrix `a` (joints x joints over the movable joints).
    pub fn add_inertia(&self, a: &mut DMatrix<f64>) {
        for (c, &i) in self.cols.iter().enumerate() {
            for (d, &j) in self.cols.iter().enumerate() {
                a[(i, j)] += self.inertia[(c, d)];
            }
        }
    }

    /// The rotors' kinetic energy 1/2 m_d' diag(Ia) m_d (J).
    pub fn kinetic_energy(&self, qd: &[f64]) -> f64 {
        (0..self.cols.len())
            .map(|k| 0.5 * self.ia[k] * self.motor(k, qd).powi(2))
            .sum()
    }

    /// d/dt of [`MotorDrives::kinetic_energy`]: m_d' diag(Ia) m_dd (W).
    pub fn kinetic_energy_rate(&self, qd: &[f64], qdd: &[f64]) -> f64 {
        (0..self.cols.len())
            .map(|k| self.ia[k] * self.motor(k, qd) * self.motor(k, qdd))
            .sum()
    }
}
