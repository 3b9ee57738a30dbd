//! Minimum-effort point-to-point motion by direct multiple shooting, solved by an
//! equality-constrained SQP (the solver of `examples/optimal_control`, shared with
//! `tests/optimal_control.rs` through `#[path]`; not part of robodyn's API).
//!
//! Problem (state x = (q, qd), 2N entries; control Gamma_c, N entries, constant on each of the
//! K intervals of length dt = T / K):
//!
//! ```text
//! min   1/2 sum_k Gamma_c,k' W Gamma_c,k dt
//! s.t.  x_0 = x_start,  x_K = (q_goal, 0),  x_{k+1} = F(x_k, Gamma_c,k)   (continuity)
//! ```
//!
//! Gamma_c is the torque beyond gravity compensation: the joint torques are
//! Gamma = Gamma_c + g(q), as on a robot whose controller adds g(q) to the commanded torques
//! (the Panda's torque interface does). F is `substeps` classical Runge–Kutta steps of the
//! direct model with gravity compensated, qdd = A^-1 (Gamma_c - C(q, qd) qd - friction),
//! i.e. `direct_dynamics` without gravity. Its sensitivities ([`Sensitivities`]) are either
//! chained through the RK4 stages from `direct_dynamics_derivatives_into` (dqdd/dq, dqdd/dqd,
//! A^-1), or central finite differences of F.
//!
//! Why not Gauss–Newton: the cost is quadratic, but the Gauss–Newton SQP (Hessian W dt, the
//! constraints' curvature left out) diverges on this problem (full steps) or crawls (damped
//! steps, ~400 iterations on the Panda): the linearized dynamics let the QP buy cheap motion of
//! light links with large state excursions. The Hessian of the Lagrangian is therefore taken
//! exactly, stage by stage, H_k = d2(lambda_{k+1}' F)/dw_k^2 over w_k = (x_k, Gamma_c,k):
//! forward differences of the analytical gradient S_k' lambda_{k+1} (3N linearizations), or
//! second differences of the scalar lambda' F (F only) on the finite-difference route.
//!
//! Each SQP iteration, in named steps:
//! 1. `linearize`: F, its sensitivities S_k = [A_k | B_k] = [dF/dx_k | dF/dGamma_k] and the
//!    defects d_k = F(x_k, Gamma_k) - x_{k+1} on every interval; `multipliers`: the
//!    least-squares multipliers of the current point and its optimality residual;
//!    `lagrangian_hessian`: H_k;
//! 2. `qp_step`: the QP (quadratic model of the Lagrangian, linearized constraints) by a
//!    Riccati recursion: the backward sweep leaves dx_K affine in the terminal multipliers,
//!    a 2N x 2N system (faer's LU) fixes them, the forward sweep gives the step; a stage whose
//!    reduced Hessian is not positive definite gets a terminal penalty, then a
//!    Levenberg–Marquardt term;
//! 3. `line_search`: Armijo backtracking on the l1 merit function cost + rho sum |defects|_1,
//!    rho above the largest multiplier of the continuity constraints.
//!
//! Converged when every defect (initial, continuity, terminal) is below `defect_tol` and the
//! first-order optimality residual ([`stationarity`]) below `stationarity_tol`: the point is
//! then feasible and stationary, whatever regularization the last steps used.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use nalgebra::{DMatrix, DVector, Vector3};
use robodyn::{
    direct_dynamics, direct_dynamics_derivatives_into, direct_dynamics_into, inverse_dynamics,
    Data, DdmDerivatives, DerivativesData, Environment, Method, Robot,
};
use std::error::Error;

/// The solver's result type (robodyn's errors and the solver's own, as text).
pub type Res<T> = Result<T, Box<dyn Error>>;

/// Vectors over the nodes or the intervals (states x_0 ... x_K, controls Gamma_0 ... ).
pub type Trajectory = Vec<DVector<f64>>;

/// Where the sensitivities of F come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sensitivities {
    /// Chained through the RK4 stages from the analytical derivatives of the direct model.
    Analytical,
    /// Central finite differences of F over (x_k, Gamma_k), relative step 1e-6.
    CentralDifferences,
}

impl Sensitivities {
    /// A name for tables.
    pub fn name(self) -> &'static str {
        match self {
            Sensitivities::Analytical => "analytical",
            Sensitivities::CentralDifferences => "central differences",
        }
    }
}

/// The point-to-point problem.
#[derive(Clone, Debug)]
pub struct Problem {
    /// x_0 = (q, qd) at t = 0 (2N entries).
    pub x_start: Vec<f64>,
    /// q at t = T (reached at rest).
    pub q_goal: Vec<f64>,
    /// T (s).
    pub horizon: f64,
    /// K, the number of shooting intervals.
    pub intervals: usize,
    /// RK4 steps per interval.
    pub substeps: usize,
    /// W, the diagonal weights of the torques in the cost (N entries, > 0).
    pub weights: Vec<f64>,
}

