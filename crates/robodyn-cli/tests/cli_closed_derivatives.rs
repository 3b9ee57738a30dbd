//! `idm --derivatives` and `ddm --derivatives` on closed chains (the matrices over the actuated
//! joints, the loops kept closed on the assembly branch) and `ddm --derivatives` on a tree:
//! checked against central differences of the library's closed models ALONG THE BRANCH (an
//! independent route: the models' values only, the tracker re-closing the loops at q_a ± h;
//! h = 1e-4, truncation ~1e-9, bound 2e-6 relative), A against the closed direct model's A_cl,
//! Ainv A_cl = I, and the CSV against the JSON.

use robodyn::nalgebra::{DMatrix, DVector};
use robodyn::{Branch, ClosedChain};

mod common;
use common::{robot, run};

/// A closed model evaluated on a tracker: its N values at a state.
type Model<'a> = dyn Fn(&mut Branch, &[Vec<f64>; 3]) -> DVector<f64> + 'a;

const H: f64 = 1e-4;

fn matrix(v: &serde_json::Value) -> DMatrix<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(v.clone()).unwrap();
    DMatrix::from_fn(rows.len(), rows[0].len(), |r, c| rows[r][c])
}

fn list(v: &[f64]) -> String {
    v.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(",")
}

fn rel(m: &DMatrix<f64>, e: &DMatrix<f64>) -> f64 {
    (m - e).amax() / e.amax().max(1.0)
}

/// Central differences along argument `which` of `f` (N values), from a copy of `branch` each.
fn central(branch: &Branch, x: &[Vec<f64>; 3], which: usize, f: &Model<'_>) -> DMatrix<f64> {
    let n = x[0].len();
    let mut m = DMatrix::zeros(n, n);
    for k in 0..n {
        let at = |s: f64| {
            let mut y = x.clone();
            y[which][k] += s;
            f(&mut branch.clone(), &y)
        };
        m.set_column(k, &((at(H) - at(-H)) / (2.0 * H)));
    }
    m
}

/// A state near the assembly of `name`: q_a offset from the assembly, qd_a and a third vector.
fn state(chain: &ClosedChain, third: f64) -> [Vec<f64>; 3] {
    let b = chain.assembly_branch().unwrap();
    let n = chain.dof();
    let q = b
        .q_a()
        .iter()
        .enumerate()
        .map(|(k, x)| x + 0.1 * (k as f64 + 1.0))
        .collect();
    let qd = (0..n).map(|k| 0.5 - 0.3 * k as f64).collect();
    [
        q,
        qd,
        (0..n).map(|k| third * (1.0 - 0.7 * k as f64)).collect(),
    ]
}

#[test]
fn closed_idm_derivatives_match_finite_differences_along_the_branch() {
    for name in ["fivebar.toml", "spatial_loop.toml"] {
        let file = robot(name);
        let r = robodyn::io::load(std::path::Path::new(&file)).unwrap();
        let chain = ClosedChain::new(&r).unwrap();
        let x = state(&chain, 2.0);
        let (q, qd, qdd) = (list(&x[0]), list(&x[1]), list(&x[2]));
        let base = [
            "idm",
            &file,
            "--derivatives",
            "--q",
            &q,
            "--qd",
            &qd,
            "--qdd",
            &qdd,
        ];
        let json: serde_json::Value =
            serde_json::from_str(&run(&[&base[..], &["--format", "json"]].concat())).unwrap();
        let b = chain.assembly_branch().unwrap();
        let idm = |b: &mut Branch, y: &[Vec<f64>; 3]| {
            robodyn::closed_inverse_dynamics(&chain, b, &y[0], &y[1], &y[2])
                .unwrap()
                .gamma_cl
        };
        let (dq, dqd, a) = (
            matrix(&json["dtau_dq"]),
            matrix(&json["dtau_dqd"]),
            matrix(&json["A"]),
        );
        assert!(
            rel(&dq, &central(&b, &x, 0, &idm)) < 2e-6,
            "{name}: dtau_dq {dq}"
        );
        assert!(
            rel(&dqd, &central(&b, &x, 1, &idm)) < 2e-6,
            "{name}: dtau_dqd {dqd}"
        );
        let a_cl = robodyn::closed_direct_dynamics(&chain, &mut b.clone(), &x[0], &x[1], &x[2])
            .unwrap()
            .a_cl;
        assert!(rel(&a, &a_cl) < 1e-12, "{name}: A {a}");
        let tau: Vec<f64> = serde_json::from_value(json["tau"].clone()).unwrap();
        let expected = idm(&mut b.clone(), &x);
        assert!((DVector::from_vec(tau) - expected).amax() < 1e-9);
        let joints: Vec<usize> = serde_json::from_value(json["joints"].clone()).unwrap();
        assert_eq!(joints, chain.coordinates().frames());
        assert!(json["rcond_wp"].as_f64().unwrap() > 1e-3);
        assert_eq!(json["singularity_warning"], false);
        // CSV: the same numbers as the JSON, one row per matrix row
        let text = run(&base);
        let n = chain.dof();
        let rows: Vec<Vec<String>> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').map(String::from).collect())
            .collect();
        assert_eq!(rows.len(), 3 * n);
        for (k, m) in [&dq, &dqd, &a].iter().enumerate() {
            for i in 0..n {
                for c in 0..n {
                    let v: f64 = rows[k * n + i][2 + c].parse().unwrap();
                    assert!((v - m[(i, c)]).abs() <= 1e-9 * m[(i, c)].abs().max(1.0));
                }
            }
        }
    }
}

