//! Base inertial parameters: the numerical and symbolic methods on the SR400 (closed chain), the
//! RX-90 (serial) and random trees.
#[path = "common/frames.rs"]
mod frames;

use nalgebra::DMatrix;
use rand::{Rng, RngCore};
use robodyn::algorithms::base_parameters::inertial_bound;
use robodyn::algorithms::base_parameters::{
    numeric_base_parameters, ConsistentSample, NumericBase, NumericOptions, Sampler, TreeSampler,
};
use robodyn::algorithms::regressor::{
    parameter_name, tree_regressor, Friction, ParameterSelection, RotorMode, PARAMS_PER_LINK,
};
use robodyn::{Data, Expr, Robot, RobotDescription};
use robodyn_testing::{random_inertial, random_tree, rng, TreeOptions};
use std::f64::consts::FRAC_PI_2;

fn sr400() -> Robot {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/sr400.toml");
    robodyn::io::load(std::path::Path::new(path)).unwrap()
}

/// Stäubli RX-90 from the conventions' geometry, with random consistent inertial values and
/// rotor inertias (no friction).
fn rx90(seed: u64) -> Robot {
    let mut r = rng(seed);
    let mut d = RobotDescription::new("RX-90", 6, 6);
    let alpha = ["0", "pi/2", "0", "-pi/2", "pi/2", "-pi/2"];
    for j in 1..=6 {
        let f = d.frame_mut(j);
        f.alpha = Expr::parse(alpha[j - 1]).unwrap();
    }
    d.frame_mut(3).d = Expr::symbol("D3");
    d.frame_mut(4).r = Expr::symbol("RL4");
    d.symbols.insert("D3".into(), 0.5);
    d.symbols.insert("RL4".into(), 0.45);
    for j in 1..=6 {
        let v = random_inertial(&mut r);
        for (k, x) in v.iter().enumerate() {
            d.link_mut(j).params[k] = Expr::num(*x);
        }
        d.link_mut(j).params[10] = Expr::num(r.random_range(0.1..1.0));
        d.link_mut(j).params[11] = Expr::zero();
        d.link_mut(j).params[12] = Expr::zero();
    }
    Robot::new(d).unwrap()
}

/// Test-local sampler of the SR400 from Example 10.1's closed-form loop relations:
/// theta3 = theta7 + pi/2 - theta2, theta8 = theta2 - theta7, so G is constant.
struct Sr400Sampler;

fn sr400_g() -> DMatrix<f64> {
    // q_a = (q1, q2, q4, q5, q6, q7)
    let mut g = DMatrix::zeros(8, 6);
    g[(0, 0)] = 1.0;
    g[(1, 1)] = 1.0;
    g[(2, 1)] = -1.0;
    g[(2, 5)] = 1.0;
    g[(3, 2)] = 1.0;
    g[(4, 3)] = 1.0;
    g[(5, 4)] = 1.0;
    g[(6, 5)] = 1.0;
    g[(7, 1)] = 1.0;
    g[(7, 5)] = -1.0;
    g
}

impl Sampler for Sr400Sampler {
    fn sample(
        &mut self,
        _robot: &Robot,
        rng: &mut dyn RngCore,
    ) -> robodyn::Result<ConsistentSample> {
        let g = sr400_g();
        let mut v = |s: f64| -> nalgebra::DVector<f64> {
            nalgebra::DVector::from_fn(6, |_, _| rng.random_range(-s..s))
        };
        let (qa, qda, qdda) = (v(1.5), v(2.0), v(5.0));
        let mut q: Vec<f64> = (&g * qa).iter().cloned().collect();
        q[2] += FRAC_PI_2;
        Ok(ConsistentSample {
            q,
            qd: (&g * qda).iter().cloned().collect(),
            qdd: (&g * qdda).iter().cloned().collect(),
            g: Some(g),
        })
    }
}

#[test]
fn sr400_sampler_closes_the_loop() {
    // Independent check of the test sampler: the origins of the cut joint frame 9 and of its twin
    // frame 10 coincide and their z axes are parallel for every sample.
    let robot = sr400();
    let mut r = rng(3);
    for _ in 0..20 {
        let s = Sr400Sampler.sample(&robot, &mut r).unwrap();
        let t = frames::per_frame(&robot, &s.q);
        let (t9, t10) = (&t[8], &t[9]);
        assert!((t9.pos - t10.pos).norm() < 1e-12, "loop not closed");
        assert!((t9.rot.column(2) - t10.rot.column(2)).norm() < 1e-12);
    }
}

