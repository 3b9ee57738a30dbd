//! Generated derivatives of the inverse dynamic model (`ModelKind::IdmDerivatives`, `robodyn
//! generate --model idm-derivatives`): out = [dGamma/dq, dGamma/dqd, A], each N x N
//! column-major.
//!
//! Cross-checks, each against a route that does not share the generated code's derivation:
//! - the numeric analytical derivatives `inverse_dynamics_derivatives` (the Newton–Euler
//!   recursion differentiated by hand, D1–D14, and A by composite links), to 1e-10 relative,
//!   interpreted here and compiled in Rust, C, Python and MATLAB by `codegen_compile.rs`
//!   ([`derivative_cases`] are among its programs);
//! - central finite differences (Richardson-extrapolated) of the generated IDM program itself;
//! - the structure: the first column of dGamma/dq of a robot whose first axis is vertical is
//!   identically zero in the generated code (the numeric derivatives agree: ~0).
//!
//! Robots: the RX-90 (symbolic parameters and numeric values), the torso with two arms (a tree),
//! a random tree with fixed frames, friction and external wrenches, and the UR5 and the Panda
//! of example-robot-data when installed. Friction is kept: Fv on the diagonal of dGamma/dqd,
//! the Coulomb term's derivative 0 (random velocities are away from 0).

use crate::codegen_kinematics::evaluate;
use robodyn::codegen::{generate, GenOptions, ModelKind};
use robodyn::{inverse_dynamics_derivatives, Robot, RobotDescription};
use robodyn_symbolic::Program;
use robodyn_testing::{random_state, random_tree_description, rng, TreeOptions};
use std::path::Path;

mod common;

/// A generated derivative program, its input sets (q, qd, qdd, p per state) and the numeric
/// derivatives at those states, in the program's output layout.
pub(crate) struct DerivativeCase {
    pub prog: Program,
    pub inputs: Vec<Vec<Vec<f64>>>,
    pub expected: Vec<Vec<f64>>,
    pub what: String,
    pub desc: RobotDescription,
    pub numeric: bool,
}

fn robot_file(name: &str) -> RobotDescription {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(format!("{name}.toml"));
    robodyn::io::load_description(&path).unwrap()
}

fn parameters(prog: &Program, desc: &RobotDescription) -> Vec<f64> {
    let env = crate::codegen_compile::env_of(desc);
    prog.inputs
        .iter()
        .filter(|g| g.by_name)
        .flat_map(|g| g.symbols.iter().flatten())
        .map(|s| env(s).unwrap_or_else(|| panic!("no value for {s}")))
        .collect()
}

/// The robots: (tag, description, numeric).
fn setups() -> Vec<(String, RobotDescription, bool)> {
    let mut out = vec![
        ("rx90_d".to_string(), robot_file("rx90"), false),
        ("rx90_dnum".to_string(), robot_file("rx90"), true),
        ("torso2arms_d".to_string(), robot_file("torso2arms"), false),
    ];
    let opts = TreeOptions {
        p_fixed: 0.3,
        ..TreeOptions::default()
    };
    out.push((
        "tree_d".to_string(),
        random_tree_description(&mut rng(61), 7, &opts),
        false,
    ));
    if let Some(dir) = common::example_robot_data("generated derivatives of UR5 and Panda") {
        for (file, tag) in [("ur5_robot.urdf", "ur5_d"), ("panda.urdf", "panda_d")] {
            let path = common::find_file(&dir, file).unwrap();
            out.push((
                tag.to_string(),
                robodyn::io::load_description(&path).unwrap(),
                true,
            ));
        }
    }
    out
}

/// Column-major entries of the three numeric matrices, as the generated code writes them.
fn numeric_derivatives(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let d = inverse_dynamics_derivatives(robot, q, qd, qdd).unwrap();
    [&d.dtau_dq, &d.dtau_dqd, &d.a]
        .iter()
        .flat_map(|m| m.as_slice().to_vec())
        .collect()
}

/// Every setup's derivative program with three random states and the numeric derivatives.
pub(crate) fn derivative_cases() -> Vec<DerivativeCase> {
    let mut cases = Vec::new();
    for (s, (tag, desc, numeric)) in setups().into_iter().enumerate() {
        let robot = Robot::new(desc.clone()).unwrap();
        let joints: Vec<usize> = desc.movable_joints();
        let pick = |v: &[f64]| joints.iter().map(|&j| v[j - 1]).collect::<Vec<f64>>();
        let mut r = rng(600 + s as u64);
        let states: Vec<[Vec<f64>; 3]> = (0..3)
            .map(|_| {
                let [q, qd, qdd] = random_state(&mut r, desc.nl);
                [pick(&q), pick(&qd), pick(&qdd)]
            })
            .collect();
        let opt = GenOptions {
            model: ModelKind::IdmDerivatives,
            numeric,
            name: Some(format!("{tag}_idm_derivatives")),
            ..GenOptions::default()
        };
        let prog = generate(&desc, &opt).unwrap();
        assert_eq!(prog.outputs.len(), 3 * joints.len().pow(2), "{tag}");
        let p = parameters(&prog, &desc);
        cases.push(DerivativeCase {
            inputs: states
                .iter()
                .map(|[q, qd, qdd]| vec![q.clone(), qd.clone(), qdd.clone(), p.clone()])
                .collect(),
            expected: states
                .iter()
                .map(|[q, qd, qdd]| numeric_derivatives(&robot, q, qd, qdd))
                .collect(),
            prog,
            what: format!("{tag} idm_derivatives"),
            desc,
            numeric,
        });
    }
    cases
}

