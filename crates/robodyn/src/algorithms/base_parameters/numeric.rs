//! Numerical method for the base parameters (appendix 5 of the book, [Gautier 91]; §10.3.4 for
//! closed chains).
//!
//! 1. Sample `s` random consistent states (q_tr, qd_tr, qdd_tr) with their G = dq_tr/dq_a
//!    ([`Sampler`]; identity for a tree) and stack the closed-chain regressors G^T Phi into the
//!    observation matrix W (s N rows, one column per selected standard parameter).
//!    W is one dense faer matrix whose size is checked before it is allocated
//!    ([`MAX_OBSERVATION_BYTES`]); it is dropped once its R factor is computed.
//! 2. Parameters with no effect: columns with ||W_c|| <= [`NO_EFFECT_TOLERANCE`] max_c ||W_c||.
//! 3. The remaining columns are scaled to unit norm (so the tolerance does not depend on units);
//!    tol = [`RANK_TOLERANCE`] * sigma_max (sigma_max from the SVD of R for up to
//!    [`SVD_COLUMNS`] columns, by power iteration on R beyond).
//! 4. Which parameters are kept: an *unpivoted* Householder QR (faer) of the scaled W in the column
//!    order of K (link 1 first, XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV in each link). |R_kk| is the
//!    distance of column k from the span of the columns before it, so a column is kept when
//!    |R_kk| > tol and grouped otherwise: a dependent group keeps its earliest members. This order
//!    matches the symbolic rules: Theorem 10.1 groups YY_j into XX_j (XX first) and MZ_j, M_j into
//!    the parameters of a(j) < j (lower links first); Table 10.1 keeps MX_j/MY_j over MZ_j;
//!    parallelogram loops group the link of larger number into the smaller one; a rotor inertia
//!    IA_j comes after the ZZ it groups into.
//! 5. W = [W1 W2] (kept, grouped): a QR of R with its columns in the order [kept, grouped] gives
//!    [[R11, R12], [0, R22]]; beta = R11^-1 R12 solves W1 beta = W2 in the least-squares sense,
//!    so Phi K = Phi_1 (K1 + beta K2), i.e. K_base = K1 + beta K2. The rank is certified: the
//!    smallest singular value of R11 (inverse iteration) must exceed tol and ||R22||_F (what the
//!    kept columns leave of the grouped ones) must not; otherwise the samples are
//!    ill-conditioned and an error is returned, never a count.
//!
//! Absent parameters (a literal 0 in a SYMORO file, [`ParameterSelection::absent`]) are not in
//! K, but as in SYMORO a base parameter may take their place (MXR2 = d3 M3 when MX2 is written
//! 0): their columns are candidates when they lie in the span of the existing ones (distance
//! <= tol), so both methods name the same base parameters.

use super::super::regressor::{
    closed_chain_regressor, floating_tree_regressor, parameter_count, tree_regressor,
    FloatingBaseState, ParameterSelection, PARAMS_PER_LINK,
};
use super::names::ParameterNames;
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Robot;
use crate::report::number::{format_number, significant};
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::{Mat, MatRef, Par};
use nalgebra::DMatrix;
use rand::{Rng, RngCore};

/// A column whose norm is at most this fraction of the largest column norm of W is a parameter
/// with no effect.
pub const NO_EFFECT_TOLERANCE: f64 = 1e-10;

/// Relative rank tolerance on the unit-column W: tol = RANK_TOLERANCE * sigma_max. Rounding
/// leaves dependent columns at 1e-14..1e-12 (the textbook max(m, n) eps sigma_max proved too
/// tight on random trees), while independent columns of randomly sampled states are many orders
/// above 1e-9.
pub const RANK_TOLERANCE: f64 = 1e-9;

/// Largest observation matrix W the numerical method allocates (1 GiB: about 10,000 columns,
/// some 780 links with every drive parameter); beyond, it returns an error before allocating.
/// The peak memory is about 2.5 times W (W, then its R factor and one reordered copy).
pub const MAX_OBSERVATION_BYTES: usize = 1 << 30;

/// Up to this many columns the singular values of W are computed (SVD of R) and reported;
/// beyond, sigma_max comes from power iteration on R and `singular_values` is empty.
pub const SVD_COLUMNS: usize = 800;

/// A consistent state of the equivalent tree with the Jacobian G = dq_tr/dq_a.
#[derive(Clone, Debug)]
pub struct ConsistentSample {
    /// Tree joint positions q_tr, NL entries (rad or m; fixed frames 0).
    pub q: Vec<f64>,
    /// Tree joint velocities, NL entries (rad/s or m/s).
    pub qd: Vec<f64>,
    /// Tree joint accelerations, NL entries (rad/s² or m/s²).
    pub qdd: Vec<f64>,
    /// G (NL x N); `None` means identity (tree).
    pub g: Option<DMatrix<f64>>,
}

