//! Small linear systems written out symbolically for a fixed size: the L D L' solution of the
//! direct dynamic model (A symmetric positive definite) and Gaussian elimination with a row
//! order fixed at generation time for the closed-chain models (Wp, not symmetric).

use super::pair_name;
use crate::error::{Error, Result};
use crate::scalar::DynScalar as _;
use nalgebra::DMatrix;
use robodyn_symbolic::program::name_value;
use robodyn_symbolic::Expr;

/// Solve A x = b by A = L D L' written out for the fixed size (A symmetric positive definite):
/// D_i = A_ii - sum_k L_ik^2 D_k, L_ij = (A_ij - sum_k L_ik L_jk D_k) / D_j, then forward,
/// diagonal and backward substitution. Intermediates are named L<i><j>, D<i>, Y<i>, X<i>.
pub(crate) fn ldl_solve(a: &[Vec<Expr>], b: &[Expr], joints: &[usize]) -> Vec<Expr> {
    let n = a.len();
    let mut l = vec![vec![Expr::zero(); n]; n];
    let mut d = vec![Expr::zero(); n];
    let mut ld = vec![vec![Expr::zero(); n]; n]; // L_ik D_k
    for i in 0..n {
        for j in 0..i {
            let mut s = a[i][j].clone();
            for k in 0..j {
                s -= ld[i][k].clone() * l[j][k].clone();
            }
            let s = s.named(|| pair_name("U", joints[i], joints[j]));
            ld[i][j] = s.clone();
            l[i][j] = (s / d[j].clone()).named(|| pair_name("L", joints[i], joints[j]));
        }
        let mut s = a[i][i].clone();
        for k in 0..i {
            s -= ld[i][k].clone() * l[i][k].clone();
        }
        d[i] = s.named(|| format!("D{}", joints[i]));
    }
    let mut y = vec![Expr::zero(); n];
    for i in 0..n {
        let mut s = b[i].clone();
        for k in 0..i {
            s -= l[i][k].clone() * y[k].clone();
        }
        y[i] = s.named(|| format!("Y{}", joints[i]));
    }
    let mut x = vec![Expr::zero(); n];
    for i in (0..n).rev() {
        let mut s = y[i].clone() / d[i].clone();
        for k in i + 1..n {
            s -= l[k][i].clone() * x[k].clone();
        }
        x[i] = if i == 0 {
            s
        } else {
            s.named(|| format!("X{}", joints[i]))
        };
    }
    x
}

/// Solve M X = B (M square, p x p; B p x m) by Gaussian elimination written out. Generated code
/// cannot pivot at run time without branches, so the row order is fixed here: `m_ref` is M at a
/// reference configuration and each step takes the remaining row with the largest pivot there
/// (partial pivoting). The result is valid wherever M is regular and those pivots do not
/// vanish, i.e. in the neighbourhood of the reference configuration on its assembly branch.
///
/// Intermediates: `IP<c>` = 1 / pivot of column c, `LU<r>_<c>` the eliminated entries (L below
/// the pivots, U to their right), `RHS<r>_<k>` the updated right-hand sides; the solution gets
/// `name(row, column)`. Fails when M is singular at the reference (relative tolerance 1e-9).
pub(crate) fn lu_solve(
    m: &[Vec<Expr>],
    b: &[Vec<Expr>],
    m_ref: &DMatrix<f64>,
    name: &dyn Fn(usize, usize) -> String,
) -> Result<Vec<Vec<Expr>>> {
    let p = m.len();
    let ncols = b.first().map_or(0, Vec::len);
    let mut a: Vec<Vec<Expr>> = m.to_vec();
    let mut rhs: Vec<Vec<Expr>> = b.to_vec();
    let mut num = m_ref.clone();
    let scale = num.amax().max(f64::MIN_POSITIVE);
    let mut free: Vec<usize> = (0..p).collect();
    let mut order = Vec::with_capacity(p);
    let mut inv = vec![Expr::zero(); p];
    for c in 0..p {
        let (k, &piv) = free
            .iter()
            .enumerate()
            .max_by(|x, y| num[(*x.1, c)].abs().total_cmp(&num[(*y.1, c)].abs()))
            .expect("a free row remains");
        if num[(piv, c)].abs() <= 1e-9 * scale {
            return Err(Error::Numerical(format!(
                "the {p} x {p} matrix is singular at the reference configuration (column {} \
                 has no pivot): the loop-closure Jacobian Wp must be regular there",
                c + 1
            )));
        }
        free.remove(k);
        order.push(piv);
        inv[c] = name_value(Expr::one() / a[piv][c].clone(), || format!("IP{}", c + 1));
        for &r in &free {
            let f = num[(r, c)] / num[(piv, c)];
            for j in c..p {
                num[(r, j)] -= f * num[(piv, j)];
            }
            let fs = (a[r][c].clone() * inv[c].clone()).named(|| format!("LU{}_{}", r + 1, c + 1));
            if fs.is_zero() {
                continue;
            }
            for j in c + 1..p {
                let v = a[r][j].clone() - fs.clone() * a[piv][j].clone();
                a[r][j] = v.named(|| format!("LU{}_{}", r + 1, j + 1));
            }
            for k in 0..ncols {
                let v = rhs[r][k].clone() - fs.clone() * rhs[piv][k].clone();
                rhs[r][k] = v.named(|| format!("RHS{}_{}", r + 1, k + 1));
            }
        }
    }
    // back substitution, last pivot first
    let mut x = vec![vec![Expr::zero(); ncols]; p];
    for c in (0..p).rev() {
        let piv = order[c];
        for k in 0..ncols {
            let mut s = rhs[piv][k].clone();
            for j in c + 1..p {
                s -= a[piv][j].clone() * x[j][k].clone();
            }
            x[c][k] = (s * inv[c].clone()).named(|| name(c, k));
        }
    }
    Ok(x)
}