impl Problem {
    /// dt = T / K.
    pub fn dt(&self) -> f64 {
        self.horizon / self.intervals as f64
    }

    /// (q_goal, 0).
    pub fn x_goal(&self) -> DVector<f64> {
        let n = self.q_goal.len();
        DVector::from_iterator(2 * n, self.q_goal.iter().copied().chain(vec![0.0; n]))
    }

    /// The cost 1/2 sum_k Gamma_k' W Gamma_k dt.
    pub fn cost(&self, u: &[DVector<f64>]) -> f64 {
        let dt = self.dt();
        u.iter()
            .map(|uk| {
                uk.iter()
                    .zip(&self.weights)
                    .map(|(g, w)| 0.5 * w * g * g * dt)
                    .sum::<f64>()
            })
            .sum()
    }
}

/// Solver settings.
#[derive(Clone, Copy, Debug)]
pub struct Options {
    /// The sensitivities of F.
    pub sensitivities: Sensitivities,
    /// Iteration limit (an error past it).
    pub max_iterations: usize,
    /// Largest defect accepted at convergence (rad, m, rad/s, m/s).
    pub defect_tol: f64,
    /// Largest first-order optimality residual accepted at convergence ([`stationarity`]).
    pub stationarity_tol: f64,
}

impl Options {
    /// Defects below 1e-8, optimality residual below 1e-6 (the finite-difference route stalls
    /// near 1e-7: its sensitivities carry errors of ~1e-9), at most 100 iterations.
    pub fn new(sensitivities: Sensitivities) -> Self {
        Options {
            sensitivities,
            max_iterations: 100,
            defect_tol: 1e-8,
            stationarity_tol: 1e-6,
        }
    }
}

/// One SQP iteration as logged.
#[derive(Clone, Copy, Debug)]
pub struct Iterate {
    /// Cost at the start of the iteration.
    pub cost: f64,
    /// Largest defect at the start of the iteration.
    pub max_defect: f64,
    /// max |dGamma| of the QP step.
    pub step: f64,
    /// The accepted step length (0 at the converged iterate).
    pub alpha: f64,
}

/// A converged solution.
#[derive(Clone, Debug)]
pub struct Solution {
    /// x_0 ... x_K.
    pub x: Vec<DVector<f64>>,
    /// Gamma_0 ... Gamma_{K-1}.
    pub u: Vec<DVector<f64>>,
    /// The cost.
    pub cost: f64,
    /// Largest defect (initial, continuity, terminal).
    pub max_defect: f64,
    /// SQP iterations (linearizations) done, the converged one included.
    pub iterations: usize,
    /// The iterations.
    pub history: Vec<Iterate>,
}

/// F(x, Gamma) by RK4 and its sensitivities, with the buffers of robodyn's calls made once.
pub struct Integrator<'a> {
    robot: &'a Robot,
    /// The robot's environment without gravity (the controls are gravity-compensated).
    env: Environment,
    n: usize,
    h: f64,
    substeps: usize,
    data: Data,
    deriv: DerivativesData,
    ddm: DdmDerivatives,
    /// dk of the previous stage, dk of this one, dy (2N x 3N each); f(y) (2N).
    dk: [DMatrix<f64>; 2],
    dy: DMatrix<f64>,
    qdd: Vec<f64>,
}

/// The RK4 tableau: stage offsets c_i and weights b_i.
const RK4_C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
const RK4_B: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];

impl<'a> Integrator<'a> {
    /// The integrator of `problem`'s F for `robot` (a fixed-base tree).
    pub fn new(robot: &'a Robot, problem: &Problem) -> Self {
        let n = robot.dof();
        let mut env = robot.environment().clone();
        env.gravity = Vector3::zeros();
        Integrator {
            robot,
            env,
            n,
            h: problem.dt() / problem.substeps as f64,
            substeps: problem.substeps,
            data: Data::new(robot),
            deriv: DerivativesData::new(robot),
            ddm: DdmDerivatives::new(robot),
            dk: [DMatrix::zeros(2 * n, 3 * n), DMatrix::zeros(2 * n, 3 * n)],
            dy: DMatrix::zeros(2 * n, 3 * n),
            qdd: vec![0.0; n],
        }
    }

    /// f(y, Gamma) = (qd, ddm(q, qd, Gamma)) into `out`.
    fn f(&mut self, y: &DVector<f64>, u: &DVector<f64>, out: &mut DVector<f64>) -> Res<()> {
        let n = self.n;
        let (q, qd) = y.as_slice().split_at(n);
        direct_dynamics_into(
            self.robot,
            &mut self.data,
            &self.env,
            q,
            qd,
            u.as_slice(),
            Method::Composite,
            &mut self.qdd,
        )?;
        out.rows_mut(0, n).copy_from_slice(qd);
        out.rows_mut(n, n).copy_from_slice(&self.qdd);
        Ok(())
    }