/// Produces random consistent states: random for a tree, through the loop-closure equations for a
/// closed chain.
pub trait Sampler {
    /// One random consistent state of `robot` (its equivalent tree) drawn from `rng`.
    fn sample(&mut self, robot: &Robot, rng: &mut dyn RngCore) -> Result<ConsistentSample>;
}

/// Random states of a tree: q in [-pi, pi], qd in [-2, 2], qdd in [-5, 5] (G = I).
#[derive(Clone, Copy, Debug, Default)]
pub struct TreeSampler;

impl Sampler for TreeSampler {
    fn sample(&mut self, robot: &Robot, rng: &mut dyn RngCore) -> Result<ConsistentSample> {
        if !robot.is_tree() {
            return Err(Error::Input(format!(
                "{} has {} closed loop(s): random independent joint values are not consistent; \
                 use a loop-closure sampler",
                robot.name(),
                robot.n_loops()
            )));
        }
        let n = robot.nl();
        let mut v = |s: f64| -> Vec<f64> { (0..n).map(|_| rng.random_range(-s..s)).collect() };
        Ok(ConsistentSample {
            q: v(std::f64::consts::PI),
            qd: v(2.0),
            qdd: v(5.0),
            g: None,
        })
    }
}

/// Options of the numerical method.
#[derive(Clone, Debug)]
pub struct NumericOptions {
    /// The standard parameters (columns of W): rotor inertias, friction, absent parameters.
    pub selection: ParameterSelection,
    /// Number of sampled states (default: 3 rows per column up to 3000 rows, then 1.25 rows
    /// per column; at least 20 samples).
    pub samples: Option<usize>,
    /// Seed of the random states (the result is a function of it).
    pub seed: u64,
}

impl NumericOptions {
    /// The options for `selection` with the default number of samples and seed 1. (There is no
    /// `Default`: the selection is a robot's.)
    pub fn new(selection: ParameterSelection) -> NumericOptions {
        NumericOptions {
            selection,
            samples: None,
            seed: 1,
        }
    }
}

/// Result of the numerical method. Parameter indices are indices in K (13 per link).
#[derive(Clone, Debug)]
pub struct NumericBase {
    /// The selected standard parameters that exist (columns of W), in K order.
    pub columns: Vec<usize>,
    /// Base parameters (kept, independent columns W1), in K order. An absent parameter (see
    /// `absent`) can be one: its value is then its grouped parameters alone.
    pub base: Vec<usize>,
    /// Grouped parameters (dependent columns W2), in K order.
    pub grouped: Vec<usize>,
    /// Parameters with no effect (zero columns).
    pub no_effect: Vec<usize>,
    /// Parameters of the selection that do not exist (literal 0 in a SYMORO file).
    pub absent: Vec<usize>,
    /// K_base = K1 + beta K2 (base.len() x grouped.len()).
    pub beta: DMatrix<f64>,
    /// Numerical rank tolerance used on the scaled W.
    pub tolerance: f64,
    /// Singular values of the scaled W (non-zero columns), largest first; empty above
    /// [`SVD_COLUMNS`] columns.
    pub singular_values: Vec<f64>,
    /// Smallest singular value of the kept columns W1 (scaled): with `residual_grouped`, the
    /// rank certificate sigma_min > tolerance >= residual.
    pub sigma_min_kept: f64,
    /// Largest residual of the grouped columns after the kept ones (||R22||_F, scaled).
    pub residual_grouped: f64,
    /// Rows of W.
    pub rows: usize,
}

impl NumericBase {
    /// Number of base parameters.
    pub fn count(&self) -> usize {
        self.base.len()
    }

    /// Base parameter values K1 + beta K2 for a full standard vector K (13 per link; absent
    /// parameters count as 0).
    pub fn base_values(&self, k: &[f64]) -> Vec<f64> {
        let value = |i: usize| {
            if self.absent.contains(&i) {
                0.0
            } else {
                k[i]
            }
        };
        self.base
            .iter()
            .enumerate()
            .map(|(r, &b)| {
                value(b)
                    + self
                        .grouped
                        .iter()
                        .enumerate()
                        .map(|(c, &g)| self.beta[(r, c)] * k[g])
                        .sum::<f64>()
            })
            .collect()
    }

    /// Whether base parameter number `r` is a combination (grouped parameters, or it takes the
    /// place of an absent parameter).
    pub fn is_regrouped(&self, r: usize) -> bool {
        self.absent.contains(&self.base[r])
            || (0..self.grouped.len()).any(|c| self.beta[(r, c)].abs() > 1e-9)
    }

