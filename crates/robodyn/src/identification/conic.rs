//! A small dense primal-dual interior-point solver for the convex quadratic programs of
//! physical consistency, in pure Rust (nalgebra):
//!
//! ```text
//!  min 1/2 x^T P x + q^T x   subject to   S_j(x) = C_j + sum_k x_(v_jk) A_jk  PSD (4x4),
//!                                          x_i >= l_i,  x_i <= u_i  (listed variables)
//! ```
//!
//! with P symmetric positive semidefinite. The method is the one of CVXOPT's `coneqp`
//! (Vandenberghe 2010, "The CVXOPT linear and quadratic cone program solvers"): infeasible
//! start, Nesterov–Todd scaling of every cone (for a 4x4 block: two Cholesky factors and the
//! SVD of their product), Mehrotra's predictor–corrector, the Newton systems reduced to the
//! n x n positive definite matrix P + L^T (W^T W)^-1 L, factored by Cholesky and refined
//! iteratively, and the problem first equilibrated (Ruiz: columns of [P; L], one factor per
//! cone block, and the objective) as Clarabel does, its origin moved to the minimizer of the
//! objective alone (so that the objective at the optimum is its increase over the
//! unconstrained minimum and the relative gap measures that, not the size of the data).
//!
//! After convergence the answer is polished: the minimizer on the face of the cones that the
//! last iterate identifies (active eigenvectors of each block, active bounds), kept only when
//! its optimality is verified (primal feasible, multipliers in the dual cones, objective no
//! worse); it makes active constraints exactly active and the weakly determined variables
//! exact.
//!
//! Convergence (in the equilibrated problem, infinity norms): primal residual
//! ||s - S(x)|| <= tol (1 + max(||s||, ||C||, ||L x||)), dual residual
//! ||P x + q - L^T z|| <= tol (1 + max(||P x||, ||q||, ||L^T z||)), and duality gap
//! <s, z> <= tol max(1, min(|primal objective|, |dual objective|)); by default tol = 1e-10.
//! A run whose primal residual and gap are met but whose dual residual stops decreasing (five
//! iterations without a 10 % reduction) below 1e-6 —
//! rounding in the products of an ill-conditioned P, e.g. a noise-free fit — is accepted with
//! reduced accuracy (as Clarabel's "almost solved"), visible in `dual_residual`. Anything else
//! that does not meet the rules within the iteration budget is an error naming the residuals
//! reached: no answer is returned silently.

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector, Matrix4, Vector4};

mod polish;

/// One 4x4 positive semidefinite constraint S(x) = constant + sum_k x\[var_k\] A_k (symmetric).
#[derive(Clone, Debug, PartialEq)]
pub struct PsdBlock {
    /// The constant C (symmetric).
    pub constant: Matrix4<f64>,
    /// (variable index, A_k symmetric): the linear part.
    pub terms: Vec<(usize, Matrix4<f64>)>,
}

impl PsdBlock {
    /// S(x).
    pub fn value(&self, x: &[f64]) -> Matrix4<f64> {
        let mut s = self.constant;
        for (v, a) in &self.terms {
            s += a * x[*v];
        }
        s
    }
}

/// The problem: min 1/2 x^T P x + q^T x subject to the PSD blocks and the bounds.
#[derive(Clone, Debug, PartialEq)]
pub struct ConicQp {
    /// P (n x n, symmetric positive semidefinite; only its symmetric part is used).
    pub p: DMatrix<f64>,
    /// q (n).
    pub q: DVector<f64>,
    /// S_j(x) PSD.
    pub psd: Vec<PsdBlock>,
    /// (variable, l): x_variable >= l.
    pub lower: Vec<(usize, f64)>,
    /// (variable, u): x_variable <= u.
    pub upper: Vec<(usize, f64)>,
}

/// Stopping rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Settings {
    /// Iteration budget (default 100; well-posed problems take 15 to 40).
    pub max_iterations: usize,
    /// Relative tolerance of the residuals and the gap (default 1e-10).
    pub tolerance: f64,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            max_iterations: 100,
            tolerance: 1e-10,
        }
    }
}

