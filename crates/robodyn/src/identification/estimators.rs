//! Estimators of the inverse dynamic identification model Y = W X + rho (Gautier 1990, 1997;
//! Khalil & Dombre §12.4; Janot, Vandanjon, Gautier 2014 for the instrumental variables).
//!
//! The observation matrix is never stored. Its rows stream into a triangular factor of the
//! augmented matrix [W Y] ([`TriangularFactor`]): T (p+1 x p+1, upper) with
//! T^T T = [W Y]^T [W Y], i.e. the normal equations carried as their Cholesky factor, updated by
//! a Householder QR of [T; new rows] for every block of rows (numerically the least squares
//! of W itself, not of W^T W: the condition number is not squared). Factors of disjoint row
//! sets combine by stacking ([`combine`]), so a fleet's logs can be processed on separate
//! machines and merged. One factor is kept per joint: Gautier's weights, the per-joint residuals
//! and any subset of parameters (essential parameters) come from the factors alone, since
//! ||Y_j - W_j X||^2 = ||T_j [X; -1]||^2.

use crate::error::{Error, Result};
use faer::Mat;

/// Rows gathered before each QR update of a factor.
const BLOCK_ROWS: usize = 256;

/// Streaming triangular factor of [W y] for one group of rows (see the module documentation).
/// Serialized as its row count and the upper triangle of T with every row folded in
/// ([`FactorData`]).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(into = "FactorData", try_from = "FactorData")]
pub struct TriangularFactor {
    /// Number of parameters p.
    p: usize,
    /// T ((p+1) x (p+1)); only its upper triangle is nonzero.
    t: Mat<f64>,
    /// Rows not yet folded into T.
    block: Mat<f64>,
    filled: usize,
    rows: usize,
}

impl TriangularFactor {
    /// An empty factor for `p` parameters (no row yet).
    pub fn new(p: usize) -> TriangularFactor {
        TriangularFactor {
            p,
            t: Mat::zeros(p + 1, p + 1),
            block: Mat::zeros(BLOCK_ROWS, p + 1),
            filled: 0,
            rows: 0,
        }
    }

    /// Parameters p.
    pub fn params(&self) -> usize {
        self.p
    }

    /// Rows received.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Add the row (w, y).
    pub fn push(&mut self, w: &[f64], y: f64) {
        debug_assert_eq!(w.len(), self.p);
        let r = self.filled;
        for (c, &v) in w.iter().enumerate() {
            self.block[(r, c)] = v;
        }
        self.block[(r, self.p)] = y;
        self.filled += 1;
        self.rows += 1;
        if self.filled == BLOCK_ROWS {
            self.flush();
        }
    }

    /// Fold the pending rows into T.
    fn flush(&mut self) {
        if self.filled == 0 {
            return;
        }
        let p1 = self.p + 1;
        let mut s = Mat::<f64>::zeros(p1 + self.filled, p1);
        for c in 0..p1 {
            for r in 0..=c {
                s[(r, c)] = self.t[(r, c)];
            }
            for r in 0..self.filled {
                s[(p1 + r, c)] = self.block[(r, c)];
            }
        }
        self.t = upper(&s, p1);
        self.filled = 0;
    }

    /// T with every row folded in.
    pub fn factor(&mut self) -> &Mat<f64> {
        self.flush();
        &self.t
    }

    /// Merge the rows of another factor (e.g. computed on another machine).
    pub fn merge(&mut self, other: &mut TriangularFactor) {
        assert_eq!(self.p, other.p, "factors of different parameter counts");
        self.flush();
        other.flush();
        self.t = combine(&[(&self.t, 1.0), (&other.t, 1.0)]);
        self.rows += other.rows;
    }
}