    /// Grouping equation of base parameter number `r` as text, e.g. `XX2 - YY2 + 9/25*M3`, in
    /// `names`. Coefficients are shown as short rationals when they are (display only).
    pub fn equation(&self, r: usize, names: &ParameterNames) -> String {
        let b = self.base[r];
        let terms: Vec<(f64, usize)> = self
            .grouped
            .iter()
            .enumerate()
            .map(|(c, &g)| (self.beta[(r, c)], g))
            .filter(|(v, _)| v.abs() >= 1e-9)
            .collect();
        let magnitudes: Vec<f64> = terms.iter().map(|(v, _)| v.abs()).collect();
        let mut s = if self.absent.contains(&b) {
            String::new()
        } else {
            names.name(b).to_string()
        };
        for ((v, g), mag) in terms.iter().zip(format_coefficients(&magnitudes)) {
            let term = if mag == "1" {
                names.name(*g).to_string()
            } else {
                format!("{mag}*{}", names.name(*g))
            };
            s = match (s.is_empty(), *v < 0.0) {
                (true, false) => term,
                (true, true) => format!("-{term}"),
                (false, neg) => format!("{s} {} {term}", if neg { "-" } else { "+" }),
            };
        }
        if s.is_empty() {
            "0".into()
        } else {
            s
        }
    }
}

/// A coefficient for display, alone: [`format_coefficients`] of one value.
pub fn format_coefficient(x: f64) -> String {
    format_coefficients(&[x]).remove(0)
}

/// The coefficients of one grouping equation for display, in one style for the whole line
/// (issue 30 found `9/40*MZ3` next to `0.007875*M3`):
///
/// - decimals by default: a coefficient within 1e-9 of a fraction p/q (q <= 64) with a finite
///   decimal expansion is written as that decimal, exactly (`9/40` is `0.225`, the geometry's own
///   number), any other one with 12 significant digits (the rounding of the sums that made it);
/// - fractions when every coefficient of the line is within 1e-9 of a fraction with q <= 64
///   and one of them has no finite decimal (`1/3*M3 + 1/2*M4`, not `0.333333333333*M3`);
/// - integers as integers in either style.
pub fn format_coefficients(values: &[f64]) -> Vec<String> {
    // the fraction p/q (q <= 64) within 1e-9 of x, if any
    let fraction = |x: f64| -> Option<(i64, i64)> {
        (1..=64i64).find_map(|q| {
            let p = (x * q as f64).round();
            ((x - p / q as f64).abs() <= 1e-9 * x.abs().max(1.0)).then_some((p as i64, q))
        })
    };
    let terminates = |mut q: i64| {
        for f in [2, 5] {
            while q % f == 0 {
                q /= f;
            }
        }
        q == 1
    };
    let fractions: Vec<Option<(i64, i64)>> = values.iter().map(|&x| fraction(x)).collect();
    let as_fractions = fractions.iter().all(Option::is_some)
        && fractions.iter().flatten().any(|&(_, q)| !terminates(q));
    values
        .iter()
        .zip(&fractions)
        .map(|(&x, f)| match *f {
            Some((p, 1)) => p.to_string(),
            Some((p, q)) if as_fractions => format!("{p}/{q}"),
            Some((p, q)) if terminates(q) => format_number(p as f64 / q as f64),
            _ => significant(x, 12),
        })
        .collect()
}

/// Parallelism of the dense factorizations (every core rayon has).
fn par() -> Par {
    Par::rayon(0)
}