/// The optimum with its certificate: S_j(x) = psd_slack_j, psd_dual_j PSD with
/// P x + q = sum_j L_j^T psd_dual_j + lower_dual - upper_dual (KKT).
#[derive(Clone, Debug, PartialEq)]
pub struct ConicSolution {
    /// The minimizer x.
    pub x: Vec<f64>,
    /// 1/2 x^T P x + q^T x.
    pub objective: f64,
    /// Slacks of the PSD blocks (S_j(x) up to the primal residual).
    pub psd_slack: Vec<Matrix4<f64>>,
    /// Dual variables (Lagrange multipliers) of the PSD blocks.
    pub psd_dual: Vec<Matrix4<f64>>,
    /// Multipliers of the lower bounds (>= 0).
    pub lower_dual: Vec<f64>,
    /// Multipliers of the upper bounds (>= 0).
    pub upper_dual: Vec<f64>,
    /// Interior-point iterations.
    pub iterations: usize,
    /// Whether the answer is the polished one: the minimizer on the face of the cones the
    /// interior point identified, verified optimal (see the `polish` step), rather than the
    /// last interior iterate.
    pub polished: bool,
    /// Relative primal residual, dual residual and gap at the end (equilibrated problem).
    pub primal_residual: f64,
    /// See `primal_residual`.
    pub dual_residual: f64,
    /// See `primal_residual`.
    pub gap: f64,
}

/// A bound in the equilibrated problem: s = s0 + a x_var >= 0.
#[derive(Clone, Copy, Debug)]
struct Linear {
    var: usize,
    a: f64,
    s0: f64,
}

/// The equilibrated problem: x = d .* x_hat, block j scaled by e_j, objective by c.
struct Equilibrated {
    p: DMatrix<f64>,
    q: DVector<f64>,
    blocks: Vec<PsdBlock>,
    lin: Vec<Linear>,
    d: DVector<f64>,
    /// The origin of x_hat: x = d .* (origin + u), u the solver's variable (see `center`).
    origin: DVector<f64>,
    e_psd: Vec<f64>,
    e_lin: Vec<f64>,
    c: f64,
}

/// A point of the cone product (or of its space): one 4x4 matrix per block, one number per
/// bound.
#[derive(Clone, Debug)]
struct ConeVec {
    psd: Vec<Matrix4<f64>>,
    lin: Vec<f64>,
}

impl ConeVec {
    fn dot(&self, o: &ConeVec) -> f64 {
        let a: f64 = self.psd.iter().zip(&o.psd).map(|(x, y)| x.dot(y)).sum();
        a + self.lin.iter().zip(&o.lin).map(|(x, y)| x * y).sum::<f64>()
    }

    fn norm_inf(&self) -> f64 {
        let a = self.psd.iter().map(|m| m.amax()).fold(0.0, f64::max);
        self.lin.iter().map(|v| v.abs()).fold(a, f64::max)
    }

    fn axpy(&mut self, alpha: f64, o: &ConeVec) {
        for (x, y) in self.psd.iter_mut().zip(&o.psd) {
            *x += y * alpha;
        }
        for (x, y) in self.lin.iter_mut().zip(&o.lin) {
            *x += alpha * y;
        }
    }

    fn sub(&self, o: &ConeVec) -> ConeVec {
        let mut r = self.clone();
        r.axpy(-1.0, o);
        r
    }
}

/// Nesterov–Todd scaling of one 4x4 block: W(u) = R^T u R, with R^-1 S R^-T = R^T Z R = lambda.
struct PsdScaling {
    r: Matrix4<f64>,
    rinv: Matrix4<f64>,
    lambda: Vector4<f64>,
    /// (R R^T)^-1 = R^-T R^-1.
    m: Matrix4<f64>,
}

/// The scalings of all cones.
struct Scaling {
    psd: Vec<PsdScaling>,
    /// sqrt(s / z) per bound (W), and lambda = sqrt(s z).
    w: Vec<f64>,
    lambda: Vec<f64>,
}

/// Equilibration (Ruiz) iterations.
const RUIZ_ITERATIONS: usize = 15;
/// Largest relative dual residual accepted, with reduced accuracy, from a run that stalls with
/// its primal residual and gap below the tolerance.
const REDUCED_DUAL: f64 = 1e-6;
/// Fraction of the step to the boundary of the cones.
const STEP_FRACTION: f64 = 0.99;

impl Equilibrated {
    fn n(&self) -> usize {
        self.q.len()
    }

