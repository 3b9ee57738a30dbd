//! Numerical method for the base parameters (appendix 5 of the book, [Gautier 91]; §10.3.4 for
//! closed chains).
//!
//! 1. Sample `s` random consistent states (q_tr, qd_tr, qdd_tr) with their G = dq_tr/dq_a
//!    ([`Sampler`]; identity for a tree) and stack the closed-chain regressors G^T Phi into the
//!    observation matrix W (s N rows, one column per selected standard parameter).
//! 2. Parameters with no effect: columns with ||W_c|| <= [`NO_EFFECT_TOLERANCE`] max_c ||W_c||.
//! 3. The remaining columns are scaled to unit norm (so the tolerance does not depend on units).
//!    The rank r (the number of base parameters) comes from the singular values of the scaled W:
//!    sigma_k > tol with tol = [`RANK_TOLERANCE`] * sigma_max.
//! 4. Which parameters are kept: an *unpivoted* Householder QR of the scaled W in the column
//!    order of K (link 1 first, XX XY XZ YY YZ ZZ MX MY MZ M IA FS FV in each link). |R_kk| is the
//!    distance of column k from the span of the columns before it, so a column is kept when
//!    |R_kk| > tol and grouped otherwise: a dependent group keeps its earliest members. This order
//!    matches the symbolic rules: Theorem 10.1 groups YY_j into XX_j (XX first) and MZ_j, M_j into
//!    the parameters of a(j) < j (lower links first); Table 10.1 keeps MX_j/MY_j over MZ_j;
//!    parallelogram loops group the link of larger number into the smaller one; a rotor inertia
//!    IA_j comes after the ZZ it groups into. The count kept must equal the SVD rank, otherwise
//!    the samples are ill-conditioned and an error is returned.
//! 5. W = [W1 W2] (kept, grouped): beta solves W1 beta = W2 in the least-squares sense (exact
//!    up to rounding), so Phi K = Phi_1 (K1 + beta K2), i.e. K_base = K1 + beta K2.

use super::super::regressor::{
    closed_chain_regressor, parameter_name, tree_regressor, ParameterSelection, PARAMS_PER_LINK,
};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::Robot;
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

/// A consistent state of the equivalent tree with the Jacobian G = dq_tr/dq_a.
#[derive(Clone, Debug)]
pub struct ConsistentSample {
    pub q: Vec<f64>,
    pub qd: Vec<f64>,
    pub qdd: Vec<f64>,
    /// G (NL x N); `None` means identity (tree).
    pub g: Option<DMatrix<f64>>,
}

/// Produces random consistent states: random for a tree, through the loop-closure equations for a
/// closed chain.
pub trait Sampler {
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
    pub selection: ParameterSelection,
    /// Number of sampled states (default: enough for 3 rows per column, at least 20).
    pub samples: Option<usize>,
    pub seed: u64,
}

/// Result of the numerical method. Parameter indices are indices in K (13 per link).
#[derive(Clone, Debug)]
pub struct NumericBase {
    /// The selected standard parameters (columns of W), in K order.
    pub columns: Vec<usize>,
    /// Base parameters (kept, independent columns W1), in K order.
    pub base: Vec<usize>,
    /// Grouped parameters (dependent columns W2), in K order.
    pub grouped: Vec<usize>,
    /// Parameters with no effect (zero columns).
    pub no_effect: Vec<usize>,
    /// K_base = K1 + beta K2 (base.len() x grouped.len()).
    pub beta: DMatrix<f64>,
    /// Numerical rank tolerance used on the scaled W.
    pub tolerance: f64,
    /// Singular values of the scaled W (non-zero columns), largest first.
    pub singular_values: Vec<f64>,
    /// Rows of W.
    pub rows: usize,
}

impl NumericBase {
    /// Number of base parameters.
    pub fn count(&self) -> usize {
        self.base.len()
    }

    /// Base parameter values K1 + beta K2 for a full standard vector K (13 per link).
    pub fn base_values(&self, k: &[f64]) -> Vec<f64> {
        self.base
            .iter()
            .enumerate()
            .map(|(r, &b)| {
                k[b] + self
                    .grouped
                    .iter()
                    .enumerate()
                    .map(|(c, &g)| self.beta[(r, c)] * k[g])
                    .sum::<f64>()
            })
            .collect()
    }

    /// Names of the base parameters.
    pub fn base_names(&self) -> Vec<String> {
        self.base.iter().map(|&i| parameter_name(i)).collect()
    }

    /// Grouping equation of base parameter number `r` as text, e.g. `XX2 - YY2 + 0.36*M3`.
    /// Coefficients are rounded to 12 significant digits for display only.
    pub fn equation(&self, r: usize) -> String {
        let mut s = parameter_name(self.base[r]);
        for (c, &g) in self.grouped.iter().enumerate() {
            let b = self.beta[(r, c)];
            if b.abs() < 1e-9 {
                continue;
            }
            let mag = format_coefficient(b.abs());
            let sign = if b < 0.0 { " - " } else { " + " };
            if mag == "1" {
                s.push_str(&format!("{sign}{}", parameter_name(g)));
            } else {
                s.push_str(&format!("{sign}{mag}*{}", parameter_name(g)));
            }
        }
        s
    }
}