/// The serialized form of a [`TriangularFactor`]: its rows and the upper triangle of T, row i
/// holding `T[i][i..=p]` (T^T T = [W y]^T [W y]: W^T W, W^T y and y^T y of the rows, carried as
/// their Cholesky factor).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FactorData {
    /// Rows (equations) folded into the factor.
    pub rows: usize,
    /// Row i: `T[i][i], ..., T[i][p]` (p + 1 - i numbers).
    pub upper: Vec<Vec<f64>>,
}

impl From<TriangularFactor> for FactorData {
    fn from(mut f: TriangularFactor) -> FactorData {
        let p1 = f.p + 1;
        let rows = f.rows;
        let t = f.factor();
        FactorData {
            rows,
            upper: (0..p1)
                .map(|i| (i..p1).map(|c| t[(i, c)]).collect())
                .collect(),
        }
    }
}

impl TryFrom<FactorData> for TriangularFactor {
    type Error = String;
    fn try_from(d: FactorData) -> std::result::Result<TriangularFactor, String> {
        let p1 = d.upper.len();
        if p1 == 0 {
            return Err("a factor with no row of T".into());
        }
        let mut f = TriangularFactor::new(p1 - 1);
        for (i, row) in d.upper.iter().enumerate() {
            if row.len() != p1 - i {
                return Err(format!(
                    "row {i} of a factor's upper triangle has {} numbers, {} expected",
                    row.len(),
                    p1 - i
                ));
            }
            for (k, &v) in row.iter().enumerate() {
                if !v.is_finite() {
                    return Err(format!("a factor holds a non-finite number ({v})"));
                }
                f.t[(i, i + k)] = v;
            }
        }
        f.rows = d.rows;
        Ok(f)
    }
}

/// The p1 x p1 upper triangle of the R factor of `s` (p1 columns).
fn upper(s: &Mat<f64>, p1: usize) -> Mat<f64> {
    let qr = s.qr();
    let r = qr.thin_R();
    let mut t = Mat::zeros(p1, p1);
    for c in 0..p1 {
        for i in 0..=c.min(r.nrows().saturating_sub(1)) {
            t[(i, c)] = r[(i, c)];
        }
    }
    t
}

/// Triangular factor of the weighted union of row sets: QR of [w_1 T_1; w_2 T_2; ...].
pub fn combine(parts: &[(&Mat<f64>, f64)]) -> Mat<f64> {
    let p1 = parts[0].0.ncols();
    let mut s = Mat::<f64>::zeros(p1 * parts.len(), p1);
    for (k, (t, w)) in parts.iter().enumerate() {
        for c in 0..p1 {
            for r in 0..=c {
                s[(k * p1 + r, c)] = w * t[(r, c)];
            }
        }
    }
    upper(&s, p1)
}

/// Restrict a factor of [W y] to the parameter columns `keep`: the factor of [W_keep y].
pub fn restrict(t: &Mat<f64>, keep: &[usize]) -> Mat<f64> {
    let p = t.ncols() - 1;
    let m = keep.len();
    let mut s = Mat::<f64>::zeros(p + 1, m + 1);
    for r in 0..=p {
        for (c, &k) in keep.iter().enumerate() {
            s[(r, c)] = t[(r, k)];
        }
        s[(r, m)] = t[(r, p)];
    }
    upper(&s, m + 1)
}

/// ||y - W x||^2 from the factor T of [W y]: ||T [x; -1]||^2.
pub fn residual_sq(t: &Mat<f64>, x: &[f64]) -> f64 {
    let p = t.ncols() - 1;
    (0..=p)
        .map(|r| {
            let mut s = -t[(r, p)];
            for c in r..p {
                s += t[(r, c)] * x[c];
            }
            s * s
        })
        .sum()
}

/// ||y||^2 from the factor of [W y].
pub fn output_sq(t: &Mat<f64>) -> f64 {
    let p = t.ncols() - 1;
    (0..=p).map(|r| t[(r, p)] * t[(r, p)]).sum()
}

/// Relative singular values below this make the least-squares problem rank-deficient: the
/// parameters are not identifiable from the data (refused).
pub const RANK_TOLERANCE: f64 = 1e-12;

