//! Polishing of the interior point's answer (as OSQP's polish, here with PSD faces): the
//! interior point approaches the optimum from inside the cones and stops at a relative gap of
//! about 1e-10, so a constraint active at the optimum is still slightly inactive and a
//! parameter that only a weak term of the objective determines is accurate to about the
//! square root of the gap. The optimum is the minimizer of the objective on the face of the
//! cones it lies on: guess that face from the last iterate (a direction of a block, or a bound,
//! is active where its slack is smaller than its multiplier), minimize on it (an
//! equality-constrained QP: one linear system), and keep the result only if it is optimal for
//! the whole problem — primal feasible, its multipliers in the dual cones, and no worse than
//! the interior point's answer. Several guesses are tried (the ratio slack / multiplier
//! compared with 1, then with every threshold that changes the face, nearest to 1 first);
//! when none passes, the interior point's answer stands.

use super::{ConeVec, Equilibrated};
use nalgebra::{DMatrix, DVector, Matrix4, Vector4};

/// An equality constraint on the face: row . u = rhs, with the dual matrix (or bound) it
/// carries.
struct Row {
    coef: DVector<f64>,
    rhs: f64,
    /// Block j and sym(a b^T), or bound i.
    owner: Owner,
}

enum Owner {
    Block(usize, Matrix4<f64>),
    Bound(usize),
}

/// The face of the guess `ratio`: the eigenvectors of each block's slack whose eigenvalue is
/// below ratio times the multiplier's Rayleigh quotient, the bounds with s < ratio z; its
/// equality constraints S_j(u) v_a . w_b = 0 (v_a active, w_b any later eigenvector), s_i = 0.
fn face(eq: &Equilibrated, s: &ConeVec, z: &ConeVec, ratio: f64) -> Vec<Row> {
    let n = eq.n();
    let mut rows = Vec::new();
    for (j, (b, (sm, zm))) in eq.blocks.iter().zip(s.psd.iter().zip(&z.psd)).enumerate() {
        let eig = sm.symmetric_eigen();
        let vecs: Vec<Vector4<f64>> = (0..4).map(|k| eig.eigenvectors.column(k).into()).collect();
        let active: Vec<bool> = (0..4)
            .map(|k| eig.eigenvalues[k] < ratio * vecs[k].dot(&(zm * vecs[k])))
            .collect();
        for a in (0..4).filter(|&a| active[a]) {
            for c in (0..4).filter(|&c| !active[c] || c >= a) {
                let m = (vecs[a] * vecs[c].transpose() + vecs[c] * vecs[a].transpose()) * 0.5;
                let mut coef = DVector::zeros(n);
                for (v, ak) in &b.terms {
                    coef[*v] += ak.dot(&m);
                }
                rows.push(Row {
                    coef,
                    rhs: -b.constant.dot(&m),
                    owner: Owner::Block(j, m),
                });
            }
        }
    }
    for (i, l) in eq.lin.iter().enumerate() {
        if s.lin[i] < ratio * z.lin[i] {
            let mut coef = DVector::zeros(n);
            coef[l.var] = l.a;
            rows.push(Row {
                coef,
                rhs: -l.s0,
                owner: Owner::Bound(i),
            });
        }
    }
    rows
}

/// Minimize 1/2 u^T P u + q^T u on the face (with a 1e-12 pull toward `near`, which only
/// chooses among the minimizers when P is singular on the face): u and the multipliers.
fn solve_face(
    eq: &Equilibrated,
    rows: &[Row],
    near: &DVector<f64>,
) -> Option<(DVector<f64>, DVector<f64>)> {
    let n = eq.n();
    let m = rows.len();
    if m > n {
        return None;
    }
    let delta = 1e-12 * eq.p.diagonal().amax().max(1e-300);
    let mut k = DMatrix::zeros(n + m, n + m);
    k.view_mut((0, 0), (n, n)).copy_from(&eq.p);
    for i in 0..n {
        k[(i, i)] += delta;
    }
    let mut rhs = DVector::zeros(n + m);
    rhs.rows_mut(0, n).copy_from(&(near * delta - &eq.q));
    for (r, row) in rows.iter().enumerate() {
        for c in 0..n {
            k[(n + r, c)] = row.coef[c];
            k[(c, n + r)] = row.coef[c];
        }
        rhs[n + r] = row.rhs;
    }
    let lu = k.clone().lu();
    let mut sol = lu.solve(&rhs)?;
    for _ in 0..2 {
        let r = &rhs - &k * &sol;
        sol += lu.solve(&r)?;
    }
    if sol.iter().any(|v| !v.is_finite()) {
        return None;
    }
    // K [u; w] = [-q; d] with w = -nu: P u + q = C^T nu
    let u = sol.rows(0, n).into_owned();
    let nu = -sol.rows(n, m).into_owned();
    Some((u, nu))
}

