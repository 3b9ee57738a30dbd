//! Least squares over blocks of rows that share unknowns: the joint problems of drive-gain and
//! payload identification, built from the per-joint triangular factors of the logs' statistics.
//!
//! A block stands for rows A u ~ c of some log's joint, given as a matrix B = [A c] whose least
//! squares equal those of the rows (B^T B = [A c]^T [A c]; built from a factor T of [W y] as
//! B = T M for a linear map M of the columns). The blocks are stacked, reduced to one
//! triangular factor (faer QR), and solved by an SVD of that factor with unit-norm columns: the
//! numerical rank (singular values above [`IDENTIFIABILITY_TOLERANCE`] times the largest) says
//! which unknowns the data determine, the pseudo-inverse gives those, and the null space the
//! combinations they do not. Weighted like Gautier's WLS: each block's rows divided by the
//! standard deviation of its own residual at the ordinary estimate.

use crate::error::{Error, Result};
use faer::Mat;

/// Relative singular value (of the stacked matrix with unit-norm columns) at or below which a
/// direction of the unknowns is taken as not determined by the data.
pub const IDENTIFIABILITY_TOLERANCE: f64 = 1e-9;

/// Largest component (unit-norm columns) of an unknown along the null space for it to count as
/// determined on its own.
const NULL_COMPONENT: f64 = 1e-6;

/// One block of rows A u ~ c.
#[derive(Clone, Debug)]
pub struct Block {
    /// [A c]: u + 1 columns, any number of rows (a factor of the rows).
    pub matrix: Mat<f64>,
    /// Rows of data the block stands for.
    pub rows: usize,
    /// Covariance factor of its correlated residuals (the processing's `std_inflation`).
    pub inflation: f64,
}

/// The solution of the stacked least squares.
#[derive(Clone, Debug)]
pub struct StackedSolution {
    /// The estimate (minimum-norm in unit-column coordinates where not every unknown is
    /// determined; only the entries with `identifiable` true are meaningful alone).
    pub x: Vec<f64>,
    /// Standard deviations (0 where not identifiable).
    pub std: Vec<f64>,
    /// Whether each unknown is determined by the data on its own.
    pub identifiable: Vec<bool>,
    /// Directions of the unknowns the data do not determine (each scaled to a largest
    /// component of 1, in the unknowns' units).
    pub null_space: Vec<Vec<f64>>,
    /// Numerical rank of the stacked matrix.
    pub rank: usize,
    /// Singular values of the stacked matrix with unit-norm columns, relative to the largest.
    pub relative_singular_values: Vec<f64>,
    /// Condition number (unit-norm columns) over the determined directions.
    pub condition: f64,
    /// ||c - A u||^2 / ||c||^2 over every row (unweighted), square-rooted; 0 when c is 0.
    pub relative_error: f64,
    /// ||c - A u||^2 over every row (unweighted).
    pub residual_sq: f64,
    /// Rows of data.
    pub rows: usize,
    /// The standard deviation of each block's residual, when weighted.
    pub block_sigma: Option<Vec<f64>>,
    /// The covariance factor applied (the blocks' inflations weighted by their rows).
    pub inflation: f64,
}

/// ||B [u; -1]||^2.
fn residual(b: &Mat<f64>, u: &[f64]) -> f64 {
    let n = b.ncols() - 1;
    (0..b.nrows())
        .map(|r| {
            let s = (0..n).map(|c| b[(r, c)] * u[c]).sum::<f64>() - b[(r, n)];
            s * s
        })
        .sum()
}

/// The triangular factor of the blocks stacked, block k's rows times `weights[k]`.
fn stack(blocks: &[Block], weights: &[f64]) -> Mat<f64> {
    let cols = blocks[0].matrix.ncols();
    let total: usize = blocks.iter().map(|b| b.matrix.nrows()).sum();
    let mut s = Mat::<f64>::zeros(total.max(cols), cols);
    let mut at = 0;
    for (b, w) in blocks.iter().zip(weights) {
        for r in 0..b.matrix.nrows() {
            for c in 0..cols {
                s[(at + r, c)] = w * b.matrix[(r, c)];
            }
        }
        at += b.matrix.nrows();
    }
    let r = s.qr().thin_R().to_owned();
    Mat::from_fn(cols, cols, |i, j| if i <= j { r[(i, j)] } else { 0.0 })
}