/// A least-squares solution with its statistics.
#[derive(Clone, Debug)]
pub struct LsSolution {
    /// The estimate (p entries).
    pub x: Vec<f64>,
    /// Standard deviation of each parameter: sqrt of the diagonal of the covariance.
    pub std: Vec<f64>,
    /// Covariance sigma^2 (W^T W)^-1 (p x p, row-major), times the inflation of correlated
    /// residuals where [`LsSolution::inflate`] was applied.
    pub covariance: Vec<f64>,
    /// sigma^2 = ||rho||^2 / (r - p).
    pub sigma2: f64,
    /// ||y - W x||^2.
    pub residual_sq: f64,
    /// ||y||^2.
    pub output_sq: f64,
    /// Rows r of W.
    pub rows: usize,
    /// Condition number of W with columns scaled to unit norm (independent of units).
    pub condition: f64,
    /// Condition number of W as given.
    pub condition_unscaled: f64,
}

impl LsSolution {
    /// ||y - W x|| / ||y||.
    pub fn relative_error(&self) -> f64 {
        (self.residual_sq / self.output_sq.max(f64::MIN_POSITIVE)).sqrt()
    }

    /// Multiply the covariance by `factor` (and the standard deviations by its square root):
    /// the correlation of the residuals, see
    /// [`super::signal::Butterworth::decimated_noise_gain`]. `sigma2` stays the residual
    /// variance.
    pub fn inflate(&mut self, factor: f64) {
        for c in &mut self.covariance {
            *c *= factor;
        }
        let s = factor.sqrt();
        for d in &mut self.std {
            *d *= s;
        }
    }

    /// 100 std / |x| (infinite for x = 0).
    pub fn relative_std(&self) -> Vec<f64> {
        self.x
            .iter()
            .zip(&self.std)
            .map(|(x, s)| 100.0 * s / x.abs())
            .collect()
    }
}

/// Singular value decomposition of the p x p matrix R D^-1 (D the column norms): (U, s, V) with
/// s decreasing, as faer computes it.
struct ScaledSvd {
    norms: Vec<f64>,
    u: Mat<f64>,
    s: Vec<f64>,
    v: Mat<f64>,
}

fn scaled_svd(r: &Mat<f64>) -> Result<ScaledSvd> {
    let p = r.ncols();
    let norms: Vec<f64> = (0..p)
        .map(|c| {
            (0..r.nrows())
                .map(|i| r[(i, c)] * r[(i, c)])
                .sum::<f64>()
                .sqrt()
        })
        .collect();
    let mut a = Mat::<f64>::zeros(r.nrows(), p);
    for c in 0..p {
        let d = if norms[c] > 0.0 { norms[c] } else { 1.0 };
        for i in 0..r.nrows() {
            a[(i, c)] = r[(i, c)] / d;
        }
    }
    let svd = a
        .thin_svd()
        .map_err(|e| Error::Numerical(format!("SVD of the observation matrix failed: {e:?}")))?;
    let s: Vec<f64> = (0..p.min(r.nrows())).map(|k| svd.S()[k]).collect();
    Ok(ScaledSvd {
        norms,
        u: svd.U().to_owned(),
        s,
        v: svd.V().to_owned(),
    })
}

