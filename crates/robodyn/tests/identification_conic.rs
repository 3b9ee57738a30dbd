//! The interior-point solver of the consistency SDP (`identification::conic`), checked
//! independently of its own formulas: problems with a known analytic optimum (an unconstrained
//! optimum inside the cone is returned as it is; the Frobenius projection onto the PSD cone is
//! the eigenvalue clipping; bounds clamp), optima on the boundary (rank-deficient
//! pseudo-inertias), the KKT conditions at the returned point of random problems (fixed seeds)
//! recomputed here from the blocks' matrices, and errors (not answers) for infeasible problems
//! and an exhausted iteration budget.

use nalgebra::{DMatrix, DVector, Matrix4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robodyn::identification::conic::{solve, ConicQp, ConicSolution, PsdBlock, Settings};
use robodyn::identification::consistency::{from_pseudo_inertia, pseudo_inertia};

/// The link block of variables 10 j .. 10 j + 10: their pseudo-inertia PSD.
fn link_block(j: usize) -> PsdBlock {
    PsdBlock {
        constant: Matrix4::zeros(),
        terms: (0..10)
            .map(|l| {
                let mut e = [0.0; 10];
                e[l] = 1.0;
                (10 * j + l, pseudo_inertia(&e))
            })
            .collect(),
    }
}

/// A random pseudo-inertia B B^T of rank `rank` (a rigid body's, PSD), scaled like a link of a
/// few kilograms and tens of centimetres.
fn random_psd(rng: &mut ChaCha8Rng, rank: usize) -> Matrix4<f64> {
    let mut j = Matrix4::zeros();
    let scale = Matrix4::from_diagonal(&nalgebra::Vector4::new(0.2, 0.2, 0.2, 1.5));
    for _ in 0..rank {
        let b = nalgebra::Vector4::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let b = scale * b;
        j += b * b.transpose();
    }
    j
}

fn random_spd(rng: &mut ChaCha8Rng, n: usize, condition: f64) -> DMatrix<f64> {
    let a = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
    let q = a.qr().q();
    let d = DVector::from_fn(n, |i, _| {
        condition.powf(-(i as f64) / (n - 1).max(1) as f64)
    });
    &q * DMatrix::from_diagonal(&d) * q.transpose()
}

/// The largest |a_i - b_i| and the largest |b_i|.
fn max_error(a: &[f64], b: &[f64]) -> (f64, f64) {
    let err = a
        .iter()
        .zip(b)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    (err, b.iter().map(|v| v.abs()).fold(0.0, f64::max))
}

fn objective(qp: &ConicQp, x: &[f64]) -> f64 {
    let x = DVector::from_column_slice(x);
    0.5 * x.dot(&(&qp.p * &x)) + qp.q.dot(&x)
}

/// The KKT conditions, recomputed from the problem's matrices: S_j(x) and Z_j PSD, bounds and
/// their multipliers >= 0, complementarity, and stationarity
/// P x + q = sum_j L_j^T Z_j + lower_dual - upper_dual (relative to the size of its terms).
fn assert_kkt(qp: &ConicQp, sol: &ConicSolution, tol: f64) {
    let x = &sol.x;
    let mut grad = &qp.p * DVector::from_column_slice(x) + &qp.q;
    let mut size = grad.amax().max(qp.q.amax());
    for (b, z) in qp.psd.iter().zip(&sol.psd_dual) {
        let s = b.value(x);
        let es = s.symmetric_eigenvalues();
        let ez = z.symmetric_eigenvalues();
        assert!(es.min() >= -tol * es.amax().max(1.0), "S {es:?}");
        assert!(ez.min() >= -tol * ez.amax().max(1.0), "Z {ez:?}");
        let comp = (s * z).trace();
        assert!(
            comp.abs() <= tol * (1.0 + s.norm() * z.norm()),
            "tr(S Z) = {comp:e}"
        );
        for (v, a) in &b.terms {
            let t = (a * z).trace();
            grad[*v] -= t;
            size = size.max(t.abs());
        }
    }
    for (&(v, l), &y) in qp.lower.iter().zip(&sol.lower_dual) {
        assert!(
            x[v] >= l - tol * l.abs().max(1.0) && y >= -tol,
            "x{v} {} >= {l}",
            x[v]
        );
        assert!((y * (x[v] - l)).abs() <= tol * (1.0 + y.abs()), "lower {v}");
        grad[v] -= y;
    }
    for (&(v, u), &y) in qp.upper.iter().zip(&sol.upper_dual) {
        assert!(
            x[v] <= u + tol * u.abs().max(1.0) && y >= -tol,
            "x{v} {} <= {u}",
            x[v]
        );
        assert!((y * (u - x[v])).abs() <= tol * (1.0 + y.abs()), "upper {v}");
        grad[v] += y;
    }
    assert!(
        grad.amax() <= tol * size.max(1.0),
        "stationarity residual {:e} (terms {size:e})",
        grad.amax()
    );
}

/// The unconstrained minimizer -P^-1 q is strictly consistent: the solver returns it.
#[test]
fn an_interior_unconstrained_optimum_is_returned() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    for case in 0..5 {
        let nl = 1 + case;
        let n = 10 * nl + 3;
        let mut truth = vec![0.0; n];
        for j in 0..nl {
            let k = from_pseudo_inertia(&random_psd(&mut rng, 4));
            truth[10 * j..10 * j + 10].copy_from_slice(&k);
        }
        for v in &mut truth[10 * nl..] {
            *v = rng.random_range(0.1..2.0);
        }
        let p = random_spd(&mut rng, n, 1e6);
        let q = -(&p * DVector::from_column_slice(&truth));
        let qp = ConicQp {
            p,
            q,
            psd: (0..nl).map(link_block).collect(),
            lower: (10 * nl..n).map(|v| (v, 0.0)).collect(),
            upper: vec![],
        };
        let sol = solve(&qp, &Settings::default()).unwrap();
        let (err, scale) = max_error(&sol.x, &truth);
        assert!(err < 1e-8 * scale, "case {case}: error {err:e}");
        assert_kkt(&qp, &sol, 1e-8);
    }
}