fn names(v: &[usize]) -> Vec<String> {
    v.iter().map(|&i| parameter_name(i)).collect()
}

fn expected(list: &str) -> Vec<String> {
    list.split_whitespace().map(String::from).collect()
}

/// Base regressor times base values against the full model on fresh states (not the samples):
/// G^T Phi K = G^T Phi_1 K_base. Returns the worst relative error; a mismatch names the state.
fn check_reproduces(robot: &Robot, nb: &NumericBase, sampler: &mut dyn Sampler, seed: u64) -> f64 {
    let k = robot.standard_parameters();
    let kb = nb.base_values(&k);
    let mut r = rng(seed);
    let nl = robot.nl();
    let mut ws = Data::new(robot);
    let mut phi = DMatrix::zeros(nl, PARAMS_PER_LINK * nl);
    let mut worst: f64 = 0.0;
    for _ in 0..10 {
        let s = sampler.sample(robot, &mut r).unwrap();
        tree_regressor(
            robot.numeric(),
            &mut ws,
            &robot.numeric().env,
            &s.q,
            &s.qd,
            &s.qdd,
            &mut phi,
        );
        let gt = s.g.clone().unwrap_or_else(|| DMatrix::identity(nl, nl));
        let y = gt.transpose() * &phi;
        let full: Vec<f64> = (0..y.nrows())
            .map(|row| nb.columns.iter().map(|&c| y[(row, c)] * k[c]).sum())
            .collect();
        let scale = full.iter().fold(1.0f64, |a, x| a.max(x.abs()));
        for (row, f) in full.iter().enumerate() {
            let b: f64 = nb.base.iter().zip(&kb).map(|(&c, v)| y[(row, c)] * v).sum();
            worst = worst.max((b - f).abs() / scale);
        }
    }
    worst
}

#[test]
fn sr400_numeric_has_42_base_parameters_as_table_10_2() {
    let robot = sr400();
    let opt = NumericOptions {
        selection: ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None),
        samples: None,
        seed: 1,
    };
    let nb = numeric_base_parameters(&robot, &mut Sr400Sampler, &opt).unwrap();
    let table = expected(
        "ZZ1 XX2 XY2 XZ2 YZ2 ZZ2 MX2 MY2 XX3 XY3 XZ3 YZ3 ZZ3 MX3 MY3 \
         XX4 XY4 XZ4 YZ4 ZZ4 MX4 MY4 IA4 XX5 XY5 XZ5 YZ5 ZZ5 MX5 MY5 IA5 \
         XX6 XY6 XZ6 YZ6 ZZ6 MX6 MY6 IA6 MX7 MY7 MY8",
    );
    assert_eq!(nb.count(), 42);
    assert_eq!(names(&nb.base), table);
    assert_eq!(
        names(&nb.no_effect),
        expected("XX1 XY1 XZ1 YY1 YZ1 MX1 MY1 MZ1 M1 MZ2 MZ7")
    );
    let err = check_reproduces(&robot, &nb, &mut Sr400Sampler, 99);
    assert!(err < 1e-9, "SR400 base model error {err:e}");
    eprintln!("SR400 numeric: 42 base parameters, reproduction error {err:e}");
}

#[test]
fn rx90_numeric_has_40_base_parameters() {
    let robot = rx90(5);
    let opt = NumericOptions {
        selection: ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None),
        samples: None,
        seed: 2,
    };
    let nb = numeric_base_parameters(&robot, &mut TreeSampler, &opt).unwrap();
    let mut table = expected("ZZ1 XX2 XY2 XZ2 YZ2 ZZ2 MX2 MY2");
    for j in 3..=6 {
        for p in ["XX", "XY", "XZ", "YZ", "ZZ", "MX", "MY", "IA"] {
            table.push(format!("{p}{j}"));
        }
    }
    assert_eq!(names(&nb.base), table);
    assert_eq!(nb.count(), 40);
    let err = check_reproduces(&robot, &nb, &mut TreeSampler, 98);
    assert!(err < 1e-9, "RX-90 base model error {err:e}");
}