/// Ordinary least squares on the factor T of [W y] (p parameters, `rows` rows). `names` name the
/// parameters in the refusal of a rank-deficient problem.
pub fn least_squares(t: &Mat<f64>, rows: usize, names: &[String]) -> Result<LsSolution> {
    let p = t.ncols() - 1;
    if rows <= p {
        return Err(Error::Input(format!(
            "{rows} equations for {p} parameters: the log is too short (after decimation and \
             border removal) to identify them"
        )));
    }
    let r = Mat::from_fn(p, p, |i, j| t[(i, j)]);
    let z: Vec<f64> = (0..p).map(|i| t[(i, p)]).collect();
    let svd = scaled_svd(&r)?;
    if let Some(&k) = svd
        .norms
        .iter()
        .enumerate()
        .find(|(_, &n)| n == 0.0)
        .map(|(k, _)| k)
        .as_ref()
    {
        return Err(Error::Numerical(format!(
            "parameter {} has no effect on the measured torques (its column of W is zero): the \
             motion does not excite it",
            names
                .get(k)
                .cloned()
                .unwrap_or_else(|| format!("#{}", k + 1))
        )));
    }
    let smax = svd.s[0];
    let smin = *svd.s.last().unwrap();
    if smin.is_nan() || smin <= RANK_TOLERANCE * smax {
        // the parameters with large components in the null direction
        let v = &svd.v;
        let mut parts: Vec<(f64, usize)> = (0..p).map(|i| (v[(i, p - 1)].abs(), i)).collect();
        parts.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
        let list: Vec<String> = parts
            .iter()
            .take_while(|(a, _)| *a > 0.1)
            .map(|(a, i)| format!("{} ({a:.2})", names.get(*i).cloned().unwrap_or_default()))
            .collect();
        return Err(Error::Numerical(format!(
            "the observation matrix is rank-deficient (smallest/largest singular value of the \
             unit-column W = {:.1e}): a combination of {} is not identifiable from this motion; \
             excite the robot more (robodyn excite) or leave these parameters out",
            smin / smax,
            list.join(", ")
        )));
    }
    // x = D^-1 V S^-1 U^T z
    let utz: Vec<f64> = (0..p)
        .map(|k| (0..p).map(|i| svd.u[(i, k)] * z[i]).sum::<f64>() / svd.s[k])
        .collect();
    let x: Vec<f64> = (0..p)
        .map(|i| (0..p).map(|k| svd.v[(i, k)] * utz[k]).sum::<f64>() / svd.norms[i])
        .collect();
    let res = residual_sq(t, &x);
    let sigma2 = res / (rows - p) as f64;
    // (W^T W)^-1 = D^-1 V S^-2 V^T D^-1
    let mut cov = vec![0.0; p * p];
    for i in 0..p {
        for j in 0..p {
            let mut s = 0.0;
            for k in 0..p {
                s += svd.v[(i, k)] * svd.v[(j, k)] / (svd.s[k] * svd.s[k]);
            }
            cov[i * p + j] = sigma2 * s / (svd.norms[i] * svd.norms[j]);
        }
    }
    let unscaled = r
        .singular_values()
        .map_err(|e| Error::Numerical(format!("SVD failed: {e:?}")))?;
    let condition_unscaled = unscaled[0] / unscaled[unscaled.len() - 1];
    Ok(LsSolution {
        std: (0..p).map(|i| cov[i * p + i].max(0.0).sqrt()).collect(),
        covariance: cov,
        x,
        sigma2,
        residual_sq: res,
        output_sq: output_sq(t),
        rows,
        condition: smax / smin,
        condition_unscaled,
    })
}

/// Gautier's weight of one joint's equations: the standard deviation of its error, from the
/// least-squares solution of the joint's own equations Y_j = W_j X (rank-revealing: W_j
/// involves only the parameters of the links the joint carries), sigma_j^2 =
/// ||Y_j - W_j X_j||^2 / (r_j - c_j), c_j the rank of W_j.
pub fn joint_sigma(t: &Mat<f64>, rows: usize) -> Result<f64> {
    let p = t.ncols() - 1;
    let r = Mat::from_fn(p, p, |i, j| t[(i, j)]);
    let z: Vec<f64> = (0..p).map(|i| t[(i, p)]).collect();
    let rho2 = t[(p, p)] * t[(p, p)];
    let svd = scaled_svd(&r)?;
    let smax = svd.s.first().copied().unwrap_or(0.0);
    let live = svd.norms.iter().filter(|&&n| n > 0.0).count();
    let rank = svd
        .s
        .iter()
        .take(live)
        .filter(|&&s| s > 1e-10 * smax)
        .count();
    // the part of z outside the range of R: components along the dropped left singular vectors
    let mut outside = 0.0;
    for k in rank..p {
        let c: f64 = (0..p).map(|i| svd.u[(i, k)] * z[i]).sum();
        outside += c * c;
    }
    if rows <= rank {
        return Err(Error::Input(format!(
            "{rows} equations of one joint for {rank} identifiable parameters: too few to weight \
             them"
        )));
    }
    Ok(((rho2 + outside) / (rows - rank) as f64).sqrt())
}