/// Pseudo-inverse solution of the factor `t` of [A c] (u + 1 columns) for `rows` rows.
fn pseudo_inverse(t: &Mat<f64>, rows: usize) -> Result<StackedSolution> {
    let u = t.ncols() - 1;
    let nr = t.nrows();
    let norms: Vec<f64> = (0..u)
        .map(|c| (0..nr).map(|i| t[(i, c)].powi(2)).sum::<f64>().sqrt())
        .collect();
    let scale = |c: usize| if norms[c] > 0.0 { norms[c] } else { 1.0 };
    let a = Mat::from_fn(nr, u, |i, c| t[(i, c)] / scale(c));
    let svd = a
        .thin_svd()
        .map_err(|e| Error::Numerical(format!("SVD of the stacked rows failed: {e:?}")))?;
    let s: Vec<f64> = (0..u).map(|k| svd.S()[k]).collect();
    let smax = s.first().copied().unwrap_or(0.0);
    if !(smax.is_finite() && smax > 0.0) {
        return Err(Error::Numerical(
            "the stacked rows are zero: the logs determine nothing".into(),
        ));
    }
    let rank = s
        .iter()
        .filter(|&&v| v > IDENTIFIABILITY_TOLERANCE * smax)
        .count();
    let (uu, v) = (svd.U(), svd.V());
    let coef: Vec<f64> = (0..rank)
        .map(|k| (0..nr).map(|i| uu[(i, k)] * t[(i, u)]).sum::<f64>() / s[k])
        .collect();
    let x: Vec<f64> = (0..u)
        .map(|i| (0..rank).map(|k| v[(i, k)] * coef[k]).sum::<f64>() / scale(i))
        .collect();
    let res = residual(t, &x);
    let out: f64 = (0..nr).map(|i| t[(i, u)].powi(2)).sum();
    let sigma2 = if rows > rank {
        res / (rows - rank) as f64
    } else {
        0.0
    };
    let null: Vec<usize> = (rank..u).collect();
    let identifiable: Vec<bool> = (0..u)
        .map(|i| null.iter().all(|&k| v[(i, k)].abs() <= NULL_COMPONENT))
        .collect();
    let std = (0..u)
        .map(|i| {
            if !identifiable[i] {
                return 0.0;
            }
            let q: f64 = (0..rank).map(|k| (v[(i, k)] / s[k]).powi(2)).sum();
            (sigma2 * q).sqrt() / scale(i)
        })
        .collect();
    let null_space = null
        .iter()
        .map(|&k| {
            let d: Vec<f64> = (0..u).map(|i| v[(i, k)] / scale(i)).collect();
            let m = d.iter().fold(0.0f64, |a, b| a.max(b.abs()));
            d.iter().map(|x| x / m).collect()
        })
        .collect();
    Ok(StackedSolution {
        x,
        std,
        identifiable,
        null_space,
        rank,
        relative_singular_values: s.iter().map(|v| v / smax).collect(),
        condition: if rank > 0 {
            smax / s[rank - 1]
        } else {
            f64::INFINITY
        },
        relative_error: if out > 0.0 { (res / out).sqrt() } else { 0.0 },
        residual_sq: res,
        rows,
        block_sigma: None,
        inflation: 1.0,
    })
}

/// Most re-estimations of the weights (they settle to 0.1 % in a few).
const WEIGHT_ITERATIONS: usize = 10;

/// The standard deviation of each block's residual at `sol` (degrees of freedom shared in
/// proportion to the rows); an error when a block is fitted exactly.
fn block_sigma(blocks: &[Block], sol: &StackedSolution) -> Result<Vec<f64>> {
    let rows = sol.rows.max(1) as f64;
    let dof = (sol.rows.saturating_sub(sol.rank).max(1)) as f64 / rows;
    let sigma: Vec<f64> = blocks
        .iter()
        .map(|b| (residual(&b.matrix, &sol.x) / (b.rows.max(1) as f64 * dof)).sqrt())
        .collect();
    if let Some(k) = sigma.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
        return Err(Error::Setting {
            option: "identification::Options::estimator",
            reason: format!(
                "block {} of the rows is fitted exactly (sigma = 0), so the weight 1/sigma is \
                 infinite; use ordinary least squares (noise-free data)",
                k + 1
            ),
        });
    }
    Ok(sigma)
}