    /// x_{k+1} = F(x, Gamma): `substeps` RK4 steps.
    pub fn step(&mut self, x: &DVector<f64>, u: &DVector<f64>) -> Res<DVector<f64>> {
        let (h, m) = (self.h, 2 * self.n);
        let mut z = x.clone();
        let (mut k, mut y, mut acc) = (DVector::zeros(m), DVector::zeros(m), DVector::zeros(m));
        for _ in 0..self.substeps {
            acc.fill(0.0);
            for (&c, &b) in RK4_C.iter().zip(&RK4_B) {
                y.copy_from(&z);
                y.axpy(c * h, &k, 1.0);
                self.f(&y, u, &mut k)?;
                acc.axpy(b * h, &k, 1.0);
            }
            z += &acc;
        }
        Ok(z)
    }

    /// F(x, Gamma) and its sensitivities [dF/dx | dF/dGamma] (2N x 3N) into `s`.
    pub fn linearize(
        &mut self,
        x: &DVector<f64>,
        u: &DVector<f64>,
        how: Sensitivities,
        s: &mut DMatrix<f64>,
    ) -> Res<DVector<f64>> {
        match how {
            Sensitivities::Analytical => self.step_analytical(x, u, s),
            Sensitivities::CentralDifferences => {
                self.central_differences(x, u, s)?;
                self.step(x, u)
            }
        }
    }

    /// RK4 with the sensitivities chained through its stages: with Z = d(state)/d(x, Gamma),
    /// stage i has y_i = z + c_i h k_{i-1}, dy_i = Z + c_i h dk_{i-1} and
    /// dk_i = [[0, 1], [dqdd/dq, dqdd/dqd]] dy_i + [0; A^-1] on the Gamma columns.
    fn step_analytical(
        &mut self,
        x: &DVector<f64>,
        u: &DVector<f64>,
        s: &mut DMatrix<f64>,
    ) -> Res<DVector<f64>> {
        let (h, n) = (self.h, self.n);
        let mut z = x.clone();
        let (mut k, mut y, mut acc) = (
            DVector::zeros(2 * n),
            DVector::zeros(2 * n),
            DVector::zeros(2 * n),
        );
        s.fill(0.0);
        s.view_mut((0, 0), (2 * n, 2 * n)).fill_with_identity();
        let mut sacc = s.clone();
        for _ in 0..self.substeps {
            acc.fill(0.0);
            sacc.copy_from(s);
            for (&c, &b) in RK4_C.iter().zip(&RK4_B) {
                y.copy_from(&z);
                y.axpy(c * h, &k, 1.0);
                self.dy.copy_from(s);
                self.dy.zip_apply(&self.dk[0], |d, p| *d += c * h * p);
                self.stage_jacobian(&y, u)?;
                k.rows_mut(0, n).copy_from(&y.rows(n, n));
                k.rows_mut(n, n).copy_from(&self.ddm.qdd);
                acc.axpy(b * h, &k, 1.0);
                sacc.zip_apply(&self.dk[1], |a, d| *a += b * h * d);
                self.dk.swap(0, 1);
            }
            z += &acc;
            s.copy_from(&sacc);
        }
        Ok(z)
    }

    /// dk = J_y dy + [0; A^-1] (Gamma columns) at stage point `y` into `dk[1]`, the direct
    /// model's derivatives (and qdd) into `ddm`.
    fn stage_jacobian(&mut self, y: &DVector<f64>, u: &DVector<f64>) -> Res<()> {
        let n = self.n;
        let (q, qd) = y.as_slice().split_at(n);
        direct_dynamics_derivatives_into(
            self.robot,
            &mut self.deriv,
            &self.env,
            q,
            qd,
            u.as_slice(),
            &mut self.ddm,
        )?;
        let dk = &mut self.dk[1];
        dk.rows_mut(0, n).copy_from(&self.dy.rows(n, n));
        let mut lower = dk.rows_mut(n, n);
        lower.gemm(1.0, &self.ddm.dqdd_dq, &self.dy.rows(0, n), 0.0);
        lower.gemm(1.0, &self.ddm.dqdd_dqd, &self.dy.rows(n, n), 1.0);
        let mut du = dk.view_mut((n, 2 * n), (n, n));
        du += &self.ddm.ainv;
        Ok(())
    }