/// Instrumental-variable accumulators of one group of rows: Z^T W, Z^T y, Z^T Z.
#[derive(Clone, Debug)]
pub struct IvAccumulator {
    p: usize,
    /// Z^T W (p x p, row-major).
    pub zw: Vec<f64>,
    /// Z^T y (p).
    pub zy: Vec<f64>,
    /// Z^T Z (p x p, row-major).
    pub zz: Vec<f64>,
    /// Rows accumulated.
    pub rows: usize,
}

impl IvAccumulator {
    /// Zero accumulators for `p` parameters.
    pub fn new(p: usize) -> IvAccumulator {
        IvAccumulator {
            p,
            zw: vec![0.0; p * p],
            zy: vec![0.0; p],
            zz: vec![0.0; p * p],
            rows: 0,
        }
    }

    /// Add the row (w, y) with its instrument z.
    pub fn push(&mut self, z: &[f64], w: &[f64], y: f64) {
        let p = self.p;
        for i in 0..p {
            if z[i] == 0.0 {
                continue;
            }
            let zi = z[i];
            let row = &mut self.zw[i * p..(i + 1) * p];
            for (a, &b) in row.iter_mut().zip(w) {
                *a += zi * b;
            }
            let row = &mut self.zz[i * p..(i + 1) * p];
            for (a, &b) in row.iter_mut().zip(z) {
                *a += zi * b;
            }
            self.zy[i] += zi * y;
        }
        self.rows += 1;
    }

    /// Add the rows of another group (another log of the same robot).
    pub fn add(&mut self, other: &IvAccumulator) {
        assert_eq!(
            self.p, other.p,
            "accumulators of different parameter counts"
        );
        for (a, b) in self.zw.iter_mut().zip(&other.zw) {
            *a += b;
        }
        for (a, b) in self.zz.iter_mut().zip(&other.zz) {
            *a += b;
        }
        for (a, b) in self.zy.iter_mut().zip(&other.zy) {
            *a += b;
        }
        self.rows += other.rows;
    }
}

