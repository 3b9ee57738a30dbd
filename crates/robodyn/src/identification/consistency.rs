//! Physically consistent standard parameters (Sousa & Cortesão 2014, Wensing, Kim & Slotine
//! 2017): a link's standard parameters are those of a rigid body with a non-negative mass
//! density iff its pseudo-inertia matrix
//!
//! ```text
//!  J_j = [ Sigma  h ]      Sigma = tr(I)/2 1 - I,  h = (MX, MY, MZ),  m = M,
//!        [ h^T    m ]
//! ```
//!
//! (I the inertia tensor about O_j in R_j, Sigma = int r r^T dm) is positive semidefinite; this
//! implies m >= 0 and the triangle inequalities of the principal moments. With rotor inertias
//! and friction coefficients >= 0 these are linear matrix inequalities in K, solved as a
//! semidefinite program with Clarabel's PSD cone:
//!
//! [`consistent_parameters`]: identification under the constraints,
//! min ||Y - W x(K, offsets)||^2_weights / sigma^2 + eps ||K - K0||_S^2 — equivalently the
//! consistent set nearest to the unconstrained estimate in the metric of its covariance. K0 are
//! the robot file's values and S a per-parameter scale: eps = 1e-6 only chooses among the K
//! with the same base parameters (moving K by one scale unit costs as much as moving the
//! estimate by 1e-3 standard deviations).

use super::conic;
use super::estimators::LsSolution;
use super::model_access::ModelAccess;
use super::parameters::ParameterModel;
use super::Consistent;
use crate::algorithms::regressor::PARAMS_PER_LINK;
use crate::error::{Error, Result};
use crate::model::param::{FS, FV, IA};
use faer::Mat;
use nalgebra::{DMatrix, DVector, Matrix4};

/// Weight of the pull toward the robot file's parameters (relative, per scaled parameter).
const PRIOR_WEIGHT: f64 = 1e-6;

/// A consistent solution and the full identified vector (offsets included).
#[derive(Clone, Debug)]
pub struct ConsistentSolution {
    /// The consistent parameters and their checks.
    pub result: Consistent,
    /// The identified vector (base parameters, motor parameters, offsets) they give.
    pub x_full: Vec<f64>,
}

/// The decision variables: the 10 inertial parameters of every link, the drive parameters the
/// identified vector uses, and the offsets.
struct Variables {
    /// Index in K of each standard variable.
    standard: Vec<usize>,
    /// Positions (in `standard`) of the drive parameters (>= 0).
    drives: Vec<usize>,
    /// Parameter index (in x) of each offset variable.
    offsets: Vec<usize>,
    nl: usize,
}

impl Variables {
    fn new(model: &ParameterModel) -> Variables {
        let nl = model.standard_count / PARAMS_PER_LINK;
        let mut standard: Vec<usize> = (0..nl)
            .flat_map(|j| (0..10).map(move |p| PARAMS_PER_LINK * j + p))
            .collect();
        let mut drives = Vec::new();
        let mut used: Vec<usize> = model
            .map
            .iter()
            .flatten()
            .map(|(i, _)| *i)
            .filter(|i| matches!(i % PARAMS_PER_LINK, IA | FS | FV))
            .collect();
        used.sort_unstable();
        used.dedup();
        for i in used {
            drives.push(standard.len());
            standard.push(i);
        }
        let offsets = model
            .params
            .iter()
            .enumerate()
            .filter(|(_, p)| p.kind.is_free())
            .map(|(i, _)| i)
            .collect();
        Variables {
            standard,
            drives,
            offsets,
            nl,
        }
    }

    fn count(&self) -> usize {
        self.standard.len() + self.offsets.len()
    }