/// Householder QR of `a` in place, unpivoted and *without skipping any column*: R is in the
/// upper triangle (below it: the Householder vectors), and |R_kk| is the distance of column k
/// from the span of the columns before it, for every k. (faer's `qr_in_place` is rank
/// revealing: it skips a column whose residual is at rounding level and leaves R in echelon
/// form, which does not give that distance column by column.) Blocked: panels of 32 columns,
/// each factored column by column, then applied to the trailing columns in compact WY form
/// (I - V T V^T) with faer's matrix products.
///
/// Column c is zero below row `last_row(c)` (nondecreasing in c): each panel works only on the
/// rows down to the last nonzero row of its columns. A tree's W with its rows ordered by joint
/// is such a staircase (link j's columns are zero in the rows of the joints after j), and so is
/// R with its columns reordered, kept ones first ([`refactor`]): both cost far less than a
/// dense QR.
fn qr_in_place_staircase(mut a: faer::MatMut<'_, f64>, last_row: &dyn Fn(usize) -> usize) {
    use faer::linalg::matmul::matmul;
    use faer::Accum;
    let (m_all, n) = (a.nrows(), a.ncols());
    const B: usize = 32;
    let mut k = 0;
    let kmax = m_all.min(n);
    while k < kmax {
        let b = B.min(kmax - k);
        let mut tau = [0.0f64; B];
        // rows below the panel's last nonzero row stay zero (in the panel and in V)
        let m = (k..k + b)
            .map(|c| last_row(c).max(c) + 1)
            .max()
            .unwrap_or(m_all)
            .min(m_all);
        // panel: columns k..k+b, rows k..m (column slices: W is column-major)
        for c in k..k + b {
            let (mut left, mut right) = a.rb_mut().split_at_col_mut(c + 1);
            let v = left
                .rb_mut()
                .col_mut(c)
                .try_as_col_major_mut()
                .expect("column-major")
                .as_slice_mut();
            let v = &mut v[..m];
            let x0 = v[c];
            let sigma: f64 = v[c + 1..].iter().map(|x| x * x).sum();
            if sigma == 0.0 {
                tau[c - k] = 0.0;
                continue;
            }
            let norm = (x0 * x0 + sigma).sqrt();
            let beta = if x0 >= 0.0 { -norm } else { norm };
            let scale = 1.0 / (x0 - beta);
            v[c + 1..].iter_mut().for_each(|x| *x *= scale);
            v[c] = beta;
            let t = (beta - x0) / beta;
            tau[c - k] = t;
            // apply H = I - t v v^T (v_c = 1) to the rest of the panel
            let v = &v[c + 1..];
            for cc in 0..(k + b - c - 1) {
                let y = &mut right
                    .rb_mut()
                    .col_mut(cc)
                    .try_as_col_major_mut()
                    .expect("column-major")
                    .as_slice_mut()[..m];
                let dot = y[c] + v.iter().zip(&y[c + 1..]).map(|(p, q)| p * q).sum::<f64>();
                let f = t * dot;
                y[c] -= f;
                y[c + 1..].iter_mut().zip(v).for_each(|(q, p)| *q -= f * p);
            }
        }
        if k + b < n {
            // V (m-k x b, unit lower trapezoidal) and T (b x b upper) of the compact WY form
            let v = Mat::from_fn(m - k, b, |i, j| match i.cmp(&j) {
                std::cmp::Ordering::Less => 0.0,
                std::cmp::Ordering::Equal => 1.0,
                std::cmp::Ordering::Greater => a[(k + i, k + j)],
            });
            let mut tm = Mat::<f64>::zeros(b, b);
            for j in 0..b {
                tm[(j, j)] = tau[j];
                if j > 0 && tau[j] != 0.0 {
                    // T[0..j, j] = -tau_j T[0..j, 0..j] (V[:, 0..j]^T v_j)
                    let w = v.as_ref().subcols(0, j).transpose() * v.as_ref().col(j);
                    let tw = tm.as_ref().submatrix(0, 0, j, j) * &w;
                    for i in 0..j {
                        tm[(i, j)] = -tau[j] * tw[i];
                    }
                }
            }
            // A_trail <- (I - V T V^T)^T A_trail = A_trail - V T^T (V^T A_trail)
            let mut trail = a.rb_mut().submatrix_mut(k, k + b, m - k, n - k - b);
            let mut y = Mat::<f64>::zeros(b, n - k - b);
            matmul(
                y.as_mut(),
                Accum::Replace,
                v.transpose(),
                trail.rb(),
                1.0,
                par(),
            );
            let ty = tm.transpose() * &y;
            matmul(trail.rb_mut(), Accum::Add, &v, &ty, -1.0, par());
        }
        k += b;
    }
}

/// The n x n upper triangle of a factored `m x n` matrix (rows beyond m are zero).
fn upper(a: MatRef<'_, f64>) -> Mat<f64> {
    let n = a.ncols();
    Mat::from_fn(n, n, |i, j| {
        if i <= j && i < a.nrows() {
            a[(i, j)]
        } else {
            0.0
        }
    })
}

/// QR of the columns `cols` of R, in that order; returns the new R (cols.len() x cols.len()).
fn refactor(r: &Mat<f64>, cols: &[usize]) -> Mat<f64> {
    let mut a = Mat::from_fn(r.nrows(), cols.len(), |i, j| r[(i, cols[j])]);
    // column j of R is zero below row cols[j]; the reflectors of the columns before it mix rows
    // down to the largest of their own, so column j stays zero below the running maximum
    let mut last = Vec::with_capacity(cols.len());
    let mut running = 0;
    for &c in cols {
        running = running.max(c);
        last.push(running.min(r.nrows().saturating_sub(1)));
    }
    qr_in_place_staircase(a.as_mut(), &|j| last[j]);
    upper(a.as_ref())
}

/// Largest singular value of an upper triangular R by power iteration on R^T R.
fn sigma_max(r: MatRef<'_, f64>) -> f64 {
    let n = r.ncols();
    if n == 0 {
        return 0.0;
    }
    let mut x = faer::Col::<f64>::from_fn(n, |i| 1.0 + (i % 7) as f64 * 0.1);
    let mut s = 0.0;
    // a 0.1 % estimate is plenty for a tolerance (each step reads R twice)
    for _ in 0..30 {
        let y = r * &x;
        let z = r.transpose() * &y;
        let nz = z.norm_l2();
        if nz == 0.0 {
            return 0.0;
        }
        let next = nz.sqrt() / x.norm_l2().sqrt();
        x = z / nz;
        if (next - s).abs() <= 1e-3 * next {
            return next;
        }
        s = next;
    }
    s
}