    /// Column j of `s`: (F(w + e_j eps_j) - F(w - e_j eps_j)) / (2 eps_j) over w = (x, Gamma),
    /// eps_j = 1e-6 max(1, |w_j|).
    fn central_differences(
        &mut self,
        x: &DVector<f64>,
        u: &DVector<f64>,
        s: &mut DMatrix<f64>,
    ) -> Res<()> {
        let m = 2 * self.n;
        let (mut xp, mut up) = (x.clone(), u.clone());
        for j in 0..s.ncols() {
            let entry = |xp: &mut DVector<f64>, up: &mut DVector<f64>, v: Option<f64>| {
                let (e, w) = if j < m {
                    (&mut xp[j], x[j])
                } else {
                    (&mut up[j - m], u[j - m])
                };
                *e = v.unwrap_or(w);
                w
            };
            let w = entry(&mut xp, &mut up, None);
            let eps = 1e-6 * w.abs().max(1.0);
            entry(&mut xp, &mut up, Some(w + eps));
            let fp = self.step(&xp, &up)?;
            entry(&mut xp, &mut up, Some(w - eps));
            let fm = self.step(&xp, &up)?;
            entry(&mut xp, &mut up, None);
            s.column_mut(j).copy_from(&((fp - fm) / (2.0 * eps)));
        }
        Ok(())
    }
}

/// The initial guess: q along a cubic from start to goal at rest at both ends (3s^2 - 2s^3),
/// qd its derivative, Gamma_k the inverse model at the interval's midpoint.
pub fn initial_guess(robot: &Robot, p: &Problem) -> Res<(Trajectory, Trajectory)> {
    let n = robot.dof();
    let q0 = &p.x_start[..n];
    let t = p.horizon;
    let at = |s: f64| -> [Vec<f64>; 3] {
        let (pos, vel, acc) = (
            3.0 * s * s - 2.0 * s.powi(3),
            (6.0 * s - 6.0 * s * s) / t,
            (6.0 - 12.0 * s) / (t * t),
        );
        let d: Vec<f64> = (0..n).map(|j| p.q_goal[j] - q0[j]).collect();
        [
            (0..n).map(|j| q0[j] + pos * d[j]).collect(),
            (0..n).map(|j| vel * d[j]).collect(),
            (0..n).map(|j| acc * d[j]).collect(),
        ]
    };
    let kk = p.intervals;
    let mut x: Vec<DVector<f64>> = (0..=kk)
        .map(|k| {
            let [q, qd, _] = at(k as f64 / kk as f64);
            DVector::from_iterator(2 * n, q.into_iter().chain(qd))
        })
        .collect();
    x[0] = DVector::from_column_slice(&p.x_start);
    let u = (0..kk)
        .map(|k| {
            let [q, qd, qdd] = at((k as f64 + 0.5) / kk as f64);
            let z = vec![0.0; n];
            Ok(inverse_dynamics(robot, &q, &qd, &qdd)? - inverse_dynamics(robot, &q, &z, &z)?)
        })
        .collect::<robodyn::Result<Vec<_>>>()?;
    Ok((x, u))
}

/// Step 1 of an iteration: F, [A_k | B_k] and the defects (initial d_init = x_start - x_0,
/// continuity d_k = F_k - x_{k+1}, terminal d_end = x_goal - x_K).
pub struct Linearization {
    /// [A_k | B_k] per interval.
    pub s: Vec<DMatrix<f64>>,
    /// d_k per interval.
    pub d: Vec<DVector<f64>>,
    /// x_start - x_0.
    pub d_init: DVector<f64>,
    /// x_goal - x_K.
    pub d_end: DVector<f64>,
}

impl Linearization {
    /// The largest defect.
    pub fn max_defect(&self) -> f64 {
        self.d
            .iter()
            .map(|d| d.amax())
            .fold(self.d_init.amax().max(self.d_end.amax()), f64::max)
    }

    /// The sum of the defects' l1 norms (the merit function's penalty).
    fn l1(&self) -> f64 {
        self.d.iter().map(|d| d.lp_norm(1)).sum::<f64>()
            + self.d_init.lp_norm(1)
            + self.d_end.lp_norm(1)
    }
}

/// Step 1: linearize F along (x, u) (`how` = None: the defects only).
pub fn linearize(
    integ: &mut Integrator,
    p: &Problem,
    x: &[DVector<f64>],
    u: &[DVector<f64>],
    how: Option<Sensitivities>,
) -> Res<Linearization> {
    let n = integ.n;
    let mut lin = Linearization {
        s: Vec::new(),
        d: Vec::with_capacity(u.len()),
        d_init: DVector::from_column_slice(&p.x_start) - &x[0],
        d_end: p.x_goal() - &x[u.len()],
    };
    for (k, uk) in u.iter().enumerate() {
        let f = match how {
            Some(how) => {
                let mut s = DMatrix::zeros(2 * n, 3 * n);
                let f = integ.linearize(&x[k], uk, how, &mut s)?;
                lin.s.push(s);
                f
            }
            None => integ.step(&x[k], uk)?,
        };
        lin.d.push(f - &x[k + 1]);
    }
    Ok(lin)
}