    fn degree(&self) -> usize {
        4 * self.blocks.len() + self.lin.len()
    }

    fn new(qp: &ConicQp) -> Result<Equilibrated> {
        let n = qp.q.len();
        if qp.p.nrows() != n || qp.p.ncols() != n {
            return Err(Error::Numerical(format!(
                "conic QP: P is {}x{} for {n} variables",
                qp.p.nrows(),
                qp.p.ncols()
            )));
        }
        let bad_var = qp
            .psd
            .iter()
            .flat_map(|b| b.terms.iter().map(|t| t.0))
            .chain(qp.lower.iter().chain(&qp.upper).map(|b| b.0))
            .any(|v| v >= n);
        let finite = qp.p.iter().chain(qp.q.iter()).all(|v| v.is_finite())
            && qp.lower.iter().chain(&qp.upper).all(|b| b.1.is_finite());
        if bad_var || !finite {
            return Err(Error::Numerical(
                "conic QP: a constraint names a variable out of range, or a value is not finite"
                    .into(),
            ));
        }
        let mut lin: Vec<Linear> = qp
            .lower
            .iter()
            .map(|&(var, l)| Linear {
                var,
                a: 1.0,
                s0: -l,
            })
            .collect();
        lin.extend(qp.upper.iter().map(|&(var, u)| Linear {
            var,
            a: -1.0,
            s0: u,
        }));
        let mut eq = Equilibrated {
            p: (&qp.p + qp.p.transpose()) * 0.5,
            q: qp.q.clone(),
            blocks: qp.psd.clone(),
            e_psd: vec![1.0; qp.psd.len()],
            e_lin: vec![1.0; lin.len()],
            lin,
            d: DVector::from_element(n, 1.0),
            origin: DVector::zeros(n),
            c: 1.0,
        };
        eq.ruiz();
        Ok(eq)
    }

    /// Ruiz equilibration of [P L^T; L 0]: each column of x and each cone (one factor for a
    /// whole 4x4 block, which keeps it a PSD cone) divided by the square root of its largest
    /// entry, repeatedly (as Clarabel).
    fn ruiz(&mut self) {
        let n = self.n();
        for _ in 0..RUIZ_ITERATIONS {
            let mut col: Vec<f64> = (0..n).map(|k| self.p.column(k).amax()).collect();
            let mut blk = vec![0.0f64; self.blocks.len()];
            for (j, b) in self.blocks.iter().enumerate() {
                for (v, a) in &b.terms {
                    col[*v] = col[*v].max(a.amax());
                    blk[j] = blk[j].max(a.amax());
                }
            }
            let mut lr = vec![0.0f64; self.lin.len()];
            for (i, l) in self.lin.iter().enumerate() {
                col[l.var] = col[l.var].max(l.a.abs());
                lr[i] = l.a.abs();
            }
            let inv_sqrt = |v: f64| if v > 0.0 { 1.0 / v.sqrt() } else { 1.0 };
            let dk: Vec<f64> = col.iter().map(|&v| inv_sqrt(v)).collect();
            for r in 0..n {
                for c in 0..n {
                    self.p[(r, c)] *= dk[r] * dk[c];
                }
                self.q[r] *= dk[r];
                self.d[r] *= dk[r];
            }
            for (j, b) in self.blocks.iter_mut().enumerate() {
                let ej = inv_sqrt(blk[j]);
                self.e_psd[j] *= ej;
                b.constant *= ej;
                for (v, a) in &mut b.terms {
                    *a *= ej * dk[*v];
                }
            }
            for (i, l) in self.lin.iter_mut().enumerate() {
                let ei = inv_sqrt(lr[i]);
                self.e_lin[i] *= ei;
                l.s0 *= ei;
                l.a *= ei * dk[l.var];
            }
        }
    }

    /// Scale the objective to unit size (after `center`).
    fn scale_objective(&mut self) {
        let n = self.n();
        let mean_col = (0..n).map(|k| self.p.column(k).amax()).sum::<f64>() / n.max(1) as f64;
        let scale = mean_col.max(self.q.amax());
        let c = if scale > 0.0 {
            (1.0 / scale).clamp(1e-8, 1e8)
        } else {
            1.0
        };
        self.p *= c;
        self.q *= c;
        self.c = c;
    }