/// Smallest singular value of an upper triangular R (full rank expected) by inverse iteration
/// (two triangular solves per step); 0 when R has a zero on its diagonal.
fn sigma_min_upper(r: MatRef<'_, f64>) -> f64 {
    use faer::linalg::triangular_solve as ts;
    let n = r.ncols();
    if n == 0 {
        return f64::INFINITY;
    }
    if (0..n).any(|i| r[(i, i)] == 0.0 || !r[(i, i)].is_finite()) {
        return 0.0;
    }
    let mut x = Mat::<f64>::from_fn(n, 1, |i, _| 1.0 + (i % 5) as f64 * 0.3);
    let mut est = 0.0;
    for _ in 0..30 {
        let nx = x.norm_l2();
        x /= nx;
        // y = (R^T R)^-1 x: R^T u = x, then R y = u
        ts::solve_lower_triangular_in_place(r.transpose(), x.as_mut(), par());
        ts::solve_upper_triangular_in_place(r, x.as_mut(), par());
        let g = x.norm_l2(); // ~ 1 / sigma_min^2
        let next = 1.0 / g.sqrt();
        if !next.is_finite() {
            return 0.0;
        }
        if (next - est).abs() <= 1e-3 * next {
            return next;
        }
        est = next;
    }
    est
}

/// Rows of W per sample (N) and the number of samples for `ncols` columns.
fn sample_count(opt: &NumericOptions, ncols: usize, n_rows_per: usize) -> usize {
    opt.samples.unwrap_or_else(|| {
        let target = (3 * ncols).min(3000.max(ncols + ncols / 4));
        // at least 20 samples, unless that exceeds the target (large trees: N = NL rows each)
        target
            .div_ceil(n_rows_per)
            .max(20.min(target.div_ceil(n_rows_per) + 2))
    })
}

/// Run the numerical method on `robot` with `sampler`.
pub fn numeric_base_parameters(
    robot: &Robot,
    sampler: &mut dyn Sampler,
    opt: &NumericOptions,
) -> Result<NumericBase> {
    let sel = &opt.selection;
    let nl = robot.nl();
    if robot.is_floating() && !robot.is_tree() {
        return Err(Error::Input(format!(
            "{}: the numerical base parameters of a floating robot with closed loops are not \
             supported yet",
            robot.name()
        )));
    }
    if sel.rotor.len() != nl || sel.friction.len() != nl {
        return Err(Error::Input(format!(
            "the parameter selection has {} entries, the robot has NL = {nl} links",
            sel.rotor.len()
        )));
    }
    let mut columns = sel.columns();
    columns.extend(base_link_columns(robot));
    let all = observed_columns(robot, sel);
    check_observation_size(robot, opt, all.len())?;
    // 1. W
    let Observation {
        mut w,
        rows,
        samples,
        tree_rows,
    } = observation_matrix(robot, sampler, opt, &all, columns.len())?;
    let offset = if robot.is_floating() { 6 } else { 0 };
    // 2.-3. no-effect columns, the others scaled to unit norm
    let scaled = scale_columns(&mut w, &all, sel);
    let stairs = Stairs {
        rows,
        samples,
        tree_rows,
        offset,
        nl,
    };
    let r_all = staircase_r(w, &scaled.live, &all, &stairs);
    let (singular_values, tol) = rank_tolerance(&r_all, scaled.n_present)?;
    // 4. ordered selection among the existing columns and the absent ones in their span
    let candidates = span_candidates(&r_all, &scaled, &all, &stairs, tol);
    let (kept, dep) = ordered_selection(&r_all, &candidates, scaled.n_present, tol);
    // 5. beta and the rank certificate
    let g = grouping(robot, &r_all, &kept, &dep, tol)?;
    drop(r_all);
    let (norms, live) = (&scaled.norms, &scaled.live);
    let col = |k: usize| all[live[k]];
    // reported in K order (a floating base's link 0, selected first, comes after the links as
    // in K, the symbolic method's list and the regressor's base columns); beta's rows follow
    let mut rows_k: Vec<usize> = (0..kept.len()).collect();
    rows_k.sort_by_key(|&x| col(kept[x]));
    let mut beta = DMatrix::zeros(kept.len(), dep.len());
    for (r, &x) in rows_k.iter().enumerate() {
        let kc = kept[x];
        for (y, &dc) in dep.iter().enumerate() {
            beta[(r, y)] = g.beta_s[(x, y)] * norms[live[dc]] / norms[live[kc]];
        }
    }
    Ok(NumericBase {
        base: rows_k.iter().map(|&x| col(kept[x])).collect(),
        grouped: dep.iter().map(|&k| col(k)).collect(),
        no_effect: scaled.no_effect,
        absent: all
            .iter()
            .copied()
            .filter(|i| sel.absent.contains(i))
            .collect(),
        columns,
        beta,
        tolerance: tol,
        singular_values,
        sigma_min_kept: g.sigma_min_kept,
        residual_grouped: g.residual_grouped,
        rows,
    })
}

