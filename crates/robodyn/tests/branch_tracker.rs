//! The branch tracker (issue 12, item 1): tables of random, far-apart rows evaluated in order on
//! one tracker stay on the assembly branch. Every row is checked against the loop-closure
//! equations (the cut frame and its twin coincide, from the geometric model, not from the
//! closure solver's own residual) and against the branch invariant (sign of det Wp equal to the
//! assembly's), and on the SR400 against Example 10.1's parallelogram relations. A row that
//! cannot be reached on the branch is a typed error naming the row; a singular start is refused.

mod common;

use common::{cases, closure_gap, robot};
use rand::Rng;
use robodyn::{
    closed_inverse_dynamics_into, closed_state, loop_closure, Branch, ClosedChain, ClosedData,
    Error, Expr, Robot,
};
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};

/// det Wp's sign at the tracker's point (nalgebra's determinant of the returned Wp).
fn det_sign(cc: &ClosedChain, b: &mut Branch) -> f64 {
    let qa = b.q_a().to_vec();
    let z = vec![0.0; qa.len()];
    closed_state(cc, b, &qa, &z, &z)
        .unwrap()
        .wp
        .determinant()
        .signum()
}

/// `rows` random rows uniformly in the box q_a0 +- range, evaluated in order on one tracker
/// started at the assembly: every row closed and on the assembly's branch. Returns the largest
/// closure gap and the largest distance between consecutive rows.
fn far_apart_rows(r: &Robot, range: f64, rows: usize, seed: u64) -> (f64, f64) {
    let cc = ClosedChain::new(r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let qa0 = b.q_a().to_vec();
    let sign0 = det_sign(&cc, &mut b);
    assert_eq!(sign0, b.det_sign());
    let mut rng = robodyn_testing::rng(seed);
    let (mut gap, mut far): (f64, f64) = (0.0, 0.0);
    let mut previous = qa0.clone();
    let mut data = ClosedData::new(&cc);
    let env = r.environment();
    for row in 1..=rows {
        let qa: Vec<f64> = qa0
            .iter()
            .map(|x| x + rng.random_range(-range..range))
            .collect();
        far = far.max(
            qa.iter()
                .zip(&previous)
                .fold(0.0, |m, (a, b)| f64::max(m, (a - b).abs())),
        );
        previous = qa.clone();
        // the allocation-free evaluation moves the tracker...
        let n = qa.len();
        let mut tau = vec![0.0; n];
        closed_inverse_dynamics_into(
            &cc,
            &mut data,
            &mut b,
            env,
            &qa,
            &vec![0.5; n],
            &vec![-0.3; n],
            &mut tau,
        )
        .unwrap_or_else(|e| panic!("{}: {}", r.name(), e.in_row(row)));
        assert_eq!(b.q_a(), &qa[..]);
        // ...and the configuration it reached closes the loops, on the assembly's branch
        let s = loop_closure(&cc, &mut b, &qa).unwrap();
        let g = closure_gap(r, &cc, &s);
        assert!(g < 1e-10, "{} row {row}: closure gap {g:e}", r.name());
        gap = gap.max(g);
        assert_eq!(
            det_sign(&cc, &mut b),
            sign0,
            "{} row {row}: det Wp changed sign (another assembly branch)",
            r.name()
        );
    }
    (gap, far)
}

/// Bundled closed robots (files' assembly, else q = 0) and the slider-crank: 40 random rows each,
/// consecutive rows up to twice the range apart (the ranges keep the box free of singularities:
/// the SR400's parallelogram stays between its flat shapes, q7 - q2 in (0.17, 2.97)).
#[test]
fn far_apart_rows_stay_on_the_assembly_branch() {
    for (k, (name, r, _, _, range)) in cases().into_iter().enumerate() {
        let range = if name == "sr400.toml" { 0.7 } else { range };
        let (gap, far) = far_apart_rows(&r, range, 40, 70 + k as u64);
        assert!(far > range, "{name}: rows not far apart ({far})");
        println!("{name}: 40 rows up to {far:.2} rad/m apart, closure gap {gap:.1e}");
    }
}

/// On the SR400 the assembly branch is the parallelogram: theta3 = theta7 + pi/2 - theta2,
/// theta8 = theta2 - theta7 (Example 10.1) at every row, far-apart rows included.
#[test]
fn sr400_rows_keep_the_parallelogram() {
    let r = robot("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let mut rng = robodyn_testing::rng(71);
    let wrap = |x: f64| (x + PI).rem_euclid(2.0 * PI) - PI;
    for row in 0..40 {
        let qa: Vec<f64> = b
            .q_a()
            .iter()
            .enumerate()
            .map(|(k, _)| {
                let base = [0.0, 0.0, 0.0, 0.0, 0.0, FRAC_PI_2][k];
                base + rng.random_range(-0.7..0.7)
            })
            .collect();
        let s = loop_closure(&cc, &mut b, &qa).unwrap();
        let q = s.q_tree.as_slice();
        let (t2, t7) = (q[1], q[6]);
        assert!(wrap(q[2] - (t7 + FRAC_PI_2 - t2)).abs() < 1e-9, "row {row}");
        assert!(wrap(q[7] - (t2 - t7)).abs() < 1e-9, "row {row}");
    }
}

/// A row beyond a singularity of the branch is a typed error naming the row; the tracker stays
/// at the previous row.
#[test]
fn a_row_beyond_a_singularity_is_an_error_naming_the_row() {
    // SR400: q7 - q2 = -0.6 flattens the parallelogram on the way (q7 = q2): another branch
    let r = robot("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let rows = [
        [0.1, 0.2, 0.0, 0.0, 0.0, 1.2],
        [0.0, 0.3, 0.1, 0.0, 0.0, -0.3],
    ];
    let mut failed = None;
    for (k, qa) in rows.iter().enumerate() {
        if let Err(e) = loop_closure(&cc, &mut b, qa).map_err(|e| e.in_row(k + 1)) {
            failed = Some(e);
            break;
        }
    }
    let e = failed.expect("row 2 is on the crossed side of the flat parallelogram");
    assert!(
        matches!(&e, Error::Row { row: 2, source } if matches!(**source, Error::BranchLost { .. })),
        "{e}"
    );
    assert!(e.to_string().starts_with("row 2: "), "{e}");
    assert_eq!(b.q_a(), &rows[0][..], "the tracker stays at row 1");
    // the five-bar past its parallel singularity (distal links aligned at q1 = -q3 = pi/6)
    let r = robot("fivebar.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let e = loop_closure(&cc, &mut b, &[0.6, -0.6]).unwrap_err();
    assert!(matches!(e, Error::BranchLost { .. }), "{e}");
}

/// At the five-bar's singular configuration (distal links aligned) the closure is refused with
/// its conditioning; near it the result carries a warning; away from it none.
#[test]
fn singular_configurations_are_reported() {
    let r = robot("fivebar.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let a = PI / 6.0;
    let mut b = cc.assembly_branch().unwrap();
    let e = loop_closure(&cc, &mut b, &[a, -a]).unwrap_err();
    match &e {
        Error::Singular { rcond, limit, .. } => assert!(rcond < limit, "{e}"),
        other => panic!("expected Singular, got {other}"),
    }
    let near = loop_closure(&cc, &mut b, &[a - 1e-7, -(a - 1e-7)]).unwrap();
    assert!(near.conditioning.warning, "{:?}", near.conditioning);
    assert!(near.conditioning.wp < cc.limits().wp_soft);
    let far = loop_closure(&cc, &mut b, &[0.3, -0.3]).unwrap();
    assert!(!far.conditioning.warning, "{:?}", far.conditioning);
}

/// `shared/cases/external` next to the repository, or a visible skip of `what` (the optional
/// check `shared`, required by CI: `tests/common/harness.rs`).
fn external_or_skip(what: &str) -> Option<PathBuf> {
    crate::harness::shared("cases/external", what)
}

/// OpenSYMORO's SR400 `.par` with numbers: the bundled SR400's lengths, random physically
/// consistent inertial parameters, no external wrench.
fn opensymoro_sr400(path: &Path) -> robodyn::RobotDescription {
    let mut d = robodyn::io::load_description(path).unwrap();
    let mut rng = robodyn_testing::rng(400);
    for (name, v) in [
        ("d2", 0.15),
        ("d3", 0.6),
        ("d4", 0.11),
        ("r4", 0.64),
        ("d8", 0.2),
        ("G3", -9.81),
    ] {
        d.symbols.insert(name.into(), v);
    }
    for j in 1..=d.nl {
        let inertial = robodyn_testing::random_inertial(&mut rng);
        for (k, p) in ["XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"]
            .iter()
            .enumerate()
        {
            d.symbols.insert(format!("{p}{j}"), inertial[k]);
        }
        for p in ["IA", "FS", "FV"] {
            d.symbols
                .insert(format!("{p}{j}"), rng.random_range(0.0..0.5));
        }
    }
    for p in ["FX8", "FY8", "FZ8", "CX8", "CY8", "CZ8"] {
        d.symbols.insert(p.into(), 0.0);
    }
    d
}

/// The `(* robodyn assembly ... : 1 = 0.3; 2 = 0.2; ... *)` comment of a derived `.par`, read
/// here when the reader does not (yet) carry it into the description.
fn assembly_comment(path: &Path, nl: usize) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let line = text
        .lines()
        .find(|l| l.contains("robodyn assembly"))
        .expect("an assembly comment");
    let body = line.split("):").nth(1).unwrap().trim_end_matches("*)");
    let mut q = vec![0.0; nl];
    for item in body.split(';') {
        let (j, v) = item.split_once('=').unwrap();
        q[j.trim().parse::<usize>().unwrap() - 1] = v.trim().parse().unwrap();
    }
    q
}

#[test]
fn opensymoro_sr400_with_assembly_rows_stay_on_the_branch() {
    let Some(dir) = external_or_skip("OpenSYMORO SR400 .par rows on the assembly branch") else {
        return;
    };
    let path = dir.join("derived/SR400_assembly.par");
    let mut d = opensymoro_sr400(&path);
    if d.assembly.is_none() {
        d.assembly = Some(assembly_comment(&path, d.nl));
    }
    let r = Robot::new(d).unwrap();
    // far-apart rows around the assembly (q7 - q2 = 0.7 there: +-0.3 keeps it in (0.1, 1.3))
    let (gap, far) = far_apart_rows(&r, 0.3, 40, 401);
    assert!(far > 0.3);
    println!("OpenSYMORO SR400 .par: 40 rows, closure gap {gap:.1e}");
    // and the parallelogram of Example 10.1 in the file's frames (q3 = q7 - q2 - pi/2 with the
    // file's alpha and theta conventions, as its assembly comment shows)
    let cc = ClosedChain::new(&r).unwrap();
    let mut b = cc.assembly_branch().unwrap();
    let wrap = |x: f64| (x + PI).rem_euclid(2.0 * PI) - PI;
    let s = loop_closure(&cc, &mut b, &[0.5, 0.1, 0.2, 0.3, 0.4, 0.9]).unwrap();
    let q = s.q_tree.as_slice();
    assert!(wrap(q[2] - (q[6] - q[1] - FRAC_PI_2)).abs() < 1e-9, "{q:?}");
    assert!(wrap(q[7] - (q[1] - q[6])).abs() < 1e-9, "{q:?}");
}

/// OpenSYMORO's SR400 `.par` has no assembly and q = 0 flattens its parallelogram: the start is
/// refused with a typed error that says how to give an assembly, never a silent branch.
#[test]
fn opensymoro_sr400_without_assembly_refuses_the_singular_start() {
    let Some(dir) = external_or_skip("OpenSYMORO SR400 .par singular start") else {
        return;
    };
    let path = dir.join("opensymoro-symoro/SR400.par");
    let d = opensymoro_sr400(&path);
    assert!(d.assembly.is_none());
    let r = Robot::new(d).unwrap();
    let cc = ClosedChain::new(&r).unwrap();
    let e = cc.assembly_branch().unwrap_err();
    assert!(matches!(e, Error::SingularStart { .. }), "{e}");
    assert!(e.to_string().contains("assembly"), "{e}");
    // an explicit start on the parallelogram works
    let mut b = cc
        .branch_from(&[0.3, 0.2, 0.0, 0.0, 0.0, 0.9], &[-0.87, -0.7])
        .unwrap();
    assert!(loop_closure(&cc, &mut b, &[0.1, 0.1, 0.1, 0.1, 0.1, 1.0]).is_ok());
}

/// Per-call inputs: a wrench set ON a link (Pinocchio's convention) in the environment gives the
/// torques of the robot whose description has the opposite wrench BY the link, and gravity set
/// per call those of the robot rebuilt with it.
#[test]
fn environment_per_call_equals_a_rebuilt_robot() {
    let r = robot("sr400.toml");
    let cc = ClosedChain::new(&r).unwrap();
    let (f, m) = ([1.0, -2.0, 3.0], [0.5, 0.2, -0.1]);
    let mut d = r.description().clone();
    for k in 0..3 {
        d.links[4].wrench[k] = Expr::num(-f[k]);
        d.links[4].wrench[3 + k] = Expr::num(-m[k]);
    }
    d.gravity = [0.0, 1.0, -9.0].map(Expr::num);
    let rebuilt = Robot::new(d).unwrap();
    let cc2 = ClosedChain::new(&rebuilt).unwrap();
    let mut env = r.environment().clone();
    env.set_wrench_on_link(5, f.into(), m.into()).unwrap();
    env.gravity = [0.0, 1.0, -9.0].into();
    let qa = [0.1, 0.2, 0.3, -0.2, 0.4, 1.4];
    let (qd, qdd) = ([0.3; 6], [-0.2; 6]);
    let (mut t1, mut t2) = ([0.0; 6], [0.0; 6]);
    let mut b = cc.assembly_branch().unwrap();
    let mut d1 = ClosedData::new(&cc);
    closed_inverse_dynamics_into(&cc, &mut d1, &mut b, &env, &qa, &qd, &qdd, &mut t1).unwrap();
    let mut b2 = cc2.assembly_branch().unwrap();
    let mut d2 = ClosedData::new(&cc2);
    let env2 = rebuilt.environment();
    closed_inverse_dynamics_into(&cc2, &mut d2, &mut b2, env2, &qa, &qd, &qdd, &mut t2).unwrap();
    for k in 0..6 {
        assert!(
            (t1[k] - t2[k]).abs() < 1e-10 * t2[k].abs().max(1.0),
            "{t1:?} vs {t2:?}"
        );
    }
    // and the tree model the same way
    let mut e3 = r.environment().clone();
    e3.set_wrench_on_link(5, f.into(), m.into()).unwrap();
    e3.gravity = [0.0, 1.0, -9.0].into();
    let q = [0.1, 0.2, 0.3, -0.2, 0.4, 1.4, 0.2, -0.4];
    let mut tau = [0.0; 8];
    let mut data = robodyn::Data::new(&r);
    robodyn::inverse_dynamics_into(&r, &mut data, &e3, &q, &[0.3; 8], &[-0.2; 8], &mut tau)
        .unwrap();
    let expected = robodyn::inverse_dynamics(&rebuilt, &q, &[0.3; 8], &[-0.2; 8]).unwrap();
    for k in 0..8 {
        assert!((tau[k] - expected[k]).abs() < 1e-10 * expected[k].abs().max(1.0));
    }
}