/// The polished point (u, z) if it is optimal for the whole problem to `tol`.
fn check(
    eq: &Equilibrated,
    rows: &[Row],
    u: &DVector<f64>,
    nu: &DVector<f64>,
    objective_ipm: f64,
    tol: f64,
) -> Option<ConeVec> {
    let mut z = ConeVec {
        psd: vec![Matrix4::zeros(); eq.blocks.len()],
        lin: vec![0.0; eq.lin.len()],
    };
    for (row, v) in rows.iter().zip(nu.iter()) {
        match &row.owner {
            Owner::Block(j, m) => z.psd[*j] += m * *v,
            Owner::Bound(i) => z.lin[*i] = *v,
        }
    }
    let mut s = eq.constant();
    s.axpy(1.0, &eq.apply(u));
    let size = s.norm_inf().max(1.0);
    let zsize = z.norm_inf().max(1.0);
    let psd_ok = |m: &Matrix4<f64>, scale: f64| m.symmetric_eigenvalues().min() >= -tol * scale;
    let primal = s.psd.iter().all(|m| psd_ok(m, size)) && s.lin.iter().all(|v| *v >= -tol * size);
    let dual = z.psd.iter().all(|m| psd_ok(m, zsize)) && z.lin.iter().all(|v| *v >= -tol * zsize);
    let stationarity = (&eq.p * u + &eq.q - eq.adjoint(&z)).amax();
    let objective = 0.5 * u.dot(&(&eq.p * u)) + eq.q.dot(u);
    let better = objective <= objective_ipm + tol * objective_ipm.abs().max(1.0);
    let stationary = stationarity <= tol * eq.q.amax().max(eq.p.amax()).max(1.0);
    (primal && dual && better && stationary).then_some(z)
}

/// Try the face guesses; the first whose minimizer is optimal replaces (u, s, z).
pub(super) fn polish(
    eq: &Equilibrated,
    u: &mut DVector<f64>,
    s: &mut ConeVec,
    z: &mut ConeVec,
    tol: f64,
) -> bool {
    let objective_ipm = 0.5 * u.dot(&(&eq.p * &*u)) + eq.q.dot(u);
    for ratio in ratios(s, z) {
        let rows = face(eq, s, z, ratio);
        let Some((up, nu)) = solve_face(eq, &rows, u) else {
            continue;
        };
        if let Some(zp) = check(eq, &rows, &up, &nu, objective_ipm, tol) {
            let mut sp = eq.constant();
            sp.axpy(1.0, &eq.apply(&up));
            *u = up;
            *s = sp;
            *z = zp;
            return true;
        }
    }
    false
}

/// The thresholds to try: 1 first, then one between every two consecutive values of the
/// directions' slack / multiplier ratios (every distinct face the ratio rule can give), nearest
/// to 1 first, at most MAX_FACES in all.
fn ratios(s: &ConeVec, z: &ConeVec) -> Vec<f64> {
    let mut r: Vec<f64> = Vec::new();
    for (sm, zm) in s.psd.iter().zip(&z.psd) {
        let eig = sm.symmetric_eigen();
        for k in 0..4 {
            let v: Vector4<f64> = eig.eigenvectors.column(k).into();
            r.push(eig.eigenvalues[k].max(0.0) / v.dot(&(zm * v)).max(f64::MIN_POSITIVE));
        }
    }
    r.extend(
        s.lin
            .iter()
            .zip(&z.lin)
            .map(|(s, z)| s.max(0.0) / z.max(f64::MIN_POSITIVE)),
    );
    r.retain(|v| v.is_finite());
    r.sort_by(f64::total_cmp);
    let mut cuts: Vec<f64> = r
        .windows(2)
        .map(|w| (w[0] * w[1]).sqrt().max(w[0]))
        .collect();
    cuts.sort_by(|a, b| a.ln().abs().total_cmp(&b.ln().abs()));
    let mut out = vec![1.0];
    out.extend(cuts.into_iter().filter(|c| *c > 0.0));
    out.dedup();
    out.truncate(MAX_FACES);
    out
}

/// Faces tried at most.
const MAX_FACES: usize = 40;