    /// Move the origin to x0: u = x - x0, q + P x0 and the constants C + L x0 in its place. The
    /// objective's value at the optimum is then of the size of its change from x0 instead of
    /// (for a least-squares objective) minus the squared norm of the data, so that the relative
    /// gap measures the accuracy of the optimum.
    fn center(&mut self, x0: &DVector<f64>) {
        self.q += &self.p * x0;
        let shift = self.apply(x0);
        for (b, m) in self.blocks.iter_mut().zip(&shift.psd) {
            b.constant += m;
        }
        for (l, v) in self.lin.iter_mut().zip(&shift.lin) {
            l.s0 += v;
        }
        self.origin += x0;
    }

    /// L x (the linear part of the slacks).
    fn apply(&self, x: &DVector<f64>) -> ConeVec {
        ConeVec {
            psd: self
                .blocks
                .iter()
                .map(|b| {
                    let mut s = Matrix4::zeros();
                    for (v, a) in &b.terms {
                        s += a * x[*v];
                    }
                    s
                })
                .collect(),
            lin: self.lin.iter().map(|l| l.a * x[l.var]).collect(),
        }
    }

    /// L^T y.
    fn adjoint(&self, y: &ConeVec) -> DVector<f64> {
        let mut r = DVector::zeros(self.n());
        for (b, m) in self.blocks.iter().zip(&y.psd) {
            for (v, a) in &b.terms {
                r[*v] += a.dot(m);
            }
        }
        for (l, v) in self.lin.iter().zip(&y.lin) {
            r[l.var] += l.a * v;
        }
        r
    }

    fn constant(&self) -> ConeVec {
        ConeVec {
            psd: self.blocks.iter().map(|b| b.constant).collect(),
            lin: self.lin.iter().map(|l| l.s0).collect(),
        }
    }

    fn identity(&self) -> ConeVec {
        ConeVec {
            psd: vec![Matrix4::identity(); self.blocks.len()],
            lin: vec![1.0; self.lin.len()],
        }
    }
}

/// Cholesky of the reduced Newton matrix with a tiny regularization if needed; solves refined
/// iteratively against the unregularized matrix.
struct Reduced {
    h: DMatrix<f64>,
    chol: nalgebra::Cholesky<f64, nalgebra::Dyn>,
}

impl Reduced {
    fn new(h: DMatrix<f64>) -> Result<Reduced> {
        let scale = h.diagonal().amax().max(f64::MIN_POSITIVE);
        let mut delta = 0.0;
        for _ in 0..8 {
            let mut hr = h.clone();
            for i in 0..h.nrows() {
                hr[(i, i)] += delta;
            }
            if let Some(chol) = hr.cholesky() {
                return Ok(Reduced { h, chol });
            }
            delta = if delta == 0.0 {
                1e-14 * scale
            } else {
                delta * 100.0
            };
        }
        Err(Error::Numerical(
            "conic QP: the Newton system is not positive definite (P and the constraints leave \
             a direction free)"
                .into(),
        ))
    }

    fn solve(&self, rhs: &DVector<f64>) -> DVector<f64> {
        let mut x = self.chol.solve(rhs);
        for _ in 0..3 {
            let r = rhs - &self.h * &x;
            x += self.chol.solve(&r);
        }
        x
    }
}

/// X o Y = (X Y + Y X) / 2 (the Jordan product of the PSD cone).
fn jordan(x: &Matrix4<f64>, y: &Matrix4<f64>) -> Matrix4<f64> {
    (x * y + y * x) * 0.5
}

/// The inverse of lambda o: X with lambda o X = r (lambda diagonal).
fn lambda_div(lambda: &Vector4<f64>, r: &Matrix4<f64>) -> Matrix4<f64> {
    Matrix4::from_fn(|i, j| 2.0 * r[(i, j)] / (lambda[i] + lambda[j]))
}