    /// E (p x count): x = E v.
    fn x_map(&self, model: &ParameterModel) -> Mat<f64> {
        let p = model.count();
        let mut e = Mat::<f64>::zeros(p, self.count());
        for (r, terms) in model.map.iter().enumerate() {
            for &(i, c) in terms {
                let v = self
                    .standard
                    .iter()
                    .position(|&s| s == i)
                    .expect("every mapped standard parameter is a variable");
                e[(r, v)] += c;
            }
        }
        for (k, &r) in self.offsets.iter().enumerate() {
            e[(r, self.standard.len() + k)] = 1.0;
        }
        e
    }

    /// Full standard vector from the variables.
    fn standard_vector(&self, v: &[f64], count: usize) -> Vec<f64> {
        let mut k = vec![0.0; count];
        for (s, &i) in self.standard.iter().enumerate() {
            k[i] = v[s];
        }
        k
    }
}

/// Weight of each standard variable in the prior term: 1 / s^2 with s the magnitude of its kind
/// of parameter in the robot file (its own value, at least 1e-3 of the largest of that kind);
/// 0 for a kind the file leaves at zero on every link (no prior: e.g. friction to identify).
fn prior_weights(vars: &Variables, prior: &[f64]) -> Vec<f64> {
    let kind_max = |p: usize| -> f64 {
        (0..vars.nl)
            .map(|j| prior[PARAMS_PER_LINK * j + p].abs())
            .fold(0.0, f64::max)
    };
    vars.standard
        .iter()
        .map(|&i| {
            let m = kind_max(i % PARAMS_PER_LINK);
            if m > 0.0 {
                let s = prior[i].abs().max(1e-3 * m);
                1.0 / (s * s)
            } else {
                0.0
            }
        })
        .collect()
}

/// Pseudo-inertia of link j (0-based) from its 10 inertial parameters.
pub fn pseudo_inertia(k: &[f64]) -> Matrix4<f64> {
    let [xx, xy, xz, yy, yz, zz, mx, my, mz, m] =
        [k[0], k[1], k[2], k[3], k[4], k[5], k[6], k[7], k[8], k[9]];
    let t = 0.5 * (xx + yy + zz);
    Matrix4::new(
        t - xx,
        -xy,
        -xz,
        mx, //
        -xy,
        t - yy,
        -yz,
        my, //
        -xz,
        -yz,
        t - zz,
        mz, //
        mx,
        my,
        mz,
        m,
    )
}

/// Smallest eigenvalue of the pseudo-inertia matrices of all links.
pub fn min_pseudo_inertia_eigenvalue(k: &[f64]) -> f64 {
    (0..k.len() / PARAMS_PER_LINK)
        .map(|j| {
            pseudo_inertia(&k[PARAMS_PER_LINK * j..PARAMS_PER_LINK * j + 10])
                .symmetric_eigenvalues()
                .min()
        })
        .fold(f64::INFINITY, f64::min)
}

/// The solver of the semidefinite program.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Solver {
    /// robodyn's interior-point method ([`super::conic`]), pure Rust: the default.
    #[default]
    InteriorPoint,
    /// Clarabel's PSD cone (feature `sdp`, the system's LAPACK): a cross-check.
    #[cfg(feature = "sdp")]
    Clarabel,
}

/// Solve min 1/2 v^T P v + q^T v subject to the consistency cones; returns v and a description
/// of the solver's end.
fn solve(
    vars: &Variables,
    p_dense: &Mat<f64>,
    q: &[f64],
    solver: Solver,
) -> Result<(Vec<f64>, String)> {
    match solver {
        Solver::InteriorPoint => solve_interior_point(vars, p_dense, q),
        #[cfg(feature = "sdp")]
        Solver::Clarabel => solve_sdp(vars, p_dense, q),
    }
}

/// Pseudo-inertia of the unit vector e_l of a link's 10 inertial parameters: J is linear in
/// them, J = sum_l k_l pseudo_inertia(e_l).
fn pseudo_inertia_basis() -> [Matrix4<f64>; 10] {
    std::array::from_fn(|l| {
        let mut e = [0.0; 10];
        e[l] = 1.0;
        pseudo_inertia(&e)
    })
}

