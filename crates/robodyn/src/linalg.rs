//! Small dense solves on preallocated buffers for the closed-chain models (p x p matrices Wp with p
//! the number of closure equations, a handful): LU with partial pivoting in place, the sign of the
//! determinant (the assembly-branch invariant) and the exact reciprocal 1-norm condition number.
//!
//! Written here because nalgebra's dynamic `LU` allocates its permutation at every
//! factorization, which would make the closed-chain evaluation allocate in a control loop; the
//! allocating paths and everything larger use nalgebra.

use nalgebra::DMatrix;

/// LU factors of a square matrix, P A = L U (unit lower L below the diagonal, U on and above),
/// with the buffers of the condition number.
#[derive(Clone, Debug)]
pub(crate) struct SmallLu {
    pub lu: DMatrix<f64>,
    piv: Vec<usize>,
    /// Parity of the row permutation (+1 / -1).
    parity: f64,
    /// ||A||_1 of the factored matrix.
    norm1: f64,
    col: Vec<f64>,
    /// False when a pivot was exactly zero (or not finite).
    pub regular: bool,
}

impl SmallLu {
    pub fn new(n: usize) -> Self {
        SmallLu {
            lu: DMatrix::zeros(n, n),
            piv: vec![0; n],
            parity: 1.0,
            norm1: 0.0,
            col: vec![0.0; n],
            regular: false,
        }
    }

    /// Factor the matrix now in `self.lu` (overwritten by its factors).
    pub fn factor(&mut self) {
        let a = &mut self.lu;
        let n = a.nrows();
        self.norm1 = (0..n)
            .map(|c| a.column(c).iter().map(|x| x.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        self.parity = 1.0;
        self.regular = true;
        for k in 0..n {
            let (mut p, mut best) = (k, a[(k, k)].abs());
            for r in k + 1..n {
                if a[(r, k)].abs() > best {
                    best = a[(r, k)].abs();
                    p = r;
                }
            }
            self.piv[k] = p;
            if p != k {
                a.swap_rows(k, p);
                self.parity = -self.parity;
            }
            let d = a[(k, k)];
            if d == 0.0 || !d.is_finite() {
                self.regular = false;
                continue;
            }
            for r in k + 1..n {
                let f = a[(r, k)] / d;
                a[(r, k)] = f;
                for c in k + 1..n {
                    let u = a[(k, c)];
                    a[(r, c)] -= f * u;
                }
            }
        }
    }

    /// Sign of det A (0 when singular).
    pub fn det_sign(&self) -> f64 {
        if !self.regular {
            return 0.0;
        }
        let mut s = self.parity;
        for k in 0..self.lu.nrows() {
            s *= self.lu[(k, k)].signum();
        }
        s
    }

    /// Solve A x = b in place.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.lu.nrows();
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for r in 0..n {
            let mut s = b[r];
            for c in 0..r {
                s -= self.lu[(r, c)] * b[c];
            }
            b[r] = s;
        }
        for r in (0..n).rev() {
            let mut s = b[r];
            for c in r + 1..n {
                s -= self.lu[(r, c)] * b[c];
            }
            b[r] = s / self.lu[(r, r)];
        }
    }

    /// Solve A^T x = b in place.
    pub fn solve_transpose(&self, b: &mut [f64]) {
        let n = self.lu.nrows();
        // A^T = U^T L^T P: solve U^T y = b, L^T z = y, x = P^T z
        for r in 0..n {
            let mut s = b[r];
            for c in 0..r {
                s -= self.lu[(c, r)] * b[c];
            }
            b[r] = s / self.lu[(r, r)];
        }
        for r in (0..n).rev() {
            let mut s = b[r];
            for c in r + 1..n {
                s -= self.lu[(c, r)] * b[c];
            }
            b[r] = s;
        }
        for k in (0..n).rev() {
            b.swap(k, self.piv[k]);
        }
    }

    /// Solve A X = B in place, column by column.
    pub fn solve_matrix(&mut self, b: &mut DMatrix<f64>) {
        let mut col = std::mem::take(&mut self.col);
        for c in 0..b.ncols() {
            col.copy_from_slice(b.column(c).as_slice());
            self.solve(&mut col);
            b.column_mut(c).copy_from_slice(&col);
        }
        self.col = col;
    }

    /// Reciprocal 1-norm condition number 1 / (||A||_1 ||A^-1||_1), exact: ||A^-1||_1 is the
    /// largest column sum of A^-1, solved column by column (n solves of an n x n system). 0 when
    /// singular.
    pub fn rcond(&mut self) -> f64 {
        if !self.regular || self.norm1 == 0.0 {
            return 0.0;
        }
        let n = self.lu.nrows();
        let mut col = std::mem::take(&mut self.col);
        let mut inv_norm: f64 = 0.0;
        for k in 0..n {
            col.iter_mut().for_each(|x| *x = 0.0);
            col[k] = 1.0;
            self.solve(&mut col);
            inv_norm = inv_norm.max(col.iter().map(|x| x.abs()).sum());
        }
        self.col = col;
        let r = 1.0 / (self.norm1 * inv_norm);
        if r.is_finite() {
            r
        } else {
            0.0
        }
    }
}

/// Reciprocal 1-norm condition number of a symmetric positive definite matrix from its
/// Cholesky factor (solves column by column into `col`).
pub(crate) fn rcond_cholesky(
    chol: &nalgebra::Cholesky<f64, nalgebra::Dyn>,
    norm1: f64,
    col: &mut nalgebra::DVector<f64>,
) -> f64 {
    let n = col.len();
    let mut inv_norm: f64 = 0.0;
    for k in 0..n {
        col.as_mut_slice().fill(0.0);
        col[k] = 1.0;
        chol.solve_mut(col);
        inv_norm = inv_norm.max(col.iter().map(|x| x.abs()).sum());
    }
    let r = 1.0 / (norm1 * inv_norm);
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

/// ||A||_1, the largest column sum.
pub(crate) fn norm1(a: &DMatrix<f64>) -> f64 {
    (0..a.ncols())
        .map(|c| a.column(c).iter().map(|x| x.abs()).sum::<f64>())
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lu_solves_and_conditions_like_nalgebra() {
        let a = DMatrix::from_row_slice(3, 3, &[0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 3.0, 0.5, -2.0]);
        let mut lu = SmallLu::new(3);
        lu.lu.copy_from(&a);
        lu.factor();
        let b = [1.0, -2.0, 0.5];
        let mut x = b;
        lu.solve(&mut x);
        let r = &a * nalgebra::DVector::from_column_slice(&x)
            - nalgebra::DVector::from_column_slice(&b);
        assert!(r.amax() < 1e-14);
        let mut y = b;
        lu.solve_transpose(&mut y);
        let r = a.transpose() * nalgebra::DVector::from_column_slice(&y)
            - nalgebra::DVector::from_column_slice(&b);
        assert!(r.amax() < 1e-14);
        assert_eq!(lu.det_sign(), a.determinant().signum());
        let inv = a.clone().try_inverse().unwrap();
        let expected = 1.0 / (norm1(&a) * norm1(&inv));
        assert!((lu.rcond() - expected).abs() < 1e-14 * expected.max(1.0));
    }
}