fn psd_scaling(s: &Matrix4<f64>, z: &Matrix4<f64>) -> Result<PsdScaling> {
    let fail = || Error::Numerical("conic QP: an iterate left the PSD cone".into());
    let ls = s.cholesky().ok_or_else(fail)?.l();
    let lz = z.cholesky().ok_or_else(fail)?.l();
    let svd = (lz.transpose() * ls).svd(false, true);
    let vt = svd.v_t.ok_or_else(fail)?;
    let lambda = svd.singular_values;
    if lambda.iter().any(|l| l.is_nan() || *l <= 0.0) {
        return Err(fail());
    }
    let ls_inv = ls
        .solve_lower_triangular(&Matrix4::identity())
        .ok_or_else(fail)?;
    let sqrt = Matrix4::from_diagonal(&lambda.map(f64::sqrt));
    let rinv = sqrt * vt * ls_inv;
    let isqrt = Matrix4::from_diagonal(&lambda.map(|l| 1.0 / l.sqrt()));
    Ok(PsdScaling {
        r: ls * vt.transpose() * isqrt,
        m: rinv.transpose() * rinv,
        rinv,
        lambda,
    })
}

fn scaling(s: &ConeVec, z: &ConeVec) -> Result<Scaling> {
    let psd = s
        .psd
        .iter()
        .zip(&z.psd)
        .map(|(s, z)| psd_scaling(s, z))
        .collect::<Result<Vec<_>>>()?;
    Ok(Scaling {
        psd,
        w: s.lin
            .iter()
            .zip(&z.lin)
            .map(|(s, z)| (s / z).sqrt())
            .collect(),
        lambda: s
            .lin
            .iter()
            .zip(&z.lin)
            .map(|(s, z)| (s * z).sqrt())
            .collect(),
    })
}

impl Scaling {
    /// Take the step alpha d: the bounds directly, each PSD block in its scaled space
    /// (CVXOPT's update): s~ = lambda + alpha ds~ and z~ = lambda + alpha dz~ are well
    /// conditioned (lambda ~ sqrt(mu) 1 near the central path) where S and Z themselves are not;
    /// their scaling R^ gives R R^, and S = R lambda R^T, Z = R^-T lambda R^-1.
    fn step(&mut self, alpha: f64, d: &Direction, s: &mut ConeVec, z: &mut ConeVec) -> Result<()> {
        for (j, w) in self.psd.iter_mut().enumerate() {
            let lam = Matrix4::from_diagonal(&w.lambda);
            let st = lam + d.ds_t.psd[j] * alpha;
            let zt = lam + d.dz_t.psd[j] * alpha;
            let hat = psd_scaling(
                &((st + st.transpose()) * 0.5),
                &((zt + zt.transpose()) * 0.5),
            )?;
            w.r *= hat.r;
            w.rinv = hat.rinv * w.rinv;
            w.m = w.rinv.transpose() * w.rinv;
            w.lambda = hat.lambda;
            let lam = Matrix4::from_diagonal(&w.lambda);
            let (sm, zm) = (
                w.r * lam * w.r.transpose(),
                w.rinv.transpose() * lam * w.rinv,
            );
            s.psd[j] = (sm + sm.transpose()) * 0.5;
            z.psd[j] = (zm + zm.transpose()) * 0.5;
        }
        for i in 0..s.lin.len() {
            s.lin[i] += alpha * d.ds.lin[i];
            z.lin[i] += alpha * d.dz.lin[i];
            self.w[i] = (s.lin[i] / z.lin[i]).sqrt();
            self.lambda[i] = (s.lin[i] * z.lin[i]).sqrt();
        }
        Ok(())
    }

    /// W^-T u (scaled slack direction).
    fn inv_t(&self, u: &ConeVec) -> ConeVec {
        ConeVec {
            psd: self
                .psd
                .iter()
                .zip(&u.psd)
                .map(|(w, u)| w.rinv * u * w.rinv.transpose())
                .collect(),
            lin: self.w.iter().zip(&u.lin).map(|(w, u)| u / w).collect(),
        }
    }

    /// W^-1 u.
    fn inv(&self, u: &ConeVec) -> ConeVec {
        ConeVec {
            psd: self
                .psd
                .iter()
                .zip(&u.psd)
                .map(|(w, u)| w.rinv.transpose() * u * w.rinv)
                .collect(),
            lin: self.w.iter().zip(&u.lin).map(|(w, u)| u / w).collect(),
        }
    }

    /// lambda o lambda, the complementarity in the scaled space.
    fn lambda_sq(&self) -> ConeVec {
        ConeVec {
            psd: self
                .psd
                .iter()
                .map(|w| Matrix4::from_diagonal(&w.lambda.component_mul(&w.lambda)))
                .collect(),
            lin: self.lambda.iter().map(|l| l * l).collect(),
        }
    }