/// W's columns (K indices): a floating base's 10 parameters (link 0 first in the ordered
/// selection: it moves freely, so its own parameters are all identifiable and the links'
/// group into it), the existing parameters of the selection (K order), then its absent ones.
fn observed_columns(robot: &Robot, sel: &ParameterSelection) -> Vec<usize> {
    let nl = robot.nl();
    base_link_columns(robot)
        .chain((0..PARAMS_PER_LINK * nl).filter(|&i| sel.slot(i) && !sel.absent.contains(&i)))
        .chain((0..PARAMS_PER_LINK * nl).filter(|&i| sel.slot(i) && sel.absent.contains(&i)))
        .collect()
}

/// K indices of a floating base's own parameters (13 NL .. 13 NL + 10, after the links'), none
/// for a fixed base.
fn base_link_columns(robot: &Robot) -> std::ops::Range<usize> {
    let start = PARAMS_PER_LINK * robot.nl();
    start..parameter_count(robot)
}

/// The shape of W: its rows, and a tree's row blocks (by base row and joint, then sample).
struct Stairs {
    rows: usize,
    samples: usize,
    tree_rows: bool,
    /// Base rows before the joints' blocks: 6 for a floating base.
    offset: usize,
    nl: usize,
}

impl Stairs {
    /// The link of K index `i` (0 for a floating base's own parameters).
    fn link(&self, i: usize) -> usize {
        if i >= PARAMS_PER_LINK * self.nl {
            0
        } else {
            i / PARAMS_PER_LINK + 1
        }
    }

    /// Position of K index `i` in the ordered selection: link 0 (a floating base) first, then
    /// K order.
    fn order(&self, i: usize) -> usize {
        if i >= PARAMS_PER_LINK * self.nl {
            i - PARAMS_PER_LINK * self.nl
        } else {
            i + PARAMS_PER_LINK
        }
    }
}

/// The columns of W after steps 2 and 3.
struct ScaledColumns {
    /// ||W_c|| of every column of W.
    norms: Vec<f64>,
    /// The columns with an effect (indices into W's columns, increasing), now packed to the left
    /// of W and scaled to unit norm: the existing ones first, then the absent candidates.
    live: Vec<usize>,
    /// How many of `live` are existing parameters.
    n_present: usize,
    /// K indices of the existing parameters of no effect.
    no_effect: Vec<usize>,
}

/// Steps 2 and 3: the existing parameters of no effect (absent columns of no effect are
/// dropped), the other columns scaled to unit norm and packed to the left of W in place (no
/// second copy of W).
fn scale_columns(w: &mut Mat<f64>, all: &[usize], sel: &ParameterSelection) -> ScaledColumns {
    let ncols = all.len();
    let norms: Vec<f64> = (0..ncols).map(|c| w.col(c).norm_l2()).collect();
    let is_absent = |c: usize| sel.absent.contains(&all[c]);
    let max_norm = (0..ncols)
        .filter(|&c| !is_absent(c))
        .map(|c| norms[c])
        .fold(0.0, f64::max);
    let zero = |c: usize| max_norm == 0.0 || norms[c] <= NO_EFFECT_TOLERANCE * max_norm;
    let no_effect: Vec<usize> = (0..ncols)
        .filter(|&c| !is_absent(c) && zero(c))
        .map(|c| all[c])
        .collect();
    let live: Vec<usize> = (0..ncols).filter(|&c| !zero(c)).collect();
    let n_present = live.iter().filter(|&&c| !is_absent(c)).count();
    for (j, &c) in live.iter().enumerate() {
        let f = 1.0 / norms[c];
        if c == j {
            w.col_mut(j).iter_mut().for_each(|x| *x *= f);
        } else {
            let (mut left, right) = w.as_mut().split_at_col_mut(c);
            let src = right.col(0);
            left.rb_mut()
                .col_mut(j)
                .iter_mut()
                .zip(src.iter())
                .for_each(|(d, x)| *d = x * f);
        }
    }
    ScaledColumns {
        norms,
        live,
        n_present,
        no_effect,
    }
}

/// R of the unpivoted QR of the scaled live columns of W (W consumed): a tree's W is a staircase
/// (rows by joint), its column c zero below the rows of its link.
fn staircase_r(mut w: Mat<f64>, live: &[usize], all: &[usize], st: &Stairs) -> Mat<f64> {
    let rows = st.rows;
    let mut a = w.as_mut().subcols_mut(0, live.len());
    let mut last = Vec::with_capacity(live.len());
    let mut running = 0;
    for &c in live {
        // link j's column is zero below the block of joint j (the base's below the base rows)
        let lr = if st.tree_rows {
            (st.offset + st.link(all[c])) * st.samples - 1
        } else {
            rows - 1
        };
        running = running.max(lr.min(rows - 1));
        last.push(running);
    }
    qr_in_place_staircase(a.rb_mut(), &|j| last[j]);
    upper(a.rb())
}