#[test]
fn random_trees_numeric_base_model_reproduces_torques() {
    let mut worst: f64 = 0.0;
    for seed in 0..30u64 {
        let mut r = rng(1000 + seed);
        let n = 2 + (seed as usize % 10);
        let opt = TreeOptions {
            gravity: if seed % 3 == 0 {
                None
            } else {
                Some([0.0, 0.0, -9.81])
            },
            ..TreeOptions::default()
        };
        let robot = random_tree(&mut r, n, &opt);
        let nopt = NumericOptions {
            selection: ParameterSelection::new(&robot, RotorMode::All, Friction::Actuated),
            samples: None,
            seed,
        };
        let nb = numeric_base_parameters(&robot, &mut TreeSampler, &nopt).unwrap();
        let err = check_reproduces(&robot, &nb, &mut TreeSampler, seed + 7);
        worst = worst.max(err);
        assert!(err < 1e-9, "seed {seed}: base model error {err:e}");
    }
    eprintln!("random trees: worst base-model error {worst:e}");
}

// ---------------------------------------------------------------------------------------------
// Symbolic method

use robodyn::algorithms::base_parameters::{
    collect_by_coefficient, symbolic_base_parameters, ParameterNames, SymbolicBase,
};

/// Base regressor (symbolic base set) times the symbolic grouped values against the full model
/// on random consistent states. A mismatch names the state; returns the worst relative error.
pub(crate) fn check_symbolic_reproduces(
    robot: &Robot,
    sb: &SymbolicBase,
    sampler: &mut dyn Sampler,
    seed: u64,
) -> f64 {
    let k = robot.standard_parameters();
    let kopt: Vec<Option<f64>> = k.iter().map(|&v| Some(v)).collect();
    let kb: Vec<f64> = sb
        .values(robot.description(), &kopt)
        .into_iter()
        .enumerate()
        .map(|(r, v)| v.unwrap_or_else(|| panic!("no value for {}", parameter_name(sb.base[r]))))
        .collect();
    let mut r = rng(seed);
    let nl = robot.nl();
    let mut ws = Data::new(robot);
    let mut phi = DMatrix::zeros(nl, PARAMS_PER_LINK * nl);
    let mut worst: f64 = 0.0;
    for _ in 0..10 {
        let s = sampler.sample(robot, &mut r).unwrap();
        tree_regressor(
            robot.numeric(),
            &mut ws,
            &robot.numeric().env,
            &s.q,
            &s.qd,
            &s.qdd,
            &mut phi,
        );
        let gt = s.g.clone().unwrap_or_else(|| DMatrix::identity(nl, nl));
        let y = gt.transpose() * &phi;
        for row in 0..y.nrows() {
            let full: f64 = sb.columns.iter().map(|&c| y[(row, c)] * k[c]).sum();
            let b: f64 = sb.base.iter().zip(&kb).map(|(&c, v)| y[(row, c)] * v).sum();
            let scale = full.abs().max(1.0);
            worst = worst.max((b - full).abs() / scale);
        }
    }
    worst
}

fn parse(s: &str) -> Expr {
    Expr::parse(s).unwrap_or_else(|e| panic!("{s}: {e}"))
}

