//! Base inertial parameters: the numerical and symbolic methods on the SR400 (closed chain), the
//! RX-90 (serial) and random trees.

use nalgebra::DMatrix;
use rand::{Rng, RngCore};
use robodyn::algorithms::base_parameters::{
    numeric_base_parameters, ConsistentSample, NumericBase, NumericOptions, Sampler, TreeSampler,
};
use robodyn::algorithms::regressor::{
    parameter_name, regressor, ParameterSelection, RotorMode, PARAMS_PER_LINK,
};
use robodyn::testing::{random_inertial, random_tree, rng, TreeOptions};
use robodyn::{Expr, Robot, RobotDescription, Workspace};
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
        for k in 0..10 {
            d.link_mut(j).params[k] = Expr::num(v[k]);
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
        let t = robodyn::geometry::frame_transforms(&robot, &s.q);
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
    let mut ws = Workspace::new(robot.numeric());
    let mut phi = DMatrix::zeros(nl, PARAMS_PER_LINK * nl);
    let mut worst: f64 = 0.0;
    for _ in 0..10 {
        let s = sampler.sample(robot, &mut r).unwrap();
        regressor(robot.numeric(), &mut ws, &s.q, &s.qd, &s.qdd, &mut phi);
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
        selection: ParameterSelection::new(&robot, RotorMode::Actuated, false),
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
        selection: ParameterSelection::new(&robot, RotorMode::Actuated, false),
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
            selection: ParameterSelection::new(&robot, RotorMode::All, true),
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