/// The semidefinite program as a conic QP: one 4x4 PSD block per link, drives >= 0.
fn conic_problem(vars: &Variables, p_dense: &Mat<f64>, q: &[f64]) -> conic::ConicQp {
    let nv = vars.count();
    let basis = pseudo_inertia_basis();
    conic::ConicQp {
        p: DMatrix::from_fn(nv, nv, |r, c| p_dense[(r, c)]),
        q: DVector::from_column_slice(q),
        psd: (0..vars.nl)
            .map(|j| conic::PsdBlock {
                constant: Matrix4::zeros(),
                terms: (0..10).map(|l| (10 * j + l, basis[l])).collect(),
            })
            .collect(),
        lower: vars.drives.iter().map(|&d| (d, 0.0)).collect(),
        upper: Vec::new(),
    }
}

fn solve_interior_point(
    vars: &Variables,
    p_dense: &Mat<f64>,
    q: &[f64],
) -> Result<(Vec<f64>, String)> {
    let sol = conic::solve(
        &conic_problem(vars, p_dense, q),
        &conic::Settings::default(),
    )
    .map_err(|e| {
        Error::Numerical(format!(
            "the SDP of the physically consistent parameters was not solved ({e}): no \
                 consistent parameters are reported"
        ))
    })?;
    let mut v = sol.x;
    let moved = make_consistent(vars, &mut v);
    let mut text = format!(
        "interior point: solved in {} iterations{} (relative residuals {:.0e} primal, {:.0e} \
         dual, gap {:.0e})",
        sol.iterations,
        if sol.polished {
            ", polished on the active face"
        } else {
            ""
        },
        sol.primal_residual,
        sol.dual_residual,
        sol.gap
    );
    if sol.dual_residual > conic::Settings::default().tolerance {
        text.push_str(" (reduced accuracy: the dual residual did not reach 1e-10)");
    }
    if moved > 0.0 {
        text.push_str(&format!(
            "; rounding-level violations projected onto the constraints (largest change {moved:.1e})"
        ));
    }
    Ok((v, text))
}

/// Make the solver's point satisfy the constraints exactly: a pseudo-inertia with a negative
/// eigenvalue (a rounding-level violation at the boundary) is replaced by its nearest PSD
/// matrix (negative eigenvalues set to zero, then raised until the computed smallest
/// eigenvalue is not negative), a negative drive parameter by 0. Returns the largest change.
fn make_consistent(vars: &Variables, v: &mut [f64]) -> f64 {
    let mut moved = 0.0f64;
    for j in 0..vars.nl {
        let k = &mut v[10 * j..10 * j + 10];
        let mut shift = 0.0;
        for _ in 0..8 {
            // checked on the parameters themselves, with the eigenvalues every check computes
            // (`min_pseudo_inertia_eigenvalue`): the round trip J -> K -> J rounds too
            let jm = pseudo_inertia(k);
            if jm.symmetric_eigenvalues().min() >= 0.0 {
                break;
            }
            let eig = jm.symmetric_eigen();
            let clipped = eig.eigenvalues.map(|l| l.max(shift));
            let jc =
                eig.eigenvectors * Matrix4::from_diagonal(&clipped) * eig.eigenvectors.transpose();
            for (a, b) in k
                .iter_mut()
                .zip(from_pseudo_inertia(&((jc + jc.transpose()) * 0.5)))
            {
                moved = moved.max((*a - b).abs());
                *a = b;
            }
            shift = if shift == 0.0 {
                4.0 * f64::EPSILON * jm.amax()
            } else {
                2.0 * shift
            };
        }
    }
    for &d in &vars.drives {
        if v[d] < 0.0 {
            moved = moved.max(-v[d]);
            v[d] = 0.0;
        }
    }
    moved
}