#[test]
fn sr400_symbolic_matches_table_10_2_and_the_chapter_listing() {
    let robot = sr400();
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None);
    // the symbolic method works on the description with symbolic inertial parameters
    let mut desc = robot.description().clone();
    for j in 1..=8 {
        *desc.link_mut(j) = robodyn::model::LinkDesc::symbolic(j);
    }
    let sb = symbolic_base_parameters(&desc, &sel).unwrap();
    for (r, e) in sb.equations.iter().enumerate() {
        eprintln!(
            "{} = {}",
            parameter_name(sb.base[r]),
            collect_by_coefficient(e, &ParameterNames::standard(8))
        );
    }
    let table = expected(
        "ZZ1 XX2 XY2 XZ2 YZ2 ZZ2 MX2 MY2 XX3 XY3 XZ3 YZ3 ZZ3 MX3 MY3 \
         XX4 XY4 XZ4 YZ4 ZZ4 MX4 MY4 IA4 XX5 XY5 XZ5 YZ5 ZZ5 MX5 MY5 IA5 \
         XX6 XY6 XZ6 YZ6 ZZ6 MX6 MY6 IA6 MX7 MY7 MY8",
    );
    assert_eq!(names(&sb.base), table);
    assert_eq!(sb.count(), 42);
    assert_eq!(
        names(&sb.no_effect),
        expected("XX1 XY1 XZ1 YY1 YZ1 MX1 MY1 MZ1 M1 MZ2 MZ7")
    );
    // the 33 grouped parameters of the chapter (IA first there; K order here)
    let mut chapter_grouped = expected(
        "IA1 YY2 M2 IA2 YY3 MZ3 M3 YY4 MZ4 M4 YY5 MZ5 M5 YY6 MZ6 M6 XX7 XY7 XZ7 YY7 YZ7 ZZ7 M7 \
         IA7 XX8 XY8 XZ8 YY8 YZ8 ZZ8 MX8 MZ8 M8",
    );
    chapter_grouped.sort();
    let mut got = names(&sb.grouped);
    got.sort();
    assert_eq!(got, chapter_grouped);
    // The chapter's listing (end of Example 10.2), written by hand. Corrections of the OCR:
    // - ZZR1: the listing reads d2^2(M3..M6) + d3^2(M2..M6); the derivation on link 2
    //   (ZZR1 += YYR2 + d2^2 MR2 with YYR2 containing d3^2 MR3) gives d3^2(M3..M6) and
    //   d2^2(M2..M6);
    // - `XZR_1 = XZ_1 + YZ_1` is XZR3 = XZ3 + YZ7 (link 7, J7 grouped into J3);
    // - `dg^2` is d8^2, `Y_1Y_6` is YY6;
    // - MYR3: the listing drops the term -d8/d3 MX8 that the chapter's own derivation on links 8
    //   and 4 carries (MYR3 = MY3 - d8 MX8/d3 + MZ4 + RL4 MR4); it is kept here.
    let listing = [
        ("ZZ1", "IA1 + ZZ1 + YY2 + YY3 + XX7 + YY8 + d4^2*(M4 + M5 + M6) + d3^2*(M3 + M4 + M5 + M6) + d2^2*(M2 + M3 + M4 + M5 + M6) + d2^2*(M7 + M8)"),
        ("XX2", "XX2 - YY2 + XX8 - YY8 - d3^2*(M3 + M4 + M5 + M6)"),
        ("XY2", "XY2 + XY8"),
        ("XZ2", "XZ2 + XZ8 - d3*MZ3"),
        ("YZ2", "YZ2 + YZ8"),
        ("ZZ2", "IA2 + ZZ2 + ZZ8 + d3^2*(M3 + M4 + M5 + M6)"),
        ("MX2", "MX2 + MX8 + d3*(M3 + M4 + M5 + M6)"),
        ("XX3", "XX3 - YY3 + YY4 - XX7 + YY7 - d4^2*(M4 + M5 + M6) + 2*MZ4*RL4 + (M4 + M5 + M6)*RL4^2 + d8^2*M8"),
        ("XY3", "XY3 - XY7 - d4*MZ4 - d4*RL4*(M4 + M5 + M6)"),
        ("XZ3", "XZ3 + YZ7"),
        ("YZ3", "YZ3 - XZ7 + d8*MZ8"),
        ("ZZ3", "IA7 + ZZ3 + YY4 + ZZ7 + d8^2*M8 + 2*MZ4*RL4 + (M4 + M5 + M6)*(d4^2 + RL4^2)"),
        ("MX3", "MX3 + d4*(M4 + M5 + M6)"),
        ("MY3", "MY3 - d8/d3*MX8 + MZ4 + (M4 + M5 + M6)*RL4"),
        ("XX4", "XX4 - YY4 + YY5"),
        ("ZZ4", "YY5 + ZZ4"),
        ("MY4", "MY4 - MZ5"),
        ("XX5", "XX5 - YY5 + YY6"),
        ("ZZ5", "YY6 + ZZ5"),
        ("MY5", "MY5 + MZ6"),
        ("XX6", "XX6 - YY6"),
        ("MX7", "MX7 - d8/d3*MX8 + d8*M8"),
    ];
    let base_names = names(&sb.base);
    for (name, eq) in listing {
        let r = base_names.iter().position(|n| n == name).unwrap();
        let diff = (sb.equations[r].clone() - parse(eq)).expand();
        assert!(
            diff.is_zero(),
            "{name}R: got {} , chapter {eq}; difference {diff}",
            collect_by_coefficient(&sb.equations[r], &ParameterNames::standard(8))
        );
    }
    // every other base parameter is its own symbol
    for (r, n) in base_names.iter().enumerate() {
        if !listing.iter().any(|(l, _)| l == n) {
            assert_eq!(sb.equations[r], parse(n), "{n}");
        }
    }
    // the collected printing of ZZR2 reads like the chapter
    // bound 10.57: 7 nr - 4 nr0 - 11 npar - 2 ng0 = 56 - 4 - 11 - 2 = 39 inertial parameters
    let inertial = sb
        .base
        .iter()
        .filter(|&&c| c % PARAMS_PER_LINK < 10)
        .count();
    assert_eq!(inertial, 39);
    assert_eq!(sb.parallelograms, vec![9]);
    let zz2 = base_names.iter().position(|n| n == "ZZ2").unwrap();
    eprintln!(
        "{}",
        collect_by_coefficient(&sb.equations[zz2], &ParameterNames::standard(8))
    );
    // values: symbolic grouped values reproduce the closed-chain torques
    let err = check_symbolic_reproduces(&robot, &sb, &mut Sr400Sampler, 5);
    assert!(err < 1e-9, "SR400 symbolic base model error {err:e}");
}