/// Largest difference relative to max(1, largest reference entry), per block.
fn block_err(got: &[f64], expected: &[f64], n: usize) -> f64 {
    got.chunks(n * n)
        .zip(expected.chunks(n * n))
        .map(|(g, e)| crate::codegen_kinematics::rel_err(g, e))
        .fold(0.0, f64::max)
}

#[test]
fn interpreted_derivatives_equal_the_numeric_analytical_ones() {
    let mut worst = 0.0f64;
    for c in derivative_cases() {
        let n = c.prog.inputs[0].symbols.len();
        for (set, exp) in c.inputs.iter().zip(&c.expected) {
            let e = block_err(&evaluate(&c.prog, set), exp, n);
            assert!(e < 1e-10, "{}: off by {e:e}", c.what);
            worst = worst.max(e);
        }
    }
    println!("generated vs numeric derivatives: worst relative error {worst:e}");
}

/// dGamma/dq and dGamma/dqd of the generated derivative program against central differences
/// of the generated IDM (Richardson-extrapolated from steps h and h/2: truncation O(h^4)), and
/// A against differences along qdd (exact: the IDM is linear in qdd).
#[test]
fn derivatives_equal_differences_of_the_generated_idm() {
    for c in derivative_cases() {
        let opt = GenOptions {
            model: ModelKind::Idm,
            numeric: c.numeric,
            ..GenOptions::default()
        };
        let idm = generate(&c.desc, &opt).unwrap();
        let n = c.prog.inputs[0].symbols.len();
        let p = parameters(&idm, &c.desc);
        for set in &c.inputs {
            let got = evaluate(&c.prog, set);
            let mut fd = vec![0.0; 3 * n * n];
            for (block, group) in [0, 1, 2].into_iter().enumerate() {
                for k in 0..n {
                    let at = |h: f64| {
                        let mut s = set[..3].to_vec();
                        s[group][k] += h;
                        s.push(p.clone());
                        evaluate(&idm, &s)
                    };
                    let d = |h: f64| -> Vec<f64> {
                        at(h)
                            .iter()
                            .zip(at(-h))
                            .map(|(a, b)| (a - b) / (2.0 * h))
                            .collect()
                    };
                    let (d1, d2) = (d(1e-3), d(5e-4));
                    for i in 0..n {
                        fd[block * n * n + k * n + i] = (4.0 * d2[i] - d1[i]) / 3.0;
                    }
                }
            }
            let e = block_err(&got, &fd, n);
            assert!(
                e < 1e-7,
                "{}: generated vs differences off by {e:e}",
                c.what
            );
        }
    }
}

/// Zeros are structural: the RX-90's first axis is vertical (along gravity), so no torque
/// depends on q1 and the generated code writes the constant 0 for the whole first column of
/// dGamma/dq (the numeric derivatives agree to rounding). The derivative program costs a
/// bounded multiple of the IDM, not the 2N IDM evaluations of finite differences.
#[test]
fn vertical_first_axis_gives_a_zero_column() {
    let c = derivative_cases()
        .into_iter()
        .find(|c| c.what.starts_with("rx90_dnum"))
        .unwrap();
    let n = 6;
    for i in 0..n {
        assert!(
            c.prog.outputs[i].expr.is_zero(),
            "dGamma{}/dq1 is not a structural zero: {}",
            i + 1,
            c.prog.outputs[i].expr
        );
    }
    for exp in &c.expected {
        assert!(exp[..n].iter().all(|x| x.abs() < 1e-9), "{:?}", &exp[..n]);
        assert!(exp[n..n * n].iter().any(|x| x.abs() > 1e-3));
    }
    let idm = generate(
        &c.desc,
        &GenOptions {
            numeric: true,
            ..GenOptions::default()
        },
    )
    .unwrap()
    .count();
    let d = c.prog.count();
    let (ops, ops_idm) = (d.mul + d.add, idm.mul + idm.add);
    assert!(ops < 2 * n * ops_idm, "{ops} operations vs IDM {ops_idm}");
    println!("RX-90 numeric: IDM {ops_idm} operations, derivatives {ops}");
}