/// A coefficient for display: a short rational (p/q with q <= 64) when it is one to 1e-9,
/// otherwise 12 significant digits.
pub fn format_coefficient(x: f64) -> String {
    for q in 1..=64i64 {
        let p = (x * q as f64).round();
        if (x - p / q as f64).abs() <= 1e-9 * x.abs().max(1.0) {
            return if q == 1 {
                format!("{}", p as i64)
            } else {
                format!("{}/{}", p as i64, q)
            };
        }
    }
    let s = format!("{x:.12e}");
    let v: f64 = s.parse().unwrap_or(x);
    format!("{v}")
}

/// Run the numerical method on `robot` with `sampler`.
pub fn numeric_base_parameters(
    robot: &Robot,
    sampler: &mut dyn Sampler,
    opt: &NumericOptions,
) -> Result<NumericBase> {
    let nl = robot.nl();
    if opt.selection.rotor.len() != nl || opt.selection.friction.len() != nl {
        return Err(Error::Input(format!(
            "the parameter selection has {} entries, the robot has NL = {nl} links",
            opt.selection.rotor.len()
        )));
    }
    let columns = opt.selection.columns();
    let ncols = columns.len();
    let mut rng = crate::testing::rng(opt.seed);
    let model = robot.numeric();
    let mut ws = Data::new(robot);
    let mut phi = DMatrix::zeros(nl, PARAMS_PER_LINK * nl);
    // first sample fixes N (rows per sample)
    let first = sampler.sample(robot, &mut rng)?;
    let n_rows_per = first.g.as_ref().map_or(nl, |g| g.ncols()).max(1);
    let samples = opt
        .samples
        .unwrap_or_else(|| (3 * ncols).div_ceil(n_rows_per).max(20));
    let rows = samples * n_rows_per;
    let mut w = DMatrix::zeros(rows, ncols);
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
        tree_regressor(model, &mut ws, &model.env, &s.q, &s.qd, &s.qdd, &mut phi);
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
        for (c, &col) in columns.iter().enumerate() {
            for r in 0..n_rows_per {
                w[(k * n_rows_per + r, c)] = block[(r, col)];
            }
        }
    }
    // 2. no-effect columns
    let norms: Vec<f64> = (0..ncols).map(|c| w.column(c).norm()).collect();
    let max_norm = norms.iter().cloned().fold(0.0, f64::max);
    let mut no_effect = Vec::new();
    let mut live = Vec::new();
    for c in 0..ncols {
        if norms[c] <= NO_EFFECT_TOLERANCE * max_norm || max_norm == 0.0 {
            no_effect.push(columns[c]);
        } else {
            live.push(c);
        }
    }
    // 3. scaled matrix and rank
    let mut ws_mat = DMatrix::zeros(rows, live.len());
    for (k, &c) in live.iter().enumerate() {
        ws_mat.set_column(k, &(w.column(c) / norms[c]));
    }
    let qr = ws_mat.clone().qr();
    let r = qr.r();
    let mut singular_values: Vec<f64> = if live.is_empty() {
        Vec::new()
    } else {
        r.clone().singular_values().iter().cloned().collect()
    };
    singular_values.sort_by(|a, b| b.partial_cmp(a).unwrap());
    let smax = singular_values.first().cloned().unwrap_or(0.0);
    let tol = RANK_TOLERANCE * smax;
    let rank = singular_values.iter().filter(|&&x| x > tol).count();
    // 4. ordered selection (unpivoted QR in K order)
    let mut kept = Vec::new();
    let mut dep = Vec::new();
    for (k, &c) in live.iter().enumerate() {
        if r[(k, k)].abs() > tol {
            kept.push(c);
        } else {
            dep.push(c);
        }
    }
    if kept.len() != rank {
        return Err(Error::Numerical(format!(
            "the ordered QR keeps {} columns but the numerical rank is {rank} (tolerance {tol:e}); \
             the samples are ill-conditioned, try more samples or another seed",
            kept.len()
        )));
    }
    // 5. beta
    let scaled = |set: &[usize]| {
        let mut m = DMatrix::zeros(rows, set.len());
        for (k, &c) in set.iter().enumerate() {
            m.set_column(k, &(w.column(c) / norms[c]));
        }
        m
    };
    let w1 = scaled(&kept);
    let w2 = scaled(&dep);
    let beta_n = if dep.is_empty() || kept.is_empty() {
        DMatrix::zeros(kept.len(), dep.len())
    } else {
        let qr1 = w1.qr();
        let qtb = qr1.q().transpose() * w2;
        qr1.r().solve_upper_triangular(&qtb).ok_or_else(|| {
            Error::Numerical("the kept columns are singular (cannot compute beta)".into())
        })?
    };
    let mut beta = beta_n;
    for (a, &kc) in kept.iter().enumerate() {
        for (b, &dc) in dep.iter().enumerate() {
            beta[(a, b)] *= norms[dc] / norms[kc];
        }
    }
    Ok(NumericBase {
        base: kept.iter().map(|&c| columns[c]).collect(),
        grouped: dep.iter().map(|&c| columns[c]).collect(),
        no_effect,
        columns,
        beta,
        tolerance: tol,
        singular_values,
        rows,
    })
}