/// The singular values of R's leading block (the existing columns; empty beyond
/// [`SVD_COLUMNS`]) and the rank tolerance [`RANK_TOLERANCE`] sigma_max.
fn rank_tolerance(r_all: &Mat<f64>, n_present: usize) -> Result<(Vec<f64>, f64)> {
    let r_present = r_all.as_ref().submatrix(0, 0, n_present, n_present);
    let singular_values: Vec<f64> = if n_present <= SVD_COLUMNS {
        let mut sv = r_present
            .to_owned()
            .singular_values()
            .map_err(|_| Error::Numerical("the SVD of W did not converge".into()))?;
        sv.sort_by(|x, y| y.total_cmp(x));
        sv
    } else {
        Vec::new()
    };
    let smax = singular_values
        .first()
        .copied()
        .unwrap_or_else(|| sigma_max(r_present));
    Ok((singular_values, RANK_TOLERANCE * smax))
}

/// The candidates of step 4 (indices into `live`, in K order): the existing columns, and the
/// absent ones in the span of the existing ones (distance below `tol`).
fn span_candidates(
    r_all: &Mat<f64>,
    scaled: &ScaledColumns,
    all: &[usize],
    st: &Stairs,
    tol: f64,
) -> Vec<usize> {
    let rows = st.rows;
    let (live, n_present) = (&scaled.live, scaled.n_present);
    let mut c: Vec<usize> = (0..live.len())
        .filter(|&k| {
            k < n_present || {
                let d = (n_present..live.len().min(rows))
                    .map(|i| r_all[(i, k)] * r_all[(i, k)])
                    .sum::<f64>()
                    .sqrt();
                d <= tol
            }
        })
        .collect();
    c.sort_by_key(|&k| st.order(all[live[k]]));
    c
}

/// Step 4, the ordered selection: an unpivoted QR of the candidates in K order (the first QR
/// already is, without absent candidates); |R_ii| > tol keeps candidate i, else an existing one
/// is grouped. Returns (kept, grouped), indices into `live`.
fn ordered_selection(
    r_all: &Mat<f64>,
    candidates: &[usize],
    n_present: usize,
    tol: f64,
) -> (Vec<usize>, Vec<usize>) {
    let r_k = if candidates.len() == n_present {
        None
    } else {
        Some(refactor(r_all, candidates))
    };
    let diag = |i: usize| match &r_k {
        Some(r) => r[(i, i)],
        None => r_all[(i, i)],
    };
    let mut kept = Vec::new();
    let mut dep = Vec::new();
    for (i, &k) in candidates.iter().enumerate() {
        if diag(i).abs() > tol {
            kept.push(k);
        } else if k < n_present {
            dep.push(k);
        }
    }
    (kept, dep)
}

/// Refuse, before any allocation, an observation matrix W beyond [`MAX_OBSERVATION_BYTES`]:
/// N <= NL rows per sample, so rows <= max(target + NL, 20 NL); phi (NL x 13 NL) counts too.
fn check_observation_size(robot: &Robot, opt: &NumericOptions, ncols: usize) -> Result<()> {
    let nl = robot.nl();
    let per = robot.nv().max(nl);
    let bound_rows = opt
        .samples
        .map(|s| s.saturating_mul(per))
        .unwrap_or_else(|| {
            (3 * ncols)
                .min(3000.max(ncols + ncols / 4))
                .saturating_add(per)
                .max(20 * per)
        });
    let bytes = bound_rows
        .saturating_mul(ncols.max(1))
        .saturating_add(nl.saturating_mul(PARAMS_PER_LINK * nl))
        .saturating_mul(8);
    if bytes > MAX_OBSERVATION_BYTES {
        return Err(Error::Setting {
            option: "base_parameters::NumericOptions::selection",
            reason: format!(
                "{}: the numerical method would need an observation matrix W of about \
                 {bound_rows} x {ncols} ({:.1} GiB, about {:.1} GiB in all); the limit is {:.1} \
                 GiB (MAX_OBSERVATION_BYTES, about 10,000 parameters). Use the symbolic method \
                 for this robot, or fewer drive parameters (no rotor inertias, no friction)",
                robot.name(),
                bytes as f64 / (1u64 << 30) as f64,
                2.5 * bytes as f64 / (1u64 << 30) as f64,
                MAX_OBSERVATION_BYTES as f64 / (1u64 << 30) as f64
            ),
        });
    }
    Ok(())
}

/// The sampled observation matrix W (rows: the regressor rows of the sampled states, a tree's
/// by joint then sample; columns: the standard parameters `all`).
struct Observation {
    w: Mat<f64>,
    rows: usize,
    samples: usize,
    tree_rows: bool,
}