#[test]
fn rx90_symbolic_has_40_base_parameters() {
    let robot = rx90(5);
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None);
    let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
    let mut table = expected("ZZ1 XX2 XY2 XZ2 YZ2 ZZ2 MX2 MY2");
    for j in 3..=6 {
        for p in ["XX", "XY", "XZ", "YZ", "ZZ", "MX", "MY", "IA"] {
            table.push(format!("{p}{j}"));
        }
    }
    assert_eq!(names(&sb.base), table);
    // R suffix exactly where the conventions say: ZZR1, XXR2, XZR2, ZZR2, MXR2; XXR, ZZR, MYR of
    // links 3-5; XXR6.
    let regrouped: Vec<String> = (0..sb.count())
        .filter(|&r| sb.is_regrouped(r))
        .map(|r| parameter_name(sb.base[r]))
        .collect();
    assert_eq!(
        regrouped,
        expected("ZZ1 XX2 XZ2 ZZ2 MX2 XX3 ZZ3 MY3 XX4 ZZ4 MY4 XX5 ZZ5 MY5 XX6")
    );
    let err = check_symbolic_reproduces(&robot, &sb, &mut TreeSampler, 6);
    assert!(err < 1e-9, "RX-90 symbolic base model error {err:e}");
}

#[test]
fn random_trees_symbolic_agrees_with_numeric() {
    let mut worst: f64 = 0.0;
    for seed in 0..400u64 {
        let mut r = rng(5000 + seed);
        let n = if seed % 50 == 7 {
            30
        } else {
            2 + (seed as usize % 9)
        };
        let opt = TreeOptions {
            gravity: if seed % 3 == 0 {
                None
            } else {
                Some([0.0, 0.0, -9.81])
            },
            p_prismatic: if seed % 2 == 0 { 0.25 } else { 0.0 },
            ..TreeOptions::default()
        };
        let robot = random_tree(&mut r, n, &opt);
        let (rotor, friction) = match seed % 3 {
            0 => (RotorMode::None, Friction::None),
            1 => (RotorMode::All, Friction::None),
            _ => (RotorMode::Actuated, Friction::Actuated),
        };
        let sel = ParameterSelection::new(&robot, rotor, friction);
        let nopt = NumericOptions {
            selection: sel.clone(),
            samples: None,
            seed,
        };
        let nb = numeric_base_parameters(&robot, &mut TreeSampler, &nopt).unwrap();
        let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
        let geometry: Vec<String> = (1..=n)
            .map(|j| {
                let f = robot.frame(j);
                format!(
                    "{j}: a={} {:?} g={} b={} al={} d={} th={} r={}",
                    f.ant, f.joint, f.gamma, f.b, f.alpha, f.d, f.theta, f.r
                )
            })
            .collect();
        assert_eq!(
            names(&sb.base),
            names(&nb.base),
            "seed {seed}: symbolic vs numeric base sets differ\n{}",
            geometry.join("\n")
        );
        // grouped values, parameter by parameter: symbolic equations vs numeric K1 + beta K2
        let k = robot.standard_parameters();
        let kopt: Vec<Option<f64>> = k.iter().map(|&v| Some(v)).collect();
        let vs = sb.values(robot.description(), &kopt);
        let vn = nb.base_values(&k);
        for (r, (a, b)) in vs.iter().zip(&vn).enumerate() {
            let a = a.unwrap();
            assert!(
                (a - b).abs() <= 1e-8 * (1.0 + b.abs()),
                "seed {seed}: base parameter {}: symbolic {a} vs numeric {b}",
                parameter_name(sb.base[r])
            );
        }
        // b_m bound on the inertial parameters (+ drive parameters kept)
        let inertial = sb
            .base
            .iter()
            .filter(|&&c| c % PARAMS_PER_LINK < 10)
            .count();
        assert!(
            inertial <= inertial_bound(&robot, 0),
            "seed {seed}: {inertial} > b_m"
        );
        let err = check_symbolic_reproduces(&robot, &sb, &mut TreeSampler, seed + 11);
        worst = worst.max(err);
        assert!(err < 1e-9, "seed {seed}: symbolic base model error {err:e}");
    }
    eprintln!("random trees: symbolic = numeric, worst symbolic base-model error {worst:e}");
}