/// The terminal map of the condensed problem: M = [Phi_{K,1} B_0 ... Phi_{K,K} B_{K-1}]
/// (2N x N K), Phi_{K,j} = A_{K-1} ... A_j.
pub fn terminal_map(lin: &Linearization, n: usize) -> DMatrix<f64> {
    let kk = lin.s.len();
    let mut m = DMatrix::zeros(2 * n, n * kk);
    let mut p = DMatrix::identity(2 * n, 2 * n);
    for k in (0..kk).rev() {
        let (a, b) = (lin.s[k].columns(0, 2 * n), lin.s[k].columns(2 * n, n));
        m.columns_mut(k * n, n).gemm(1.0, &p, &b, 0.0);
        p = &p * a;
    }
    m
}

/// The condensed QP min 1/2 dU' B dU + g' dU s.t. M dU = r, with H = B^-1: its KKT system
/// reduces to the Schur complement S = M H M' (2N x 2N, faer's Cholesky),
/// S mu = r + M H g, dU = H (M' mu - g). Returns (dU, mu).
pub fn kkt_solve(
    m: &DMatrix<f64>,
    h: &DMatrix<f64>,
    g: &DVector<f64>,
    r: &DVector<f64>,
) -> Res<(DVector<f64>, DVector<f64>)> {
    let rows = m.nrows();
    let hm = h * m.transpose();
    let s = m * &hm;
    let sf = Mat::<f64>::from_fn(rows, rows, |i, j| s[(i, j)]);
    let llt = sf.llt(Side::Lower).map_err(|e| {
        format!(
            "the condensed KKT matrix M H M' is not positive definite ({e:?}): the goal is \
             not reachable to first order (an uncontrollable linearization)"
        )
    })?;
    let rhs = r + m * (h * g);
    let b = Mat::<f64>::from_fn(rows, 1, |i, _| rhs[i]);
    let mu_m = llt.solve(&b);
    let mu = DVector::from_fn(rows, |i, _| mu_m[(i, 0)]);
    Ok((&hm * &mu - h * g, mu))
}

/// The controls stacked (N K).
fn stack(u: &[DVector<f64>]) -> DVector<f64> {
    DVector::from_iterator(
        u.iter().map(|v| v.len()).sum(),
        u.iter().flat_map(|v| v.iter().copied()),
    )
}

/// The gradient of the cost, W dt Gamma, stacked.
fn cost_gradient(p: &Problem, u: &[DVector<f64>]) -> DVector<f64> {
    let n = p.weights.len();
    let dt = p.dt();
    let mut g = stack(u);
    for (i, x) in g.iter_mut().enumerate() {
        *x *= p.weights[i % n] * dt;
    }
    g
}

/// (W dt)^-1 as a dense N K x N K matrix: the metric of the optimality residual.
fn gauss_newton_inverse(p: &Problem, kk: usize) -> DMatrix<f64> {
    let n = p.weights.len();
    let d = DVector::from_fn(n * kk, |i, _| 1.0 / (p.weights[i % n] * p.dt()));
    DMatrix::from_diagonal(&d)
}

/// The Hessian of lambda' F(w) over w = (x_k, Gamma_k) (3N x 3N), symmetrized: forward
/// differences of the analytical gradient S(w)' lambda (3N linearizations), or second
/// differences of the scalar lambda' F(w) (F only).
fn lagrangian_hessian(
    integ: &mut Integrator,
    x: &DVector<f64>,
    u: &DVector<f64>,
    s: &DMatrix<f64>,
    lambda: &DVector<f64>,
    how: Sensitivities,
) -> Res<DMatrix<f64>> {
    let m = x.len();
    let w0 = DVector::from_iterator(m + u.len(), x.iter().chain(u.iter()).copied());
    let split = |w: &DVector<f64>| {
        (
            w.rows(0, m).into_owned(),
            w.rows(m, w.len() - m).into_owned(),
        )
    };
    let dim = w0.len();
    let mut h = DMatrix::zeros(dim, dim);
    match how {
        Sensitivities::Analytical => {
            let g0 = s.transpose() * lambda;
            let mut sj = s.clone();
            for j in 0..dim {
                let eps = 1e-6 * w0[j].abs().max(1.0);
                let mut w = w0.clone();
                w[j] += eps;
                let (xp, up) = split(&w);
                integ.linearize(&xp, &up, how, &mut sj)?;
                h.set_column(j, &((sj.transpose() * lambda - &g0) / eps));
            }
        }
        Sensitivities::CentralDifferences => {
            let eps: Vec<f64> = w0.iter().map(|v| 1e-4 * v.abs().max(1.0)).collect();
            let mut phi = |w: &DVector<f64>| -> Res<f64> {
                let (xp, up) = split(w);
                Ok(integ.step(&xp, &up)?.dot(lambda))
            };
            let f0 = phi(&w0)?;
            let mut f1 = vec![0.0; dim];
            for i in 0..dim {
                let mut w = w0.clone();
                w[i] += eps[i];
                f1[i] = phi(&w)?;
            }
            for i in 0..dim {
                for j in i..dim {
                    let mut w = w0.clone();
                    w[i] += eps[i];
                    w[j] += eps[j];
                    let v = (phi(&w)? - f1[i] - f1[j] + f0) / (eps[i] * eps[j]);
                    h[(i, j)] = v;
                    h[(j, i)] = v;
                }
            }
        }
    }
    Ok(0.5 * (&h + h.transpose()))
}