/// Step 1, W from `sampler`'s states (seeded by `opt.seed`): the regressor of each state (G^T Phi
/// for a closed chain), columns `all`; `n_columns` (the existing parameters) sets the count.
fn observation_matrix(
    robot: &Robot,
    sampler: &mut dyn Sampler,
    opt: &NumericOptions,
    all: &[usize],
    n_columns: usize,
) -> Result<Observation> {
    let nl = robot.nl();
    let mut rng = crate::sampling::rng(opt.seed);
    let model = robot.numeric();
    let mut ws = Data::new(robot);
    let offset = if robot.is_floating() { 6 } else { 0 };
    let mut phi = DMatrix::zeros(offset + nl, parameter_count(robot));
    // the first sample fixes N (rows per sample)
    let first = sampler.sample(robot, &mut rng)?;
    let n_rows_per = first.g.as_ref().map_or(offset + nl, |g| g.ncols()).max(1);
    let samples = sample_count(opt, n_columns, n_rows_per);
    let rows = samples * n_rows_per;
    let tree_rows = first.g.is_none();
    let ncols = all.len();
    let mut w = Mat::<f64>::zeros(rows, ncols);
    let mut s = first;
    for k in 0..samples {
        if k > 0 {
            s = sampler.sample(robot, &mut rng)?;
        }
        if s.q.len() != nl || s.qd.len() != nl || s.qdd.len() != nl {
            return Err(Error::Input(format!(
                "the sampler returned a state of the wrong size (NL = {nl} expected)"
            )));
        }
        if robot.is_floating() {
            let [rot, v, a] = random_base_motion(&mut rng);
            let base = FloatingBaseState {
                rot: &nalgebra::Matrix3::from_column_slice(&rot),
                v: &v,
                a: &a,
            };
            floating_tree_regressor(
                model, &mut ws, &model.env, base, &s.q, &s.qd, &s.qdd, &mut phi,
            );
        } else {
            tree_regressor(model, &mut ws, &model.env, &s.q, &s.qd, &s.qdd, &mut phi);
        }
        let block = match &s.g {
            Some(g) => closed_chain_regressor(g, &phi)?,
            None => phi.clone(),
        };
        if block.nrows() != n_rows_per {
            return Err(Error::Input(
                "the sampler's G changed its number of columns".into(),
            ));
        }
        if block.iter().any(|x| !x.is_finite()) {
            return Err(Error::Numerical(
                "the regressor of a sampled state is not finite".into(),
            ));
        }
        for (c, &col) in all.iter().enumerate() {
            for r in 0..n_rows_per {
                // a tree's rows by joint, then sample: the column of link j is zero in the rows
                // of joints after j (only its ancestors a(j) < j and j itself carry it)
                let row = if tree_rows {
                    r * samples + k
                } else {
                    k * n_rows_per + r
                };
                w[(row, c)] = block[(r, col)];
            }
        }
    }
    Ok(Observation {
        w,
        rows,
        samples,
        tree_rows,
    })
}

/// A random motion of a floating base for W: its orientation (column-major rotation matrix:
/// the regressor in R_0 sees it through the direction of gravity only), twist in [-2, 2] and
/// its derivative in [-5, 5].
fn random_base_motion(rng: &mut dyn RngCore) -> [Vec<f64>; 3] {
    let mut v =
        |s: f64, n: usize| -> Vec<f64> { (0..n).map(|_| rng.random_range(-s..s)).collect() };
    let axis = v(std::f64::consts::PI, 3);
    let rot = nalgebra::Rotation3::new(nalgebra::Vector3::new(axis[0], axis[1], axis[2]));
    [rot.matrix().as_slice().to_vec(), v(2.0, 6), v(5.0, 6)]
}

/// beta and the rank certificate of step 5.
struct Grouping {
    beta_s: Mat<f64>,
    sigma_min_kept: f64,
    residual_grouped: f64,
}

/// Step 5, QR of R's columns [kept, grouped]: the scaled grouping coefficients (R11^-1 R12), the
/// smallest singular value of the kept columns and the residual of the grouped ones; an error
/// when the rank is not clear from these samples.
fn grouping(
    robot: &Robot,
    r_all: &Mat<f64>,
    kept: &[usize],
    dep: &[usize],
    tol: f64,
) -> Result<Grouping> {
    let order: Vec<usize> = kept.iter().chain(dep).copied().collect();
    let r2 = refactor(r_all, &order);
    let nk = kept.len();
    let r11 = r2.as_ref().submatrix(0, 0, nk, nk);
    let sigma_min_kept = sigma_min_upper(r11);
    let residual_grouped = {
        let mut sq = 0.0;
        for j in nk..order.len() {
            for i in nk..=j.min(r2.nrows() - 1) {
                sq += r2[(i, j)] * r2[(i, j)];
            }
        }
        sq.sqrt()
    };
    if nk > 0 && (sigma_min_kept <= tol || residual_grouped > tol) {
        return Err(Error::Numerical(format!(
            "{}: the numerical rank is not clear from these samples (smallest singular value \
             of the kept columns {sigma_min_kept:e}, residual of the grouped ones \
             {residual_grouped:e}, tolerance {tol:e}); the samples are ill-conditioned: try \
             more samples or another seed",
            robot.name()
        )));
    }
    let mut beta_s = Mat::from_fn(nk, dep.len(), |i, j| r2[(i, nk + j)]);
    if nk > 0 && !dep.is_empty() {
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            r11,
            beta_s.as_mut(),
            par(),
        );
    }
    Ok(Grouping {
        beta_s,
        sigma_min_kept,
        residual_grouped,
    })
}
