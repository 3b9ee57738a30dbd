//! Derivatives of the regressor, dPhi/dq_k and dPhi/dqd_k (docs/models/derivatives.md, D18):
//! Phi K = Gamma(K) - Gamma_e is linear in the standard parameters K, so column p of Phi is the
//! inverse model of the robot whose only nonzero parameter is p (no external wrench), and its
//! derivatives are that robot's dGamma/dq, dGamma/dqd by the analytical kernel
//! ([`super::inverse`]). Two named steps:
//! 1. [`RegressorDerivativesData::new`]: the 13 NL models of the unit parameters, once;
//! 2. [`regressor_derivatives_into`]: the kernel on each, its columns scattered into the
//!    N matrices dPhi/dq_k (and dPhi/dqd_k), N x 13 NL each.
//!
//! O(13 NL N d) per state: for observers and adaptive control, not for a 1 kHz loop of a
//! 40-joint robot.

use super::inverse::idm_derivative_columns;
use super::{DerivativesData, Tangent};
use crate::algorithms::inverse_dynamics::check_state;
use crate::error::{check_finite_matrix, Error, Result};
use crate::model::{DynModel, Environment, Robot, PARAMS_PER_LINK};
use nalgebra::DMatrix;

/// The buffers of [`regressor_derivatives_into`] for one robot: the model of the dynamic
/// recursions of each unit standard parameter, and the kernel's buffers.
#[derive(Clone, Debug)]
pub struct RegressorDerivativesData {
    /// Parameter p (K order) -> the folded model whose only nonzero parameter is K_p = 1.
    models: Vec<DynModel<f64>>,
    base: DerivativesData,
    /// The per-call environment without its wrenches (not parameters of Phi).
    env: Environment,
    dq: DMatrix<f64>,
    dqd: DMatrix<f64>,
}

impl RegressorDerivativesData {
    /// Step 1: the 13 NL unit-parameter models of `robot` (made once; allocates).
    pub fn new(robot: &Robot) -> Result<Self> {
        robot.require_no_motor_drives("the regressor derivatives")?;
        let np = PARAMS_PER_LINK * robot.nl();
        let mut k = vec![0.0; np];
        let mut models = Vec::with_capacity(np);
        for p in 0..np {
            k[p] = 1.0;
            models.push(robot.with_standard_parameters(&k)?.dynamic().clone());
            k[p] = 0.0;
        }
        let n = robot.dof();
        let e = robot.environment();
        Ok(RegressorDerivativesData {
            models,
            base: DerivativesData::new(robot),
            env: Environment::new(e.gravity, e.base.clone(), robot.nl()),
            dq: DMatrix::zeros(n, n),
            dqd: DMatrix::zeros(n, n),
        })
    }
}

/// dPhi/dq_k and dPhi/dqd_k for k over the movable joints: `dphi_dq[k]` is N x 13 NL, the
/// shape of Phi ([`crate::regressor_into`]).
#[derive(Clone, Debug, PartialEq)]
pub struct RegressorDerivatives {
    /// dPhi/dq_k, k = 0..N.
    pub dphi_dq: Vec<DMatrix<f64>>,
    /// dPhi/dqd_k (the FV columns' 1 included; FS and IA columns have zero derivatives).
    pub dphi_dqd: Vec<DMatrix<f64>>,
}

impl RegressorDerivatives {
    /// Zero matrices for `robot`: N of N x 13 NL each.
    pub fn new(robot: &Robot) -> Self {
        let (n, np) = (robot.dof(), PARAMS_PER_LINK * robot.nl());
        RegressorDerivatives {
            dphi_dq: vec![DMatrix::zeros(n, np); n],
            dphi_dqd: vec![DMatrix::zeros(n, np); n],
        }
    }
}

/// Step 2: the derivatives of the regressor Phi (Gamma = Phi K + Gamma_e, the columns of
/// [`crate::regressor_into`]) at `q`, `qd`, `qdd` over the movable joints, under `env`'s
/// gravity and base motion, into `out`. Allocation-free.
///
/// Errors: as [`super::inverse_dynamics_derivatives_into`]; [`Error::Dimension`] for `data`
/// or `out` made for another robot.
#[allow(clippy::too_many_arguments)]
pub fn regressor_derivatives_into(
    robot: &Robot,
    data: &mut RegressorDerivativesData,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    out: &mut RegressorDerivatives,
) -> Result<()> {
    data.base.check(robot)?;
    check_state(robot, &data.base.data, ["q", "qd", "qdd"], [q, qd, qdd])?;
    env.check(robot.nl())?;
    let (n, np) = (robot.dof(), PARAMS_PER_LINK * robot.nl());
    let fits = |v: &[DMatrix<f64>]| v.len() == n && v.iter().all(|m| m.shape() == (n, np));
    if data.models.len() != np || !fits(&out.dphi_dq) || !fits(&out.dphi_dqd) {
        return Err(Error::dimension(
            "regressor derivatives",
            n * n * np,
            out.dphi_dq.iter().map(|m| m.len()).sum(),
            format!(
                "{n} matrices of {n} x {np} (made for another robot than `{}`)",
                robot.name()
            ),
        ));
    }
    data.env.gravity = env.gravity;
    data.env.base = env.base.clone();
    let RegressorDerivativesData {
        models,
        base,
        env,
        dq,
        dqd,
    } = data;
    let DerivativesData {
        data: ws, dir, h, ..
    } = base;
    let dir: &mut [Tangent; 2] = dir;
    for (p, model) in models.iter().enumerate() {
        idm_derivative_columns(model, ws, dir, env, (q, qd, qdd), h, dq, dqd);
        for k in 0..n {
            for j in 0..n {
                out.dphi_dq[k][(j, p)] = dq[(j, k)];
                out.dphi_dqd[k][(j, p)] = dqd[(j, k)];
            }
        }
    }
    for (m, d) in out.dphi_dq.iter().zip(&out.dphi_dqd) {
        check_finite_matrix("dPhi/dq", m)?;
        check_finite_matrix("dPhi/dqd", d)?;
    }
    Ok(())
}

/// [`regressor_derivatives_into`] with the robot's own environment; allocates (its data and
/// result).
pub fn regressor_derivatives(
    robot: &Robot,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
) -> Result<RegressorDerivatives> {
    let mut data = RegressorDerivativesData::new(robot)?;
    let mut out = RegressorDerivatives::new(robot);
    let env = robot.environment();
    regressor_derivatives_into(robot, &mut data, env, q, qd, qdd, &mut out)?;
    Ok(out)
}