/// The QP step: state and control steps and the largest entry of the QP's continuity
/// multipliers (the gradients of its cost-to-go at the new states).
pub struct Step {
    /// dx_0 ... dx_K.
    pub dx: Vec<DVector<f64>>,
    /// dGamma_0 ... dGamma_{K-1}.
    pub du: Vec<DVector<f64>>,
    /// max |lambda|.
    pub lmax: f64,
}

/// One stage of the backward Riccati sweep: the feedback dGamma = K dx + k + L nu.
struct Gains {
    k_mat: DMatrix<f64>,
    k_vec: DVector<f64>,
    l_mat: DMatrix<f64>,
}

/// The value function V_k(dx) = 1/2 dx' P dx + dx' (p + Y nu) (nu: the terminal multipliers).
struct Value {
    p_mat: DMatrix<f64>,
    p_vec: DVector<f64>,
    y_mat: DMatrix<f64>,
    /// P, p, Y of every stage (for the multipliers).
    all: Vec<(DMatrix<f64>, DVector<f64>, DMatrix<f64>)>,
}

/// The backward sweep (Riccati recursion) of the QP with the stage Hessians `hess` (of the
/// Lagrangian's dynamics terms) plus W dt + sigma on the controls; None when a stage's
/// reduced Hessian Q_uu is not positive definite.
fn backward(
    p: &Problem,
    lin: &Linearization,
    hess: &[DMatrix<f64>],
    u: &[DVector<f64>],
    (c, sigma): (f64, f64),
) -> Option<(Vec<Gains>, Value)> {
    let m = lin.d_init.len();
    let n = m / 2;
    let dt = p.dt();
    // c/2 |dx_K - d_end|^2 vanishes on the terminal constraint: the QP's solution is the same,
    // and it makes the stages' Q_uu positive definite when the terminal constraint is what
    // makes the QP convex
    let mut v = Value {
        p_mat: DMatrix::identity(m, m) * c,
        p_vec: -c * &lin.d_end,
        y_mat: DMatrix::identity(m, m),
        all: Vec::new(),
    };
    v.all
        .push((v.p_mat.clone(), v.p_vec.clone(), v.y_mat.clone()));
    let mut gains = Vec::with_capacity(u.len());
    for k in (0..u.len()).rev() {
        let (a, b) = (lin.s[k].columns(0, m), lin.s[k].columns(m, n));
        let h = &hess[k];
        let pa = &v.p_mat * a;
        let pb = &v.p_mat * b;
        let next = &v.p_vec + &v.p_mat * &lin.d[k];
        let qxx = h.view((0, 0), (m, m)) + a.transpose() * &pa;
        let qux = h.view((m, 0), (n, m)) + b.transpose() * &pa;
        let mut quu = h.view((m, m), (n, n)) + b.transpose() * &pb;
        for j in 0..n {
            quu[(j, j)] += p.weights[j] * dt + sigma;
        }
        let qu = DVector::from_fn(n, |j, _| p.weights[j] * dt * u[k][j]) + b.transpose() * &next;
        let qx = a.transpose() * &next;
        let chol = quu.cholesky()?;
        let g = Gains {
            k_mat: -chol.solve(&qux),
            k_vec: -chol.solve(&qu),
            l_mat: -chol.solve(&(b.transpose() * &v.y_mat)),
        };
        let p_mat = &qxx + qux.transpose() * &g.k_mat;
        v.p_mat = 0.5 * (&p_mat + p_mat.transpose());
        v.p_vec = qx + qux.transpose() * &g.k_vec;
        v.y_mat = a.transpose() * &v.y_mat + qux.transpose() * &g.l_mat;
        v.all
            .push((v.p_mat.clone(), v.p_vec.clone(), v.y_mat.clone()));
        gains.push(g);
    }
    gains.reverse();
    v.all.reverse();
    Some((gains, v))
}

/// The forward sweep for the terminal multipliers `nu`: dx, dGamma.
fn forward(
    lin: &Linearization,
    gains: &[Gains],
    nu: &DVector<f64>,
) -> (Vec<DVector<f64>>, Vec<DVector<f64>>) {
    let m = lin.d_init.len();
    let mut dx = vec![lin.d_init.clone()];
    let mut du = Vec::with_capacity(gains.len());
    for (k, g) in gains.iter().enumerate() {
        let duk = &g.k_mat * &dx[k] + &g.k_vec + &g.l_mat * nu;
        let next =
            lin.s[k].columns(0, m) * &dx[k] + lin.s[k].columns(m, duk.len()) * &duk + &lin.d[k];
        dx.push(next);
        du.push(duk);
    }
    (dx, du)
}