    /// lambda <> r: the solution X of lambda o X = r.
    fn lambda_div(&self, r: &ConeVec) -> ConeVec {
        ConeVec {
            psd: self
                .psd
                .iter()
                .zip(&r.psd)
                .map(|(w, r)| lambda_div(&w.lambda, r))
                .collect(),
            lin: self.lambda.iter().zip(&r.lin).map(|(l, r)| r / l).collect(),
        }
    }

    /// Largest step alpha with lambda + alpha d in the cone (infinite when unbounded).
    fn max_step(&self, d: &ConeVec) -> f64 {
        let mut alpha = f64::INFINITY;
        for (w, d) in self.psd.iter().zip(&d.psd) {
            let k = Matrix4::from_fn(|i, j| d[(i, j)] / (w.lambda[i] * w.lambda[j]).sqrt());
            let lo = k.symmetric_eigenvalues().min();
            if lo < 0.0 {
                alpha = alpha.min(-1.0 / lo);
            }
        }
        for (l, d) in self.lambda.iter().zip(&d.lin) {
            if *d < 0.0 {
                alpha = alpha.min(-l / d);
            }
        }
        alpha
    }

    /// P + L^T (W^T W)^-1 L.
    fn reduced_matrix(&self, eq: &Equilibrated) -> DMatrix<f64> {
        let mut h = eq.p.clone();
        for (b, w) in eq.blocks.iter().zip(&self.psd) {
            let mam: Vec<Matrix4<f64>> = b.terms.iter().map(|(_, a)| w.m * a * w.m).collect();
            for (k, (vk, _)) in b.terms.iter().enumerate() {
                for (vl, al) in &b.terms {
                    h[(*vk, *vl)] += mam[k].dot(al);
                }
            }
        }
        for (l, w) in eq.lin.iter().zip(&self.w) {
            h[(l.var, l.var)] += l.a * l.a / (w * w);
        }
        h
    }
}

/// A Newton direction: dx, ds, dz and the scaled ds~ = W^-T ds, dz~ = W dz.
struct Direction {
    dx: DVector<f64>,
    ds: ConeVec,
    dz: ConeVec,
    ds_t: ConeVec,
    dz_t: ConeVec,
}

/// Solve P dx - L^T dz = -r_d, ds - L dx = -r_p, ds~ + dz~ = lambda <> r_c.
fn direction(
    eq: &Equilibrated,
    w: &Scaling,
    h: &Reduced,
    r_d: &DVector<f64>,
    r_p: &ConeVec,
    r_c: &ConeVec,
) -> Direction {
    let lr = w.lambda_div(r_c);
    let mut t = lr.clone();
    t.axpy(1.0, &w.inv_t(r_p));
    let rhs = eq.adjoint(&w.inv(&t)) - r_d;
    let dx = h.solve(&rhs);
    let ds = eq.apply(&dx).sub(r_p);
    let ds_t = w.inv_t(&ds);
    let dz_t = lr.sub(&ds_t);
    let dz = w.inv(&dz_t);
    Direction {
        dx,
        ds,
        dz,
        ds_t,
        dz_t,
    }
}

/// Residuals and objectives of an iterate.
struct Status {
    r_d: DVector<f64>,
    r_p: ConeVec,
    primal: f64,
    dual: f64,
    gap: f64,
}

fn status(eq: &Equilibrated, x: &DVector<f64>, s: &ConeVec, z: &ConeVec) -> Status {
    let px = &eq.p * x;
    let ltz = eq.adjoint(z);
    let r_d = &px + &eq.q - &ltz;
    let c0 = eq.constant();
    let lx = eq.apply(x);
    let mut r_p = s.sub(&c0);
    r_p.axpy(-1.0, &lx);
    let xpx = x.dot(&px);
    let pobj = 0.5 * xpx + eq.q.dot(x);
    let dobj = -0.5 * xpx - c0.dot(z);
    let gap = s.dot(z).abs();
    let primal = r_p.norm_inf() / (1.0 + s.norm_inf().max(c0.norm_inf()).max(lx.norm_inf()));
    let dual = r_d.amax() / (1.0 + px.amax().max(eq.q.amax()).max(ltz.amax()));
    Status {
        gap: gap / pobj.abs().min(dobj.abs()).max(1.0),
        r_d,
        r_p,
        primal,
        dual,
    }
}