/// The 10 inertial parameters (XX XY XZ YY YZ ZZ MX MY MZ M) of a pseudo-inertia matrix: the
/// inverse of [`pseudo_inertia`] (I = tr(Sigma) 1 - Sigma).
pub fn from_pseudo_inertia(j: &Matrix4<f64>) -> [f64; 10] {
    let t = j[(0, 0)] + j[(1, 1)] + j[(2, 2)];
    [
        t - j[(0, 0)],
        -j[(0, 1)],
        -j[(0, 2)],
        t - j[(1, 1)],
        -j[(1, 2)],
        t - j[(2, 2)],
        j[(0, 3)],
        j[(1, 3)],
        j[(2, 3)],
        j[(3, 3)],
    ]
}

#[cfg(feature = "sdp")]
fn solve_sdp(vars: &Variables, p_dense: &Mat<f64>, q: &[f64]) -> Result<(Vec<f64>, String)> {
    use clarabel::solver::{DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus};
    let nv = vars.count();
    let p = upper_csc(p_dense);
    let (rows, cones) = sdp_constraints(vars);
    let a = rows_csc(&rows, nv);
    // origin at the unconstrained minimizer v0 (as the interior-point solver): v = v0 + u,
    // q + P v0, s = J(v0) + J(u) = b - A u with b = -A v0
    let mut pr = DMatrix::from_fn(nv, nv, |r, c| 0.5 * (p_dense[(r, c)] + p_dense[(c, r)]));
    let reg = 1e-12 * pr.diagonal().amax();
    for i in 0..nv {
        pr[(i, i)] += reg;
    }
    let v0 = pr
        .cholesky()
        .map(|c| c.solve(&-DVector::from_column_slice(q)))
        .filter(|v| v.iter().all(|x| x.is_finite()))
        .unwrap_or_else(|| DVector::zeros(nv));
    let qc: Vec<f64> = (0..nv)
        .map(|r| q[r] + (0..nv).map(|c| p_dense[(r, c)] * v0[c]).sum::<f64>())
        .collect();
    let b: Vec<f64> = rows
        .iter()
        .map(|t| -t.iter().map(|&(c, v)| v * v0[c]).sum::<f64>())
        .collect();
    let settings = DefaultSettingsBuilder::default()
        .verbose(false)
        .max_iter(400)
        .tol_gap_abs(1e-11)
        .tol_gap_rel(1e-11)
        .tol_feas(1e-11)
        .tol_ktratio(1e-9)
        .build()
        .map_err(|e| Error::Numerical(format!("SDP settings: {e:?}")))?;
    let mut solver = DefaultSolver::new(&p, &qc, &a, &b, &cones, settings)
        .map_err(|e| Error::Numerical(format!("the SDP could not be set up: {e:?}")))?;
    solver.solve();
    let s = &solver.solution;
    let status = s.status;
    let text = format!("Clarabel: {status:?} in {} iterations", s.iterations);
    let v: Vec<f64> = s.x.iter().zip(v0.iter()).map(|(u, v0)| u + v0).collect();
    match status {
        SolverStatus::Solved => Ok((v, text)),
        SolverStatus::AlmostSolved => Ok((v, format!("{text} (reduced accuracy)"))),
        other => Err(Error::Numerical(format!(
            "the SDP of the physically consistent parameters did not converge ({other:?} after {} \
             iterations): no consistent parameters are reported",
            s.iterations
        ))),
    }
}

/// The upper triangle of the symmetric part of `p_dense`, in compressed sparse columns.
#[cfg(feature = "sdp")]
fn upper_csc(p_dense: &Mat<f64>) -> clarabel::algebra::CscMatrix<f64> {
    let nv = p_dense.ncols();
    // P: upper triangle, CSC
    let mut colptr = vec![0usize];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for c in 0..nv {
        for r in 0..=c {
            let v = 0.5 * (p_dense[(r, c)] + p_dense[(c, r)]);
            if v != 0.0 {
                rowval.push(r);
                nzval.push(v);
            }
        }
        colptr.push(rowval.len());
    }
    clarabel::algebra::CscMatrix::new(nv, nv, colptr, rowval, nzval)
}