/// Step 2: the SQP step by the Riccati recursion with the terminal constraint dx_K = d_end:
/// the backward sweep leaves dx_K affine in the terminal multipliers nu, dx_K = a + Z nu;
/// Z nu = d_end - a is solved by faer's LU (2N x 2N), then the forward sweep gives the step.
/// `sigma` grows until every stage's Q_uu is positive definite.
fn qp_step(
    p: &Problem,
    lin: &Linearization,
    hess: &[DMatrix<f64>],
    u: &[DVector<f64>],
    sigma: &mut f64,
) -> Res<Step> {
    let m = lin.d_init.len();
    let scale = p.dt() * p.weights.iter().fold(0.0, |a: f64, &b| a.max(b));
    let mut c = scale;
    let (gains, v) = loop {
        if let Some(r) = backward(p, lin, hess, u, (c, *sigma)) {
            break r;
        }
        if c < 1e12 * scale {
            c *= 10.0;
        } else {
            *sigma = (*sigma * 10.0).max(1e-6 * scale);
        }
        if *sigma > 1e12 * scale {
            return Err("the QP's reduced Hessian cannot be made positive definite".into());
        }
    };
    // dx_K(nu) = a + Z nu: a from nu = 0, Z column by column from unit nu (linear part)
    let (dx0, _) = forward(lin, &gains, &DVector::zeros(m));
    let mut z = DMatrix::zeros(m, m);
    let mut zx = vec![DMatrix::<f64>::zeros(m, m)];
    for (k, g) in gains.iter().enumerate() {
        let (a, b) = (lin.s[k].columns(0, m), lin.s[k].columns(m, g.k_vec.len()));
        let next = (a + b * &g.k_mat) * &zx[k] + b * &g.l_mat;
        zx.push(next);
    }
    z.copy_from(&zx[gains.len()]);
    let rhs = &lin.d_end - &dx0[gains.len()];
    let zf = Mat::<f64>::from_fn(m, m, |i, j| z[(i, j)]);
    let lu = zf.partial_piv_lu();
    let nu_m = lu.solve(Mat::<f64>::from_fn(m, 1, |i, _| rhs[i]));
    let nu = DVector::from_fn(m, |i, _| nu_m[(i, 0)]);
    if !nu.iter().all(|x| x.is_finite()) {
        return Err("the terminal state is not reachable to first order (Z is singular)".into());
    }
    let (dx, du) = forward(lin, &gains, &nu);
    // lambda_k = grad V_k at the new dx_k: P_k dx_k + p_k + Y_k nu
    let lambda: Vec<DVector<f64>> = v
        .all
        .iter()
        .zip(&dx)
        .map(|((pm, pv, ym), d)| pm * d + pv + ym * &nu)
        .collect();
    let lmax = lambda.iter().map(|l| l.amax()).fold(0.0, f64::max);
    Ok(Step { dx, du, lmax })
}

/// Step 3: Armijo backtracking on cost + rho |defects|_1; the accepted step length.
fn line_search(
    integ: &mut Integrator,
    p: &Problem,
    lin: &Linearization,
    x: &mut Vec<DVector<f64>>,
    u: &mut Vec<DVector<f64>>,
    step: &Step,
    rho: f64,
) -> Res<f64> {
    let merit0 = p.cost(u) + rho * lin.l1();
    let slope = cost_gradient(p, u).dot(&stack(&step.du)) - rho * lin.l1();
    let mut alpha = 1.0;
    while alpha >= 1e-8 {
        let xt: Vec<DVector<f64>> = x.iter().zip(&step.dx).map(|(a, b)| a + alpha * b).collect();
        let ut: Vec<DVector<f64>> = u.iter().zip(&step.du).map(|(a, b)| a + alpha * b).collect();
        // a trial point where the model fails (a NaN acceleration) is rejected like a worse one
        if let Ok(trial) = linearize(integ, p, &xt, &ut, None) {
            if p.cost(&ut) + rho * trial.l1() <= merit0 + 1e-4 * alpha * slope {
                *x = xt;
                *u = ut;
                return Ok(alpha);
            }
        }
        alpha *= 0.5;
    }
    Err(format!("line search failed (merit {merit0:e}, slope {slope:e})").into())
}