/// The starting point: x minimizing 1/2 x^T P x + q^T x + 1/2 ||C + L x||^2, s = C + L x moved
/// into the cone (smallest eigenvalue at least 1), z = the cone's identity.
fn start(eq: &Equilibrated) -> Result<(DVector<f64>, ConeVec, ConeVec)> {
    let n = eq.n();
    let ones = eq.identity();
    let w = Scaling {
        psd: (0..eq.blocks.len())
            .map(|_| PsdScaling {
                r: Matrix4::identity(),
                rinv: Matrix4::identity(),
                lambda: Vector4::repeat(1.0),
                m: Matrix4::identity(),
            })
            .collect(),
        w: vec![1.0; eq.lin.len()],
        lambda: vec![1.0; eq.lin.len()],
    };
    let h = Reduced::new(w.reduced_matrix(eq))?;
    let c0 = eq.constant();
    let x = h.solve(&(-(&eq.q + eq.adjoint(&c0))));
    let mut s = c0;
    s.axpy(1.0, &eq.apply(&x));
    for m in &mut s.psd {
        let lo = m.symmetric_eigenvalues().min();
        if lo < 1.0 {
            *m += Matrix4::identity() * (1.0 - lo);
        }
    }
    for v in &mut s.lin {
        *v = v.max(1.0);
    }
    debug_assert_eq!(x.len(), n);
    Ok((x, s, ones))
}

/// The minimizer of the objective alone (regularized by 1e-12 of P's largest diagonal entry
/// where P is singular), the origin of the centred problem; the start point where that is not
/// finite or far from it (an objective unbounded without the constraints).
fn unconstrained_minimizer(eq: &Equilibrated, start: &DVector<f64>) -> DVector<f64> {
    let n = eq.n();
    let scale = eq.p.diagonal().amax();
    if scale.is_nan() || scale <= 0.0 {
        return start.clone();
    }
    let mut h = eq.p.clone();
    for i in 0..n {
        h[(i, i)] += 1e-12 * scale;
    }
    let Ok(red) = Reduced::new(h) else {
        return start.clone();
    };
    let x = red.solve(&-&eq.q);
    let far = (&x - start).amax() > 1e6 * (1.0 + start.amax());
    if x.iter().all(|v| v.is_finite()) && !far {
        x
    } else {
        start.clone()
    }
}

/// Solve the problem (see the module's documentation for the method and the stopping rules).
///
/// The objective's origin is first the minimizer of the objective alone; if that run fails
/// (an origin far outside the cones can leave the iterates badly scaled), the problem is solved
/// again with the origin at the starting point, and that run's answer or error is returned.
pub fn solve(qp: &ConicQp, settings: &Settings) -> Result<ConicSolution> {
    solve_from(qp, settings, true).or_else(|_| solve_from(qp, settings, false))
}