/// min ||J(x) - J0||_F^2 subject to J(x) PSD is J0 with its negative eigenvalues set to zero
/// (the Frobenius projection onto the PSD cone), a boundary point of rank 3, 2 or 1.
#[test]
fn the_projection_onto_the_psd_cone_is_the_eigenvalue_clipping() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let block = link_block(0);
    // P = 2 L^T L, q = -2 L^T J0 with L the map of the 10 parameters to J
    let gram = DMatrix::from_fn(10, 10, |k, l| block.terms[k].1.dot(&block.terms[l].1));
    for negatives in [1, 2, 3, 1, 2, 3] {
        let m = DMatrix::from_fn(4, 4, |_, _| rng.random_range(-1.0..1.0));
        let u = m.qr().q();
        let ev: Vec<f64> = (0..4)
            .map(|i| {
                let v = rng.random_range(0.2..2.0);
                if i < negatives {
                    -v
                } else {
                    v
                }
            })
            .collect();
        let j0 = Matrix4::from_fn(|r, c| (0..4).map(|i| u[(r, i)] * ev[i] * u[(c, i)]).sum());
        let projected =
            Matrix4::from_fn(|r, c| (0..4).map(|i| u[(r, i)] * ev[i].max(0.0) * u[(c, i)]).sum());
        let q = DVector::from_fn(10, |k, _| -2.0 * block.terms[k].1.dot(&j0));
        let qp = ConicQp {
            p: &gram * 2.0,
            q,
            psd: vec![block.clone()],
            lower: vec![],
            upper: vec![],
        };
        let sol = solve(&qp, &Settings::default()).unwrap();
        let j = block.value(&sol.x);
        let err = (j - projected).amax();
        eprintln!(
            "rank {}: {} iterations, error {err:.1e}",
            4 - negatives,
            sol.iterations
        );
        assert!(err < 1e-7, "rank {}: error {err:e}", 4 - negatives);
        assert_kkt(&qp, &sol, 1e-8);
    }
}

/// Bounds alone: the minimizer of a separable quadratic is the clamped unconstrained one.
#[test]
fn bounds_clamp_a_separable_quadratic() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let n = 12;
    let w: Vec<f64> = (0..n)
        .map(|_| 10f64.powf(rng.random_range(-4.0..4.0)))
        .collect();
    let a: Vec<f64> = (0..n).map(|_| rng.random_range(-3.0..3.0)).collect();
    let lo: Vec<f64> = (0..n).map(|_| rng.random_range(-2.0..0.0)).collect();
    let hi: Vec<f64> = (0..n).map(|_| rng.random_range(0.0..2.0)).collect();
    let qp = ConicQp {
        p: DMatrix::from_diagonal(&DVector::from_column_slice(&w)),
        q: DVector::from_fn(n, |i, _| -w[i] * a[i]),
        psd: vec![],
        lower: (0..n).map(|i| (i, lo[i])).collect(),
        upper: (0..n).map(|i| (i, hi[i])).collect(),
    };
    let sol = solve(&qp, &Settings::default()).unwrap();
    for i in 0..n {
        let want = a[i].clamp(lo[i], hi[i]);
        assert!(
            (sol.x[i] - want).abs() < 1e-8,
            "{i}: {} vs {want}",
            sol.x[i]
        );
    }
    assert_kkt(&qp, &sol, 1e-8);
}