/// Solves `p` from the initial guess (x, u) (see the [module](self)).
pub fn solve(
    robot: &Robot,
    p: &Problem,
    opt: &Options,
    mut x: Vec<DVector<f64>>,
    mut u: Vec<DVector<f64>>,
) -> Res<Solution> {
    let mut integ = Integrator::new(robot, p);
    let mut history = Vec::new();
    let mut rho = 0.0f64;
    for it in 1..=opt.max_iterations {
        let lin = linearize(&mut integ, p, &x, &u, Some(opt.sensitivities))?;
        let (lambda, resid) = multipliers(p, &lin, &u)?;
        let hess = (0..u.len())
            .map(|k| {
                lagrangian_hessian(
                    &mut integ,
                    &x[k],
                    &u[k],
                    &lin.s[k],
                    &lambda[k + 1],
                    opt.sensitivities,
                )
            })
            .collect::<Res<Vec<_>>>()?;
        let mut sigma = 0.0;
        let step = qp_step(p, &lin, &hess, &u, &mut sigma)?;
        let du_max = step.du.iter().map(|d| d.amax()).fold(0.0, f64::max);
        let mut log = Iterate {
            cost: p.cost(&u),
            max_defect: lin.max_defect(),
            step: du_max,
            alpha: 0.0,
        };
        if log.max_defect <= opt.defect_tol && resid <= opt.stationarity_tol {
            history.push(log);
            return Ok(Solution {
                x,
                u,
                cost: log.cost,
                max_defect: log.max_defect,
                iterations: it,
                history,
            });
        }
        rho = rho.max(1.5 * step.lmax + 1e-9);
        log.alpha = line_search(&mut integ, p, &lin, &mut x, &mut u, &step, rho).map_err(|e| {
            format!(
                "iteration {it}: {e}; largest defect {:.1e}, optimality residual {resid:.1e}",
                log.max_defect
            )
        })?;
        history.push(log);
    }
    Err(format!(
        "no convergence in {} iterations (last: {:?})",
        opt.max_iterations,
        history.last()
    )
    .into())
}

/// The least-squares multipliers of the current point and its first-order optimality
/// residual: with the terminal map M and g = W dt Gamma, mu solves
/// (M (W dt)^-1 M') mu = M (W dt)^-1 g, the residual is max |g - M' mu| / max |g|, and the
/// continuity multipliers are lambda_K = -mu, lambda_k = A_k' lambda_{k+1}.
pub fn multipliers(
    p: &Problem,
    lin: &Linearization,
    u: &[DVector<f64>],
) -> Res<(Vec<DVector<f64>>, f64)> {
    let m2 = lin.d_init.len();
    let m = terminal_map(lin, m2 / 2);
    let h = gauss_newton_inverse(p, u.len());
    let g = cost_gradient(p, u);
    let (_, mu) = kkt_solve(&m, &h, &g, &DVector::zeros(m2))?;
    let resid = (&g - m.transpose() * &mu).amax() / g.amax().max(f64::MIN_POSITIVE);
    let mut lambda = vec![-mu];
    for k in (0..u.len()).rev() {
        let next = lin.s[k].columns(0, m2).transpose() * &lambda[0];
        lambda.insert(0, next);
    }
    Ok((lambda, resid))
}

/// The first-order optimality residual of (x, u) with the sensitivities `how`:
/// max |W dt Gamma - M' mu| / max |W dt Gamma|, mu the least-squares multipliers
/// (M (W dt)^-1 M') mu = M Gamma of the terminal map M at (x, u). Zero at a stationary point of
/// the cost on the constraints' manifold.
pub fn stationarity(
    robot: &Robot,
    p: &Problem,
    x: &[DVector<f64>],
    u: &[DVector<f64>],
    how: Sensitivities,
) -> Res<f64> {
    let mut integ = Integrator::new(robot, p);
    let lin = linearize(&mut integ, p, x, u, Some(how))?;
    Ok(multipliers(p, &lin, u)?.1)
}

/// The states at the nodes reached by the joint torques Gamma = Gamma_c,k + g(q) (g(q) =
/// `inverse_dynamics` at rest, at every stage point) from x_start: `substeps` RK4 steps per
/// interval of the direct model WITH gravity by articulated bodies, routes the solver does not
/// use (a check of its solutions).
pub fn resimulate(
    robot: &Robot,
    p: &Problem,
    u: &[DVector<f64>],
    substeps: usize,
) -> Res<Trajectory> {
    let n = robot.dof();
    let h = p.dt() / substeps as f64;
    let z = vec![0.0; n];
    let f = |x: &DVector<f64>, uk: &DVector<f64>| -> Res<DVector<f64>> {
        let (q, qd) = x.as_slice().split_at(n);
        let tau = uk + inverse_dynamics(robot, q, &z, &z)?;
        let qdd = direct_dynamics(robot, q, qd, tau.as_slice(), Method::ArticulatedBody)?;
        Ok(DVector::from_iterator(
            2 * n,
            qd.iter().copied().chain(qdd.iter().copied()),
        ))
    };
    let mut x = DVector::from_column_slice(&p.x_start);
    let mut nodes = vec![x.clone()];
    for uk in u {
        for _ in 0..substeps {
            let k1 = f(&x, uk)?;
            let k2 = f(&(&x + 0.5 * h * &k1), uk)?;
            let k3 = f(&(&x + 0.5 * h * &k2), uk)?;
            let k4 = f(&(&x + h * &k3), uk)?;
            x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        nodes.push(x.clone());
    }
    Ok(nodes)
}