fn solve_from(qp: &ConicQp, settings: &Settings, minimizer_origin: bool) -> Result<ConicSolution> {
    let mut eq = Equilibrated::new(qp)?;
    let (xs, mut s, mut z) = start(&eq)?;
    let x0 = if minimizer_origin {
        unconstrained_minimizer(&eq, &xs)
    } else {
        xs.clone()
    };
    eq.center(&x0);
    eq.scale_objective();
    let mut x = xs - &x0;
    let degree = eq.degree().max(1) as f64;
    let tol = settings.tolerance;
    let mut st = status(&eq, &x, &s, &z);
    let mut it = 0;
    let mut stalled = 0;
    let mut w = scaling(&s, &z)?;
    loop {
        if st.primal <= tol && st.dual <= tol && st.gap <= tol {
            let polished = polish::polish(&eq, &mut x, &mut s, &mut z, 10.0 * tol);
            if polished {
                st = status(&eq, &x, &s, &z);
            }
            return Ok(unscale(qp, &eq, &x, &s, &z, (it, polished), &st));
        }
        if it >= settings.max_iterations || stalled >= 5 {
            // a stalled or exhausted run: its answer stands if polishing finds a point
            // verified optimal, or with reduced accuracy if only the dual residual is above
            // the tolerance, below REDUCED_DUAL (rounding in the products of an
            // ill-conditioned P)
            let near = 1e3 * tol;
            if st.primal <= near && st.dual <= REDUCED_DUAL && st.gap <= near {
                let polished = polish::polish(&eq, &mut x, &mut s, &mut z, 10.0 * tol);
                if polished {
                    st = status(&eq, &x, &s, &z);
                    return Ok(unscale(qp, &eq, &x, &s, &z, (it, polished), &st));
                }
            }
            if st.primal <= tol && st.gap <= tol && st.dual <= REDUCED_DUAL {
                return Ok(unscale(qp, &eq, &x, &s, &z, (it, false), &st));
            }
            let why = if stalled >= 5 {
                format!("no progress after {it} iterations")
            } else {
                format!("not converged in {it} iterations")
            };
            return Err(Error::Numerical(format!(
                "the interior-point solver of the conic QP stopped: {why} (relative primal \
                 residual {:.1e}, dual residual {:.1e}, gap {:.1e}; tolerance {tol:.0e})",
                st.primal, st.dual, st.gap
            )));
        }
        it += 1;
        let h = Reduced::new(w.reduced_matrix(&eq))?;
        let mu = s.dot(&z) / degree;
        // predictor (affine scaling): r_c = -lambda o lambda
        let mut r_c = w.lambda_sq();
        r_c.psd.iter_mut().for_each(|m| *m = -*m);
        r_c.lin.iter_mut().for_each(|v| *v = -*v);
        let aff = direction(&eq, &w, &h, &st.r_d, &st.r_p, &r_c);
        let a_aff = w.max_step(&aff.ds_t).min(w.max_step(&aff.dz_t)).min(1.0);
        let sigma = (1.0 - a_aff).powi(3);
        // corrector: - ds~_a o dz~_a + sigma mu e
        let mut corr = r_c;
        for ((c, a), b) in corr.psd.iter_mut().zip(&aff.ds_t.psd).zip(&aff.dz_t.psd) {
            *c -= jordan(a, b);
            *c += Matrix4::identity() * (sigma * mu);
        }
        for ((c, a), b) in corr.lin.iter_mut().zip(&aff.ds_t.lin).zip(&aff.dz_t.lin) {
            *c += -a * b + sigma * mu;
        }
        let d = direction(&eq, &w, &h, &st.r_d, &st.r_p, &corr);
        let a_max = w.max_step(&d.ds_t).min(w.max_step(&d.dz_t));
        let alpha = (STEP_FRACTION * a_max).min(1.0);
        if alpha.is_nan() || alpha <= 1e-10 || d.dx.iter().any(|v| !v.is_finite()) {
            stalled = 5;
            continue;
        }
        x += &d.dx * alpha;
        w.step(alpha, &d, &mut s, &mut z)?;
        let previous = (st.primal, st.dual, st.gap);
        st = status(&eq, &x, &s, &z);
        // stalled: primal residual and gap met, the dual residual no longer decreasing
        let dual_limited = st.primal <= tol && st.gap <= tol;
        let better = !dual_limited || st.dual < 0.9 * previous.1;
        stalled = if better { 0 } else { stalled + 1 };
    }
}

/// The solution in the original variables and multipliers.
fn unscale(
    qp: &ConicQp,
    eq: &Equilibrated,
    x: &DVector<f64>,
    s: &ConeVec,
    z: &ConeVec,
    (iterations, polished): (usize, bool),
    st: &Status,
) -> ConicSolution {
    let xo = (&eq.origin + x).component_mul(&eq.d);
    let nl = qp.lower.len();
    let lin_dual: Vec<f64> = z
        .lin
        .iter()
        .zip(&eq.e_lin)
        .map(|(z, e)| z * e / eq.c)
        .collect();
    ConicSolution {
        objective: 0.5 * xo.dot(&(&qp.p * &xo)) + qp.q.dot(&xo),
        x: xo.iter().copied().collect(),
        psd_slack: s.psd.iter().zip(&eq.e_psd).map(|(m, e)| m / *e).collect(),
        psd_dual: z
            .psd
            .iter()
            .zip(&eq.e_psd)
            .map(|(m, e)| m * (*e / eq.c))
            .collect(),
        lower_dual: lin_dual[..nl].to_vec(),
        upper_dual: lin_dual[nl..].to_vec(),
        iterations,
        polished,
        primal_residual: st.primal,
        dual_residual: st.dual,
        gap: st.gap,
    }
}