/// Random problems shaped like the identification's (fixed seeds): several links, drives >= 0,
/// some bounds, an ill-conditioned P whose unconstrained minimizer is inconsistent. The KKT
/// conditions hold at the returned point, and no random feasible point nearby is better.
#[test]
fn random_problems_satisfy_the_kkt_conditions() {
    for seed in 0..12u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(100 + seed);
        let nl = 1 + (seed as usize % 5);
        let nd = 2 * nl;
        let n = 10 * nl + nd;
        let p = random_spd(&mut rng, n, 10f64.powi(2 + (seed % 7) as i32));
        let target: Vec<f64> = (0..n).map(|_| rng.random_range(-1.0..1.0)).collect();
        let q = -(&p * DVector::from_column_slice(&target));
        let mut upper = vec![];
        if seed % 3 == 0 {
            upper.push((10 * nl, 0.5));
        }
        let qp = ConicQp {
            p,
            q,
            psd: (0..nl).map(link_block).collect(),
            lower: (10 * nl..n).map(|v| (v, 0.0)).collect(),
            upper,
        };
        let sol = solve(&qp, &Settings::default()).unwrap();
        eprintln!(
            "seed {seed}: {} links, {} iterations, residuals {:.0e} {:.0e} {:.0e}",
            nl, sol.iterations, sol.primal_residual, sol.dual_residual, sol.gap
        );
        assert!(sol.iterations < 60);
        assert_kkt(&qp, &sol, 1e-7);
        // the convex combination with a strictly feasible point stays feasible: never better
        let mut inner = vec![0.0; n];
        for j in 0..nl {
            let k = from_pseudo_inertia(&Matrix4::identity());
            inner[10 * j..10 * j + 10].copy_from_slice(&k);
        }
        for v in &mut inner[10 * nl..] {
            *v = 0.1;
        }
        let f = objective(&qp, &sol.x);
        for t in [1e-6, 1e-4, 1e-2] {
            let y: Vec<f64> = sol
                .x
                .iter()
                .zip(&inner)
                .map(|(a, b)| (1.0 - t) * a + t * b)
                .collect();
            assert!(
                objective(&qp, &y) >= f - 1e-9 * f.abs().max(1.0),
                "seed {seed}"
            );
        }
    }
}

/// An optimum on the boundary that the unconstrained minimizer already reaches: a point mass
/// (pseudo-inertia of rank 1) and a planar body (rank 3) fitted by least squares are returned
/// as they are, although the constraint is active and its multiplier zero (no strict
/// complementarity, the hard case of interior-point methods).
#[test]
fn a_rank_deficient_optimum_is_found() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for rank in [1, 2, 3] {
        let j0 = random_psd(&mut rng, rank);
        let truth = from_pseudo_inertia(&j0);
        let p = random_spd(&mut rng, 10, 1e4);
        let q = -(&p * DVector::from_column_slice(&truth));
        let qp = ConicQp {
            p,
            q,
            psd: vec![link_block(0)],
            lower: vec![],
            upper: vec![],
        };
        let sol = solve(&qp, &Settings::default()).unwrap();
        let (err, scale) = max_error(&sol.x, &truth);
        eprintln!(
            "rank {rank}: {} iterations, error {err:.1e}",
            sol.iterations
        );
        assert!(err < 1e-6 * scale, "rank {rank}: error {err:e}");
        let f = objective(&qp, &sol.x);
        let f0 = objective(&qp, &truth);
        assert!((f - f0).abs() <= 1e-9 * f0.abs(), "objective {f} vs {f0}");
    }
}

/// No feasible point, or too few iterations: an error, not an answer.
#[test]
fn infeasible_problems_and_exhausted_budgets_are_errors() {
    let qp = ConicQp {
        p: DMatrix::identity(2, 2),
        q: DVector::from_column_slice(&[1.0, -1.0]),
        psd: vec![],
        lower: vec![(0, 1.0)],
        upper: vec![(0, 0.0)],
    };
    let e = solve(&qp, &Settings::default()).unwrap_err().to_string();
    assert!(e.contains("interior-point"), "{e}");
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let qp = ConicQp {
        p: random_spd(&mut rng, 20, 1e3),
        q: DVector::from_fn(20, |_, _| rng.random_range(-1.0..1.0)),
        psd: vec![link_block(0)],
        lower: (10..20).map(|v| (v, 0.0)).collect(),
        upper: vec![],
    };
    let settings = Settings {
        max_iterations: 2,
        ..Settings::default()
    };
    let e = solve(&qp, &settings).unwrap_err().to_string();
    assert!(e.contains("not converged in 2 iterations"), "{e}");
    assert!(solve(&qp, &Settings::default()).is_ok());
}