/// The rows of A (s = b - A v) and their cones: per link svec(J_j) in the PSD cone, the drive
/// parameters >= 0.
#[cfg(feature = "sdp")]
#[allow(clippy::type_complexity)]
fn sdp_constraints(
    vars: &Variables,
) -> (
    Vec<Vec<(usize, f64)>>,
    Vec<clarabel::solver::SupportedConeT<f64>>,
) {
    use clarabel::solver::{NonnegativeConeT, PSDTriangleConeT, SupportedConeT};
    let sq2 = std::f64::consts::SQRT_2;
    // svec of the 4x4 upper triangle, column-major: (0,0) (0,1) (1,1) (0,2) (1,2) (2,2) (0,3)...
    // J as linear combinations of XX XY XZ YY YZ ZZ MX MY MZ M (local indices 0..10)
    let entry = |r: usize, c: usize| -> Vec<(usize, f64)> {
        match (r, c) {
            (0, 0) => vec![(0, -0.5), (3, 0.5), (5, 0.5)],
            (1, 1) => vec![(0, 0.5), (3, -0.5), (5, 0.5)],
            (2, 2) => vec![(0, 0.5), (3, 0.5), (5, -0.5)],
            (0, 1) => vec![(1, -1.0)],
            (0, 2) => vec![(2, -1.0)],
            (1, 2) => vec![(4, -1.0)],
            (0, 3) => vec![(6, 1.0)],
            (1, 3) => vec![(7, 1.0)],
            (2, 3) => vec![(8, 1.0)],
            (3, 3) => vec![(9, 1.0)],
            _ => unreachable!(),
        }
    };
    let mut rows: Vec<Vec<(usize, f64)>> = Vec::new();
    let mut cones: Vec<SupportedConeT<f64>> = Vec::new();
    for j in 0..vars.nl {
        for c in 0..4 {
            for r in 0..=c {
                let scale = if r == c { 1.0 } else { sq2 };
                // A = -dJ/dv (s = b - A v = J with b = 0)
                rows.push(
                    entry(r, c)
                        .into_iter()
                        .map(|(l, v)| (10 * j + l, -scale * v))
                        .collect(),
                );
            }
        }
        cones.push(PSDTriangleConeT(4));
    }
    for &d in &vars.drives {
        rows.push(vec![(d, -1.0)]);
    }
    if !vars.drives.is_empty() {
        cones.push(NonnegativeConeT(vars.drives.len()));
    }
    (rows, cones)
}

/// The matrix of sparse `rows` (column, value) with `nv` columns, in compressed sparse columns.
#[cfg(feature = "sdp")]
fn rows_csc(rows: &[Vec<(usize, f64)>], nv: usize) -> clarabel::algebra::CscMatrix<f64> {
    let m = rows.len();
    let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); nv];
    for (r, terms) in rows.iter().enumerate() {
        for &(c, v) in terms {
            cols[c].push((r, v));
        }
    }
    let mut colptr = vec![0usize];
    let mut rowval = Vec::new();
    let mut nzval = Vec::new();
    for col in &mut cols {
        col.sort_by_key(|e| e.0);
        for &(r, v) in col.iter() {
            rowval.push(r);
            nzval.push(v);
        }
        colptr.push(rowval.len());
    }
    clarabel::algebra::CscMatrix::new(m, nv, colptr, rowval, nzval)
}

/// Add eps sum_i ((v_i - K0_i) / s_i)^2 to (P, q) (with 1/2 v^T P v + q^T v conventions).
fn add_prior(vars: &Variables, prior: &[f64], weight: f64, p: &mut Mat<f64>, q: &mut [f64]) {
    let weights = prior_weights(vars, prior);
    for (s, &i) in vars.standard.iter().enumerate() {
        let w = weight * weights[s];
        p[(s, s)] += 2.0 * w;
        q[s] -= 2.0 * w * prior[i];
    }
}