/// IDIM-IV estimate from weighted accumulators: X = (Z^T W)^-1 Z^T y, covariance
/// sigma^2 (Z^T W)^-1 Z^T Z (W^T Z)^-1 with sigma^2 = `sigma2` (the residual variance of the
/// IV estimate on the same weighted rows).
pub fn iv_solve(parts: &[(&IvAccumulator, f64)]) -> Result<(Vec<f64>, Mat<f64>)> {
    let p = parts[0].0.p;
    let mut zw = Mat::<f64>::zeros(p, p);
    let mut zz = Mat::<f64>::zeros(p, p);
    let mut zy = Mat::<f64>::zeros(p, 1);
    for (a, w) in parts {
        let w2 = w * w;
        for i in 0..p {
            for j in 0..p {
                zw[(i, j)] += w2 * a.zw[i * p + j];
                zz[(i, j)] += w2 * a.zz[i * p + j];
            }
            zy[(i, 0)] += w2 * a.zy[i];
        }
    }
    let svd = zw
        .thin_svd()
        .map_err(|e| Error::Numerical(format!("SVD of Z^T W failed: {e:?}")))?;
    let s: Vec<f64> = (0..p).map(|k| svd.S()[k]).collect();
    if s[p - 1].is_nan() || s[p - 1] <= 1e-14 * s[0] {
        return Err(Error::Numerical(format!(
            "the instrumental variables are not correlated with every column of the observation \
             matrix (Z^T W singular, sigma_min/sigma_max = {:.1e})",
            s[p - 1] / s[0]
        )));
    }
    // inverse of Z^T W = V S^-1 U^T
    let inv = Mat::from_fn(p, p, |i, j| {
        (0..p)
            .map(|k| svd.V()[(i, k)] * svd.U()[(j, k)] / s[k])
            .sum::<f64>()
    });
    let x: Vec<f64> = (0..p)
        .map(|i| (0..p).map(|j| inv[(i, j)] * zy[(j, 0)]).sum())
        .collect();
    // (Z^T W)^-1 Z^T Z (Z^T W)^-T
    let m = &inv * &zz * inv.transpose();
    Ok((x, m))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The streamed factor gives the same least squares as a QR of the whole matrix (nalgebra).
    #[test]
    fn streamed_factor_equals_whole_least_squares() {
        let mut rng = crate::sampling::rng(3);
        use rand::Rng;
        let (m, p) = (1000, 7);
        let w = nalgebra::DMatrix::from_fn(m, p, |_, _| rng.random_range(-1.0..1.0));
        let x0: Vec<f64> = (0..p).map(|k| k as f64 - 2.5).collect();
        let noise = nalgebra::DVector::from_fn(m, |_, _| rng.random_range(-0.01..0.01));
        let y = &w * nalgebra::DVector::from_column_slice(&x0) + noise;
        let mut f = TriangularFactor::new(p);
        let mut g = TriangularFactor::new(p);
        for r in 0..m {
            let row: Vec<f64> = w.row(r).iter().copied().collect();
            if r % 3 == 0 {
                g.push(&row, y[r]);
            } else {
                f.push(&row, y[r]);
            }
        }
        f.merge(&mut g);
        let names: Vec<String> = (0..p).map(|k| format!("x{k}")).collect();
        let sol = least_squares(f.factor(), m, &names).unwrap();
        let reference = w.clone().svd(true, true).solve(&y, 1e-14).unwrap();
        for k in 0..p {
            assert!((sol.x[k] - reference[k]).abs() < 1e-12, "{k}");
        }
        let res = (&y - &w * &reference).norm_squared();
        assert!((sol.residual_sq - res).abs() < 1e-10 * res);
        assert!((sol.output_sq - y.norm_squared()).abs() < 1e-10 * y.norm_squared());
        // covariance: sigma^2 (W^T W)^-1
        let inv = (w.transpose() * &w).try_inverse().unwrap() * (res / (m - p) as f64);
        for i in 0..p {
            assert!((sol.std[i] - inv[(i, i)].sqrt()).abs() < 1e-9 * sol.std[i]);
        }
        // restricted to columns 0, 2, 5
        let keep = [0, 2, 5];
        let sub = least_squares(&restrict(f.factor(), &keep), m, &names).unwrap();
        let ws = w.select_columns(keep.iter());
        let reference = ws.svd(true, true).solve(&y, 1e-14).unwrap();
        for (k, v) in sub.x.iter().enumerate() {
            assert!((v - reference[k]).abs() < 1e-12);
        }
    }

    #[test]
    fn rank_deficient_is_refused_with_the_parameters_named() {
        let mut f = TriangularFactor::new(3);
        for k in 0..50 {
            let a = (k as f64).sin();
            let b = (k as f64 * 0.3).cos();
            f.push(&[a, b, 2.0 * a - b], a + b);
        }
        let names = vec!["A".to_string(), "B".into(), "C".into()];
        let e = least_squares(f.factor(), 50, &names)
            .unwrap_err()
            .to_string();
        assert!(e.contains("rank-deficient") && e.contains('C'), "{e}");
    }
}