/// The base robot written to TOML and read back gives the torques of the full model
/// (closed chain: G^T Gamma_tr with the test sampler; RX-90: Gamma_tr directly).
#[test]
fn base_robot_file_reproduces_the_full_model() {
    use robodyn::algorithms::base_parameters::{base_robot, ParameterNames, Summary};
    use robodyn::algorithms::inverse_dynamics::inverse_dynamics;
    let dir = std::env::temp_dir().join(format!("robodyn-basep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (name, robot, closed) in [("sr400", sr400(), true), ("rx90", rx90(9), false)] {
        let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::Actuated);
        // the full model restricted to the selection (drive parameters outside it are zero)
        let mut k = robot.standard_parameters();
        let cols: std::collections::BTreeSet<usize> = sel.columns().into_iter().collect();
        for (i, v) in k.iter_mut().enumerate() {
            if !cols.contains(&i) {
                *v = 0.0;
            }
        }
        let full = robot.with_standard_parameters(&k).unwrap();
        let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
        let report = Summary::from_symbolic(
            full.description(),
            &sb,
            &ParameterNames::of(full.description()),
        );
        let values: Vec<f64> = report.base.iter().map(|b| b.value.unwrap()).collect();
        let desc = base_robot(robot.description(), &sb.base, &values).unwrap();
        let path = dir.join(format!("{name}-base.toml"));
        robodyn::io::save_description(&desc, &path).unwrap();
        let based = robodyn::io::load(&path).unwrap();
        let mut r = rng(77);
        for _ in 0..10 {
            let s = if closed {
                Sr400Sampler.sample(&robot, &mut r).unwrap()
            } else {
                TreeSampler.sample(&robot, &mut r).unwrap()
            };
            let t_full = inverse_dynamics(&full, &s.q, &s.qd, &s.qdd).unwrap();
            let t_base = inverse_dynamics(&based, &s.q, &s.qd, &s.qdd).unwrap();
            let g =
                s.g.clone()
                    .unwrap_or_else(|| DMatrix::identity(robot.nl(), robot.nl()));
            let (a, b) = (g.transpose() * t_full, g.transpose() * t_base);
            let scale = a.amax().max(1.0);
            for i in 0..a.len() {
                assert!(
                    (a[i] - b[i]).abs() <= 1e-9 * scale,
                    "{name}: row {i}: full {} vs base robot {}",
                    a[i],
                    b[i]
                );
            }
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn report_formats_carry_count_and_lists() {
    use robodyn::algorithms::base_parameters::{ParameterNames, Summary};
    use robodyn::report::base_parameters as write;
    let robot = sr400();
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None);
    let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
    let rep = Summary::from_symbolic(
        robot.description(),
        &sb,
        &ParameterNames::of(robot.description()),
    );
    let j = write::json(&rep);
    assert_eq!(j["count"], 42);
    assert_eq!(j["base"].as_array().unwrap().len(), 42);
    assert_eq!(j["base"][0]["name"], "ZZR1");
    assert_eq!(j["no_effect"].as_array().unwrap().len(), 11);
    assert_eq!(j["grouped"].as_array().unwrap().len(), 33);
    // Table 10.2 layout: link 8 row has only MY8; link 1 only ZZR1; IA4 on link 4
    let t = rep.table();
    let row = |j: usize| t[j].join(" ");
    assert_eq!(row(1), "1 0 0 0 0 0 ZZR1 0 0 0 0 0");
    assert_eq!(row(7), "7 0 0 0 0 0 0 MXR7 MY7 0 0 0");
    assert_eq!(row(8), "8 0 0 0 0 0 0 0 MY8 0 0 -");
    assert!(row(4).ends_with("IA4"));
    let latex = write::latex(&rep);
    assert!(latex.contains("ZZR_{1} &="), "{latex}");
}

/// The symbolic method needs no numeric values: the RX-90 with D3 and RL4 left symbolic gives the
/// same base set, equations in D3 and RL4, and no value where a symbol is missing.
#[test]
fn symbolic_method_on_a_description_without_values() {
    let robot = rx90(5);
    let mut desc = robot.description().clone();
    desc.symbols.clear();
    for j in 1..=6 {
        *desc.link_mut(j) = robodyn::model::LinkDesc::symbolic(j);
    }
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::None);
    let sb = symbolic_base_parameters(&desc, &sel).unwrap();
    assert_eq!(sb.count(), 40);
    let names = names(&sb.base);
    let zz2 = names.iter().position(|n| n == "ZZ2").unwrap();
    // ZZR2 = ZZ2 + IA2 + D3^2 (M3 + M4 + M5 + M6), derived by hand from Theorem 10.1 (link 3 at
    // d = D3 on the x axis of frame 2, alpha3 = 0)
    let diff = (sb.equations[zz2].clone() - parse("ZZ2 + IA2 + D3^2*(M3 + M4 + M5 + M6)")).expand();
    assert!(diff.is_zero(), "ZZR2 = {}", sb.equations[zz2]);
    let values = sb.values(&desc, &vec![None; 13 * 6]);
    assert!(values.iter().all(|v| v.is_none()));
    // a selection of the wrong size is an error, not a panic
    let bad = ParameterSelection::all(3);
    assert!(symbolic_base_parameters(&desc, &bad).is_err());
}

/// SR400 with other parameter selections (rotors on every joint, friction on every joint, none):
/// symbolic set = numeric set, values agree parameter by parameter, and the symbolic base model
/// reproduces the closed-chain torques. With rotors on the passive joints, IA8 groups into IA3
/// (qd8 = -qd3 in the parallelogram).
#[test]
fn sr400_other_selections_symbolic_equals_numeric() {
    let robot = sr400();
    let every = ParameterSelection {
        rotor: vec![true; 8],
        friction: vec![true; 8],
        absent: Default::default(),
    };
    let cases = [
        ParameterSelection::new(&robot, RotorMode::All, Friction::Actuated),
        ParameterSelection::new(&robot, RotorMode::None, Friction::None),
        ParameterSelection::new(&robot, RotorMode::Actuated, Friction::Actuated),
        every,
    ];
    for (n, sel) in cases.into_iter().enumerate() {
        let opt = NumericOptions {
            selection: sel.clone(),
            samples: None,
            seed: 4,
        };
        let nb = numeric_base_parameters(&robot, &mut Sr400Sampler, &opt).unwrap();
        let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
        assert_eq!(names(&sb.base), names(&nb.base), "case {n}");
        assert_eq!(names(&sb.no_effect), names(&nb.no_effect), "case {n}");
        let k = robot.standard_parameters();
        let kopt: Vec<Option<f64>> = k.iter().map(|&v| Some(v)).collect();
        let vs = sb.values(robot.description(), &kopt);
        for (r, (a, b)) in vs.iter().zip(nb.base_values(&k)).enumerate() {
            let a = a.unwrap();
            assert!(
                (a - b).abs() <= 1e-8 * (1.0 + b.abs()),
                "case {n}: {}: symbolic {a} vs numeric {b}",
                parameter_name(sb.base[r])
            );
        }
        let err = check_symbolic_reproduces(&robot, &sb, &mut Sr400Sampler, 40 + n as u64);
        assert!(err < 1e-9, "case {n}: error {err:e}");
        if n == 0 {
            let ia3 = names(&sb.base).iter().position(|x| x == "IA3").unwrap();
            assert_eq!(sb.equations[ia3], parse("IA3 + IA8"));
        }
    }
}