#[test]
fn closed_ddm_derivatives_match_finite_differences_along_the_branch() {
    let file = robot("twoloops.toml");
    let r = robodyn::io::load(std::path::Path::new(&file)).unwrap();
    let chain = ClosedChain::new(&r).unwrap();
    let x = state(&chain, 0.5);
    let (q, qd, tau) = (list(&x[0]), list(&x[1]), list(&x[2]));
    let out = run(&[
        "ddm",
        &file,
        "--derivatives",
        "--q",
        &q,
        "--qd",
        &qd,
        "--tau",
        &tau,
        "--format",
        "json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let b = chain.assembly_branch().unwrap();
    let ddm = |b: &mut Branch, y: &[Vec<f64>; 3]| {
        robodyn::closed_direct_dynamics(&chain, b, &y[0], &y[1], &y[2])
            .unwrap()
            .qdd_a
    };
    let (dq, dqd, ainv) = (
        matrix(&json["dqdd_dq"]),
        matrix(&json["dqdd_dqd"]),
        matrix(&json["Ainv"]),
    );
    assert!(rel(&dq, &central(&b, &x, 0, &ddm)) < 2e-6, "dqdd_dq {dq}");
    assert!(
        rel(&dqd, &central(&b, &x, 1, &ddm)) < 2e-6,
        "dqdd_dqd {dqd}"
    );
    let a_cl = robodyn::closed_direct_dynamics(&chain, &mut b.clone(), &x[0], &x[1], &x[2])
        .unwrap()
        .a_cl;
    let n = chain.dof();
    assert!((&ainv * a_cl - DMatrix::identity(n, n)).amax() < 1e-10);
    assert!(json["rcond_a_cl"].as_f64().is_some());
}

#[test]
fn tree_ddm_derivatives_match_finite_differences() {
    let file = robot("rx90.toml");
    let r = robodyn::io::load(std::path::Path::new(&file)).unwrap();
    let x = [
        vec![0.1, -0.4, 1.2, 0.3, -0.7, 0.2],
        vec![0.5, 0.1, -0.3, 0.8, 0.2, -0.6],
        vec![10.0, -20.0, 5.0, 0.0, 3.0, -1.0],
    ];
    let (q, qd, tau) = (list(&x[0]), list(&x[1]), list(&x[2]));
    let out = run(&[
        "ddm",
        &file,
        "--derivatives",
        "--q",
        &q,
        "--qd",
        &qd,
        "--tau",
        &tau,
        "--format",
        "json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let ddm = |y: &[Vec<f64>; 3]| {
        robodyn::direct_dynamics(&r, &y[0], &y[1], &y[2], robodyn::Method::Composite).unwrap()
    };
    for (which, key) in [(0, "dqdd_dq"), (1, "dqdd_dqd"), (2, "Ainv")] {
        let m = matrix(&json[key]);
        let fd = DMatrix::from_fn(6, 6, |j, k| {
            let at = |s: f64| {
                let mut y = x.clone();
                y[which][k] += s;
                ddm(&y)[j]
            };
            (at(H) - at(-H)) / (2.0 * H)
        });
        assert!(rel(&m, &fd) < 2e-6, "{key} {m}");
    }
}