fn finish(
    access: &ModelAccess,
    model: &ParameterModel,
    vars: &Variables,
    v: &[f64],
    estimate: &LsSolution,
    solver: String,
) -> Result<ConsistentSolution> {
    let e = vars.x_map(model);
    let p = model.count();
    let x_full: Vec<f64> = (0..p)
        .map(|r| (0..vars.count()).map(|c| e[(r, c)] * v[c]).sum())
        .collect();
    let standard = vars.standard_vector(v, model.standard_count);
    let deviation: Vec<f64> = (0..p)
        .map(|r| (x_full[r] - estimate.x[r]) / estimate.std[r].max(f64::MIN_POSITIVE))
        .collect();
    let max_deviation = deviation.iter().map(|d| d.abs()).fold(0.0, f64::max);
    let min_inertia = access.min_inertia_eigenvalue(&model.joint_side_drives(&standard), 30, 7)?;
    Ok(ConsistentSolution {
        result: Consistent {
            min_pseudo_inertia_eigenvalue: min_pseudo_inertia_eigenvalue(&standard),
            min_inertia_eigenvalue: min_inertia,
            x: x_full.clone(),
            standard,
            deviation,
            max_deviation,
            distance2: 0.0,
            solver,
        },
        x_full,
    })
}

/// Identification under the constraints: min ||T_w [x(v); -1]||^2 (the weighted rows of the
/// fit) over consistent standard parameters and the offsets. Since
/// ||T_w [x; -1]||^2 = ||T_w [x_hat; -1]||^2 + (x - x_hat)^T W_w^T W_w (x - x_hat), this is
/// also the consistent set nearest to the unconstrained estimate x_hat in the metric of its
/// covariance sigma^2 (W_w^T W_w)^-1 (the Mahalanobis distance, correlations included).
pub fn consistent_parameters(
    access: &ModelAccess,
    model: &ParameterModel,
    tw: &Mat<f64>,
    estimate: &LsSolution,
    solver: Solver,
) -> Result<ConsistentSolution> {
    let vars = Variables::new(model);
    let e = vars.x_map(model);
    let nv = vars.count();
    let p = model.count();
    // ||R x - z||^2 with R, z from T_w; x = E v
    let re = Mat::from_fn(p + 1, nv, |i, c| {
        (0..p).map(|k| tw[(i, k)] * e[(k, c)]).sum::<f64>()
    });
    // in units of the residual variance, so that one standard deviation costs about 1 (a
    // noise-free fit has sigma ~ 0: floored at 1e-7 of the RMS torque)
    let floor = 1e-14 * super::estimators::output_sq(tw) / estimate.rows as f64;
    let s2 = estimate.sigma2.max(floor).max(f64::MIN_POSITIVE);
    let mut pm = Mat::<f64>::zeros(nv, nv);
    let mut q = vec![0.0; nv];
    for a in 0..nv {
        for b in 0..nv {
            pm[(a, b)] = 2.0 * (0..=p).map(|i| re[(i, a)] * re[(i, b)]).sum::<f64>() / s2;
        }
        q[a] = -2.0 * (0..=p).map(|i| re[(i, a)] * tw[(i, p)]).sum::<f64>() / s2;
    }
    add_prior(
        &vars,
        &access.standard_parameters(),
        PRIOR_WEIGHT,
        &mut pm,
        &mut q,
    );
    let (v, text) = solve(&vars, &pm, &q, solver)?;
    let mut sol = finish(access, model, &vars, &v, estimate, text)?;
    // increase of the weighted residual, in units of sigma^2: the squared Mahalanobis distance
    let base = super::estimators::residual_sq(tw, &estimate.x);
    sol.result.distance2 = (super::estimators::residual_sq(tw, &sol.x_full) - base).max(0.0) / s2;
    Ok(sol)
}
