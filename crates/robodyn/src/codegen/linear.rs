//! Small linear systems written out symbolically for a fixed size: the L' D L solution of the
//! direct dynamic model along the parent array (A symmetric positive definite, branch-sparse) and Gaussian elimination with a row
//! order fixed at generation time for the closed-chain models (Wp, not symmetric).

use super::pair_name;
use crate::error::{Error, Result};
use crate::scalar::DynScalar as _;
use nalgebra::DMatrix;
use robodyn_symbolic::program::name_value;
use robodyn_symbolic::Expr;

/// Solve A x = b for the joint-space inertia matrix of a tree by A = L' D L written out for
/// the fixed size, walking the parent array (Featherstone's LTDL, *Rigid Body Dynamics
/// Algorithms* §6.5; A symmetric positive definite).
///
/// `parent[k]` is the parent of index k + 1 (1-based, 0 for the base; parents are numbered
/// before their children). A_ik is structurally zero unless one of i, k is an ancestor of the
/// other, and eliminating the last index first keeps the fill-in inside those pairs, so only
/// the entries (k, i) with i an ancestor of k are ever formed: O(n d²) operations for depth d
/// instead of the n³/6 of a dense factorization (a serial chain, d = n, stays cubic). For
/// k = n..1: D_k = A_kk, and for every ancestor i of k, U_ki = A_ki (final), L_ki = U_ki / D_k,
/// A_ij -= L_ki U_kj for the ancestors j of i (j = i included). Then L' y = b (children first),
/// x = D^-1 y - L x (parents first). Only the entries of `a` on and below the diagonal between
/// a link and its ancestors are read.
///
/// Intermediates are named with `labels` (the frame numbers): `D<k>`, `U<k><i>`, `L<k><i>`,
/// `Y<k>`, `X<k>`.
pub(crate) fn ltdl_solve(
    mut a: DMatrix<Expr>,
    mut b: Vec<Expr>,
    parent: &[usize],
    labels: &[usize],
) -> Vec<Expr> {
    let n = b.len();
    assert!(a.shape() == (n, n) && parent.len() == n && labels.len() == n);
    // ancestors of index k (0-based), nearest first
    let up = |k: usize| parent[k].checked_sub(1);
    let ancestors = |k: usize| std::iter::successors(up(k), |&i| up(i));
    let mut d = vec![Expr::zero(); n];
    for k in (0..n).rev() {
        // row k is final: every descendant of k (numbered after it) has been eliminated
        d[k] = a[(k, k)].clone().named(|| format!("D{}", labels[k]));
        for i in ancestors(k) {
            let u = a[(k, i)].clone();
            a[(k, i)] = u.named(|| pair_name("U", labels[k], labels[i]));
        }
        for i in ancestors(k) {
            let u = a[(k, i)].clone();
            if u.is_zero() {
                continue;
            }
            let l = (u / d[k].clone()).named(|| pair_name("L", labels[k], labels[i]));
            for j in std::iter::once(i).chain(ancestors(i)) {
                let v = a[(i, j)].clone() - l.clone() * a[(k, j)].clone();
                a[(i, j)] = v;
            }
            a[(k, i)] = l;
        }
    }
    // L' y = b: y_k final once its descendants are done
    for k in (0..n).rev() {
        let y = std::mem::replace(&mut b[k], Expr::zero()).named(|| format!("Y{}", labels[k]));
        for i in ancestors(k) {
            if !a[(k, i)].is_zero() {
                let v = b[i].clone() - a[(k, i)].clone() * y.clone();
                b[i] = v;
            }
        }
        b[k] = y;
    }
    // L x = D^-1 y, parents first
    let mut x = vec![Expr::zero(); n];
    for k in 0..n {
        let mut s = b[k].clone() / d[k].clone();
        for i in ancestors(k) {
            if !a[(k, i)].is_zero() {
                s -= a[(k, i)].clone() * x[i].clone();
            }
        }
        x[k] = s.named(|| format!("X{}", labels[k]));
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