/// Solve the stacked blocks: ordinary least squares, or weighted (each block's rows divided by
/// the standard deviation of its residual, iterated from the ordinary estimate until the
/// weights settle; an error when a block is fitted exactly, noise-free data, where the weight
/// is infinite). The standard deviations
/// are multiplied by the square root of the blocks' inflation (weighted by their rows).
pub fn solve(blocks: &[Block], weighted: bool) -> Result<StackedSolution> {
    if blocks.is_empty() {
        return Err(Error::Input("no rows to identify from".into()));
    }
    let rows: usize = blocks.iter().map(|b| b.rows).sum();
    let ones = vec![1.0; blocks.len()];
    let mut sol = pseudo_inverse(&stack(blocks, &ones), rows)?;
    if weighted {
        // Gautier's weights, re-estimated from the weighted fit until they settle: the ordinary
        // fit, dominated by the blocks of large torques, overstates the others' sigma
        let mut sigma: Vec<f64> = Vec::new();
        for _ in 0..WEIGHT_ITERATIONS {
            let next = block_sigma(blocks, &sol)?;
            let settled = !sigma.is_empty()
                && next
                    .iter()
                    .zip(&sigma)
                    .all(|(a, b)| (a - b).abs() <= 1e-3 * b);
            sigma = next;
            let weights: Vec<f64> = sigma.iter().map(|s| 1.0 / s).collect();
            sol = pseudo_inverse(&stack(blocks, &weights), rows)?;
            if settled {
                break;
            }
        }
        // the unweighted fit of the weighted estimate
        let res: f64 = blocks.iter().map(|b| residual(&b.matrix, &sol.x)).sum();
        let out: f64 = blocks
            .iter()
            .map(|b| {
                let n = b.matrix.ncols() - 1;
                (0..b.matrix.nrows())
                    .map(|r| b.matrix[(r, n)].powi(2))
                    .sum::<f64>()
            })
            .sum();
        sol.residual_sq = res;
        sol.relative_error = if out > 0.0 { (res / out).sqrt() } else { 0.0 };
        sol.block_sigma = Some(sigma);
    }
    let inflation = if rows > 0 {
        blocks
            .iter()
            .map(|b| b.inflation * b.rows as f64)
            .sum::<f64>()
            / rows as f64
    } else {
        1.0
    };
    for s in &mut sol.std {
        *s *= inflation.sqrt();
    }
    sol.inflation = inflation;
    Ok(sol)
}

/// The block of a factor `t` of [W y] (p + 1 columns) mapped to u unknowns: A = T[:, :p] m
/// (m: p x u, row-major rows of u), plus `y_unknown` (column index, coefficient) taking
/// coefficient times T's y column into A, and c = `y_weight` T[:, p] - T[:, :p] `known`.
pub struct BlockMap<'a> {
    /// The p x u map of W's columns onto the unknowns.
    pub columns: &'a [Vec<f64>],
    /// The y column times this coefficient is unknown `(index, coefficient)`'s column.
    pub y_unknown: Option<(usize, f64)>,
    /// Coefficient of the y column in c.
    pub y_weight: f64,
    /// A known part of the parameters, moved to c (p entries).
    pub known: Option<&'a [f64]>,
}

impl BlockMap<'_> {
    /// The block of factor `t` (its `rows` rows, `inflation`).
    pub fn apply(&self, t: &Mat<f64>, rows: usize, inflation: f64) -> Block {
        let p = t.ncols() - 1;
        let u = self.columns.first().map_or(0, |r| r.len());
        let mut b = Mat::<f64>::zeros(t.nrows(), u + 1);
        for r in 0..t.nrows() {
            for (c, m) in self.columns.iter().enumerate() {
                let w = t[(r, c)];
                if w != 0.0 {
                    for (k, mk) in m.iter().enumerate() {
                        b[(r, k)] += w * mk;
                    }
                }
            }
            if let Some((k, coef)) = self.y_unknown {
                b[(r, k)] += coef * t[(r, p)];
            }
            let known: f64 = self
                .known
                .map_or(0.0, |x| (0..p).map(|c| t[(r, c)] * x[c]).sum());
            b[(r, u)] = self.y_weight * t[(r, p)] - known;
        }
        Block {
            matrix: b,
            rows,
            inflation,
        }
    }
}

/// The identity map of p columns into u >= p unknowns (the first p).
pub fn identity_columns(p: usize, u: usize) -> Vec<Vec<f64>> {
    (0..p)
        .map(|c| (0..u).map(|k| if k == c { 1.0 } else { 0.0 }).collect())
        .collect()
}

/// A combination of named unknowns in words: `XX - YY` from a null direction (components
/// below 1e-6 of the largest left out).
pub fn combination(direction: &[f64], names: &[String]) -> String {
    let mut s = String::new();
    for (d, n) in direction.iter().zip(names) {
        if d.abs() <= 1e-6 {
            continue;
        }
        let sign = if *d < 0.0 { "-" } else { "+" };
        let mag = d.abs();
        let term = if (mag - 1.0).abs() < 1e-9 {
            n.clone()
        } else {
            format!("{mag:.6}*{n}")
        };
        if s.is_empty() {
            s = if *d < 0.0 { format!("-{term}") } else { term };
        } else {
            s.push_str(&format!(" {sign} {term}"));
        }
    }
    s
}
