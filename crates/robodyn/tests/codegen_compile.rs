//! Generated Rust, C, Python and MATLAB code compiles / runs and agrees with the numeric models.
//!
//! Cross-checks (each a different route to the same number):
//! - idm: generated Gamma vs the numeric Newton–Euler `rnea` on f64;
//! - inertia + h: generated A qdd + H vs numeric `rnea(q, qd, qdd)` (A and H never computed
//!   numerically);
//! - ddm: generated qdd from (q, qd, Gamma = rnea(q, qd, qdd*)) vs the random qdd*;
//! - closed: generated Gamma_cl vs G^T rnea with G written by hand from Example 10.1 (SR400,
//!   constant G); for the other closed robots (G depending on q, loop-closure Jacobian written
//!   out, multiplier form 10.36-10.37) vs the numeric closed-chain model G^T Gamma_tr (10.40);
//! - idm_derivatives: generated [dGamma/dq, dGamma/dqd, A] vs the numeric analytical
//!   `inverse_dynamics_derivatives` (cases of `codegen_derivatives.rs`);
//! - w: generated W = d q_p / d q_a vs the numeric W of the closed-chain model (both checked
//!   against finite differences of the loop closure in `generated_w_is_the_derivative_of_loop_closure`).
//!
//! Robots: the SR400 (symbolic and numeric), the RX-90, every other bundled robot (the closed
//! ones as their equivalent trees, and as closed chains), a slider-crank with a prismatic cut
//! joint, three random trees, and the SCARA with symbols named `end`, `p`, `in`, `out`; and the
//! DGM and Jacobian programs of `codegen_kinematics.rs` (against `frame_transforms` and the
//! derivative of the numeric DGM, to 1e-12); and the floating-base inverse dynamic models of
//! `codegen_floating.rs` (against the numeric `inverse_dynamics` of the floating robot).
//!
//! Every program is compiled (rustc, cc) into a harness that reads inputs on stdin and prints the
//! outputs; tolerance 1e-10 relative (norm-wise over each output vector).

use nalgebra::{DMatrix, DVector};
use robodyn::algorithms::closed_chain::ClosedChain;
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::codegen::{constant_g, generate, GenOptions, ModelKind};
use robodyn::model::STANDARD_PARAMETERS;
use robodyn::{Data, Expr, Robot, RobotDescription};
use robodyn_symbolic::{emit, parameter_fields, parameter_type, Lang, Program};
use robodyn_testing::{random_state, random_tree_description, rng, TreeOptions};
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

mod common;

mod sr400_base {
    include!("codegen_data/sr400_base.rs");
}

mod robots {
    include!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/benches/generated/robots.rs"
    ));
}
use robots::{rx90_description as rx90, sr400_description as sr400};

/// Value of any symbol of a generated program: robot symbols, standard parameters `XX<j>`.
pub(crate) fn env_of(desc: &RobotDescription) -> impl Fn(&str) -> Option<f64> + '_ {
    move |s: &str| {
        if let Some(v) = desc.symbols.get(s) {
            return Some(*v);
        }
        let i = s.trim_end_matches(|c: char| c.is_ascii_digit()).len();
        let (p, n) = (&s[..i], s[i..].parse::<usize>().ok()?);
        let k = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
        let l = desc.links.get(n.checked_sub(1)?)?;
        l.params[k].eval(&|t| desc.symbols.get(t).copied()).ok()
    }
}

/// One test case: a program and its input sets (one Vec per input group, per state).
struct Case {
    prog: Program,
    inputs: Vec<Vec<Vec<f64>>>,
    expected: Vec<Vec<f64>>,
    what: String,
}

/// The values of the program's parameters `p` (its group passed by name, last), or none when
/// the program has no parameters (`--numeric`).
fn parameter_values(prog: &Program, env: &dyn Fn(&str) -> Option<f64>) -> Vec<f64> {
    prog.inputs
        .iter()
        .filter(|g| g.by_name)
        .flat_map(|g| &g.symbols)
        .map(|s| env(s.as_deref().unwrap()).unwrap_or_else(|| panic!("no value for {s:?}")))
        .collect()
}

/// The input sets of every case without the `p` entry of a program that takes none, and the
/// library's `codegen::parameter_values` checked against the test's own values of `p`.
fn finish_cases(mut cases: Vec<Case>) -> Vec<Case> {
    for c in &mut cases {
        let groups = c.prog.inputs.len();
        let takes_p = c.prog.inputs.iter().any(|g| g.by_name);
        for set in &mut c.inputs {
            if !takes_p {
                assert!(set.last().is_some_and(Vec::is_empty), "{}: no p", c.what);
            }
            set.truncate(groups);
        }
    }
    cases
}

fn numeric_rnea(robot: &Robot, q: &[f64], qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let mut ws = Data::new(robot);
    let mut tau = vec![0.0; robot.nl()];
    rnea(robot.numeric(), &mut ws, q, qd, qdd, &mut tau);
    tau
}

fn movable(desc: &RobotDescription) -> Vec<usize> {
    (1..=desc.nl)
        .filter(|&j| desc.frame(j).joint.is_movable())
        .collect()
}

/// idm, inertia + h, ddm cases for a tree (or the equivalent tree of a closed robot).
fn tree_cases(desc: &RobotDescription, numeric: bool, seed: u64, tag: &str) -> Vec<Case> {
    let robot = Robot::new(desc.clone()).unwrap();
    let env = env_of(desc);
    let nl = desc.nl;
    let joints = movable(desc);
    let mut r = rng(seed);
    let states: Vec<[Vec<f64>; 3]> = (0..3).map(|_| random_state(&mut r, nl)).collect();
    let gen = |model: ModelKind| {
        let opt = GenOptions {
            model,
            numeric,
            name: Some(format!("{tag}_{}", model.name())),
            ..Default::default()
        };
        generate(desc, &opt).unwrap()
    };
    let mut cases = Vec::new();
    // idm
    let prog = gen(ModelKind::Idm);
    let p = parameter_values(&prog, &env);
    // joint arrays of the generated code: the movable joints in frame order (as the library's)
    let pick = |v: &[f64]| joints.iter().map(|&j| v[j - 1]).collect::<Vec<f64>>();
    for g in &prog.inputs[..3] {
        assert_eq!(
            g.symbols.len(),
            joints.len(),
            "{tag}: {} holds the movable joints",
            g.name
        );
    }
    cases.push(Case {
        inputs: states
            .iter()
            .map(|[q, qd, qdd]| vec![pick(q), pick(qd), pick(qdd), p.clone()])
            .collect(),
        expected: states
            .iter()
            .map(|[q, qd, qdd]| pick(&numeric_rnea(&robot, q, qd, qdd)))
            .collect(),
        prog,
        what: format!("{tag} idm"),
    });
    // inertia and h: expected outputs are checked through A qdd + H = rnea (see check_ah)
    for model in [ModelKind::Inertia, ModelKind::H] {
        let prog = gen(model);
        let p = parameter_values(&prog, &env);
        cases.push(Case {
            inputs: states
                .iter()
                .map(|[q, qd, _]| {
                    if model == ModelKind::Inertia {
                        vec![pick(q), p.clone()]
                    } else {
                        vec![pick(q), pick(qd), p.clone()]
                    }
                })
                .collect(),
            expected: states
                .iter()
                .map(|[q, qd, qdd]| pick(&numeric_rnea(&robot, q, qd, qdd)))
                .collect(),
            prog,
            what: format!("{tag} {}", model.name()),
        });
    }
    // ddm
    let prog = gen(ModelKind::Ddm);
    let p = parameter_values(&prog, &env);
    cases.push(Case {
        inputs: states
            .iter()
            .map(|[q, qd, qdd]| {
                let tau = numeric_rnea(&robot, q, qd, qdd);
                vec![pick(q), pick(qd), pick(&tau), p.clone()]
            })
            .collect(),
        expected: states.iter().map(|[_, _, qdd]| pick(qdd)).collect(),
        prog,
        what: format!("{tag} ddm"),
    });
    cases
}

/// G of the SR400 from Example 10.1: theta3 = theta7 + pi/2 - theta2, theta8 = theta2 - theta7;
/// rows q1..q8, columns the actuated joints 1, 2, 4, 5, 6, 7.
fn sr400_g() -> DMatrix<f64> {
    let act = [1, 2, 4, 5, 6, 7];
    let mut g = DMatrix::zeros(8, 6);
    for (c, &a) in act.iter().enumerate() {
        g[(a - 1, c)] = 1.0;
    }
    g[(2, 1)] = -1.0; // q3 = -q2 + q7
    g[(2, 5)] = 1.0;
    g[(7, 1)] = 1.0; // q8 = q2 - q7
    g[(7, 5)] = -1.0;
    g
}

/// A consistent SR400 state from the actuated one: q_tr with the loop relations, qd = G qd_a,
/// qdd = G qdd_a (G constant).
fn sr400_state(qa: &[f64], qda: &[f64], qdda: &[f64]) -> [Vec<f64>; 3] {
    let g = sr400_g();
    let mut q = (&g * DVector::from_column_slice(qa)).as_slice().to_vec();
    q[2] += std::f64::consts::FRAC_PI_2;
    let qd = (&g * DVector::from_column_slice(qda)).as_slice().to_vec();
    let qdd = (&g * DVector::from_column_slice(qdda)).as_slice().to_vec();
    [q, qd, qdd]
}

fn closed_case(desc: &RobotDescription, numeric: bool) -> Case {
    let robot = Robot::new(desc.clone()).unwrap();
    let g = sr400_g();
    let opt = GenOptions {
        model: ModelKind::Closed,
        numeric,
        name: Some(format!("sr400_closed{}", if numeric { "_num" } else { "" })),
        g: Some(g.map(Expr::num)),
        ..Default::default()
    };
    let prog = generate(desc, &opt).unwrap();
    let p = parameter_values(&prog, &env_of(desc));
    let mut r = rng(400);
    let mut inputs = Vec::new();
    let mut expected = Vec::new();
    for _ in 0..3 {
        let [qa, qda, qdda] = random_state(&mut r, 6);
        let [q, qd, qdd] = sr400_state(&qa, &qda, &qdda);
        let tau = DVector::from_vec(numeric_rnea(&robot, &q, &qd, &qdd));
        expected.push((g.transpose() * tau).as_slice().to_vec());
        inputs.push(vec![q, qd, qdd, p.clone()]);
    }
    Case {
        prog,
        inputs,
        expected,
        what: "sr400 closed".into(),
    }
}

/// Closed states of a closed robot near its reference: q_a within `range` of q_a0, q_p by
/// continuation from (q_a0, q_p0) (so the assembly branch is kept), qd_a and qdd_a random.
fn closed_states(
    cc: &ClosedChain,
    qa0: &[f64],
    qp0: &[f64],
    range: f64,
    seed: u64,
) -> Vec<robodyn::algorithms::closed_chain::ClosedIdm> {
    let mut r = rng(seed);
    let n = qa0.len();
    (0..3)
        .map(|_| {
            use rand::Rng;
            let qa: Vec<f64> = qa0
                .iter()
                .map(|x| x + r.random_range(-range..range))
                .collect();
            let [_, qda, qdda] = random_state(&mut r, n);
            let mut b = cc.branch_from(qa0, qp0).unwrap();
            robodyn::closed_inverse_dynamics(cc, &mut b, &qa, &qda, &qdda).unwrap()
        })
        .collect()
}

fn v(x: &nalgebra::DVector<f64>) -> Vec<f64> {
    x.iter().copied().collect()
}

/// The closed and w models of every closed robot whose G depends on q (all but the SR400).
fn general_closed_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    for (k, (label, robot, qa0, qp0, range)) in common::cases().into_iter().enumerate() {
        if label == "sr400.toml" {
            continue;
        }
        let desc = robot.description().clone();
        let tag = label.trim_end_matches(".toml").replace('-', "_");
        let cc = ClosedChain::new(&robot).unwrap();
        let states = closed_states(&cc, qa0, qp0, range, 600 + k as u64);
        for model in [ModelKind::Closed, ModelKind::W] {
            let opt = GenOptions {
                model,
                name: Some(format!("{tag}_{}", model.name())),
                ..Default::default()
            };
            let prog = generate(&desc, &opt).unwrap();
            let p = parameter_values(&prog, &env_of(&desc));
            let inputs = states
                .iter()
                .map(|s| {
                    let st = &s.state;
                    if model == ModelKind::W {
                        vec![v(&st.q), p.clone()]
                    } else {
                        vec![v(&st.q), v(&st.qd), v(&st.qdd), p.clone()]
                    }
                })
                .collect();
            let expected = states
                .iter()
                .map(|s| {
                    if model == ModelKind::W {
                        // row by row: passive joint, then actuated joint
                        s.state.w.transpose().as_slice().to_vec()
                    } else {
                        s.gamma_cl.as_slice().to_vec()
                    }
                })
                .collect();
            cases.push(Case {
                prog,
                inputs,
                expected,
                what: format!("{tag} {}", model.name()),
            });
        }
    }
    cases
}

fn all_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let sr = sr400();
    cases.extend(tree_cases(&sr, false, 1, "sr400"));
    cases.extend(tree_cases(&sr, true, 2, "sr400_num"));
    cases.push(closed_case(&sr, false));
    cases.push(closed_case(&sr, true));
    cases.extend(tree_cases(&rx90(), false, 3, "rx90"));
    // every other bundled robot (the closed ones as their equivalent trees)
    for (k, name) in [
        "torso2arms",
        "scara",
        "fourbar",
        "fivebar",
        "spatial_loop",
        "twoloops",
    ]
    .into_iter()
    .enumerate()
    {
        let path = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../robots")
            .join(format!("{name}.toml"));
        let d = robodyn::io::load_description(&path).unwrap();
        cases.extend(tree_cases(&d, false, 20 + k as u64, name));
    }
    cases.extend(general_closed_cases());
    // robot symbols named like the code's own arrays or a language's keywords (the SCARA with
    // D2 -> end, D3 -> p, L1 -> in, G3 -> out): the emitters rename them, inputs go by position
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots/scara.toml");
    let mut text = std::fs::read_to_string(path).unwrap();
    for (from, to) in [("D2", "end"), ("D3", "p"), ("L1", "in"), ("G3", "out")] {
        text = text
            .replace(&format!("\"{from}\""), &format!("\"{to}\""))
            .replace(&format!("\n{from} = "), &format!("\n{to} = "));
    }
    let (d, _) = robodyn::io::toml_format::parse_description(&text, None).unwrap();
    for s in ["end", "p", "in", "out"] {
        assert!(d.symbols.contains_key(s), "{s}");
    }
    cases.extend(tree_cases(&d, false, 30, "reserved_names"));
    let opts = TreeOptions::default();
    for (k, seed) in [11u64, 12, 13].into_iter().enumerate() {
        let mut r = rng(seed);
        let n = 3 + 2 * k;
        let d = random_tree_description(&mut r, n, &opts);
        cases.extend(tree_cases(&d, false, seed, &format!("tree{seed}")));
    }
    cases.extend(fixed_frame_cases());
    // the derivatives of the IDM: see codegen_derivatives.rs
    cases.extend(
        crate::codegen_derivatives::derivative_cases()
            .into_iter()
            .map(|c| Case {
                prog: c.prog,
                inputs: c.inputs,
                expected: c.expected,
                what: c.what,
            }),
    );
    // the inverse dynamic model of floating-base robots: see codegen_floating.rs
    cases.extend(
        crate::codegen_floating::floating_cases()
            .into_iter()
            .map(|c| Case {
                prog: c.prog,
                inputs: c.inputs,
                expected: c.expected,
                what: c.what,
            }),
    );
    // the geometric and kinematic models (DGM iT_j, Jacobian iJ_j): see codegen_kinematics.rs
    cases.extend(
        crate::codegen_kinematics::kinematic_cases()
            .into_iter()
            .map(|c| Case {
                prog: c.prog,
                inputs: c.inputs,
                expected: c.expected,
                what: c.what,
            }),
    );
    finish_cases(cases)
}

/// Robots whose frames include fixed joints: the generated code's joint arrays hold the movable
/// joints only (in frame order) and its fixed frames are folded into their movable ancestor; a
/// small URDF (mount, flange, side sensor and tool fixed), a random tree with many fixed frames
/// and external wrenches on them, and the UR10 and the Panda of example-robot-data when
/// installed.
fn fixed_frame_cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fixed_frames.urdf");
    let d = robodyn::io::load_description(&path).unwrap();
    assert_eq!(movable(&d), [2, 4, 5]);
    cases.extend(tree_cases(&d, false, 40, "fixed_urdf"));
    cases.extend(tree_cases(&d, true, 41, "fixed_urdf_num"));
    let opts = TreeOptions {
        p_fixed: 0.4,
        ..TreeOptions::default()
    };
    let d = random_tree_description(&mut rng(42), 9, &opts);
    assert!(movable(&d).len() < d.nl, "the tree has fixed frames");
    cases.extend(tree_cases(&d, false, 42, "tree_fixed"));
    if let Some(dir) = common::example_robot_data("generated code of UR10 and Panda not checked") {
        for (name, tag) in [("ur10_robot.urdf", "ur10"), ("panda.urdf", "panda")] {
            let path = common::find_file(&dir, name).unwrap();
            let d = robodyn::io::load_description(&path).unwrap();
            cases.extend(tree_cases(&d, true, 43, tag));
        }
    }
    cases
}

fn tmp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("robodyn-codegen-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn stdin_text(c: &Case) -> String {
    let mut s = format!("{}\n", c.inputs.len());
    for set in &c.inputs {
        for g in set {
            for x in g {
                s += &format!("{x:e} ");
            }
        }
        s.push('\n');
    }
    s
}

fn run(bin: &Path, args: &[String], input: &str) -> Vec<Vec<f64>> {
    let mut child = Command::new(bin)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "{bin:?} {args:?} failed");
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
        .collect()
}

fn rel_err(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = b.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / scale
}

/// Compare outputs of case `c` (in the harness order) with the expected values; inertia and h
/// are checked together as A qdd + H = Gamma.
fn check(cases: &[Case], outputs: &[Vec<Vec<f64>>], lang: &str) -> f64 {
    let mut worst = 0.0f64;
    let mut worst_case = String::new();
    for (i, c) in cases.iter().enumerate() {
        if c.what.ends_with(" inertia") {
            let h = &outputs[i + 1];
            let hcase = &cases[i + 1];
            let qdd_all: Vec<Vec<f64>> = cases[i - 1].inputs.iter().map(|s| s[2].clone()).collect();
            let joints: Vec<usize> = c.prog.inputs[0]
                .symbols
                .iter()
                .enumerate()
                .filter_map(|(k, s)| s.as_ref().map(|_| k))
                .collect();
            let n = joints.len();
            for (s, a_low) in outputs[i].iter().enumerate() {
                let mut a = DMatrix::zeros(n, n);
                let mut k = 0;
                for r in 0..n {
                    for cc in 0..=r {
                        a[(r, cc)] = a_low[k];
                        a[(cc, r)] = a_low[k];
                        k += 1;
                    }
                }
                let qdd = DVector::from_iterator(n, joints.iter().map(|&j| qdd_all[s][j]));
                let tau = a * qdd + DVector::from_column_slice(&h[s]);
                let e = rel_err(tau.as_slice(), &hcase.expected[s]);
                assert!(e < 1e-10, "{lang} {}: A qdd + H off by {e:e}", c.what);
                worst = worst.max(e);
            }
            continue;
        }
        if c.what.ends_with(" h") {
            continue;
        }
        // the geometric models (a few products per entry) to 1e-12
        let kinematic = c.what.contains(" dgm ") || c.what.contains(" jacobian ");
        let tolerance = if kinematic { 1e-12 } else { 1e-10 };
        for (got, exp) in outputs[i].iter().zip(&c.expected) {
            let e = rel_err(got, exp);
            assert!(e < tolerance, "{lang} {}: off by {e:e}", c.what);
            if e > worst {
                worst_case = c.what.clone();
            }
            worst = worst.max(e);
        }
        assert_eq!(outputs[i].len(), c.expected.len());
    }
    println!("{lang}: worst relative error {worst:e} ({worst_case})");
    worst
}

fn rust_harness(cases: &[Case]) -> String {
    let mut s = String::new();
    for c in cases {
        s += &emit(&c.prog, Lang::Rust);
        s.push('\n');
    }
    s += "use std::io::Read;\nfn main() {\n    let which: usize = std::env::args().nth(1).unwrap().parse().unwrap();\n";
    s += "    let mut t = String::new();\n    std::io::stdin().read_to_string(&mut t).unwrap();\n";
    s += "    let v: Vec<f64> = t.split_whitespace().map(|x| x.parse().unwrap()).collect();\n";
    s += "    let n = v[0] as usize;\n    let mut pos = 1;\n    for _ in 0..n {\n        match which {\n";
    for (i, c) in cases.iter().enumerate() {
        s += &format!("            {i} => {{\n");
        let mut args = Vec::new();
        for (k, g) in c.prog.inputs.iter().enumerate() {
            let n = g.symbols.len();
            if g.by_name {
                // the parameter struct, field by field
                let fields: Vec<String> = parameter_fields(&c.prog)
                    .iter()
                    .enumerate()
                    .map(|(i, (_, f))| format!("{f}: v[pos + {i}]"))
                    .collect();
                let t = parameter_type(&c.prog, Lang::Rust).unwrap();
                s += &format!(
                    "                let g{k} = {t} {{ {} }}; pos += {n};\n",
                    fields.join(", ")
                );
                args.push(format!("&g{k}"));
            } else {
                s += &format!("                let g{k} = &v[pos..pos + {n}]; pos += {n};\n");
                args.push(format!("g{k}"));
            }
        }
        s += &format!(
            "                let mut out = [0.0f64; {}];\n                {}({}, &mut out);\n",
            c.prog.outputs.len(),
            c.prog.name,
            args.join(", ")
        );
        s += "                let o: Vec<String> = out.iter().map(|x| format!(\"{:e}\", x)).collect();\n                println!(\"{}\", o.join(\" \"));\n            }\n";
    }
    s += "            _ => panic!(),\n        }\n    }\n}\n";
    s
}

fn c_harness(cases: &[Case]) -> String {
    let mut s = String::from("#include <stdio.h>\n#include <stdlib.h>\n");
    for c in cases {
        // one helper definition is enough
        let code = emit(&c.prog, Lang::C).replace(
            "static inline double rd_sign(double x) { return (x > 0.0) - (x < 0.0); }",
            "",
        );
        s += &code;
        s.push('\n');
    }
    s = s.replacen(
        "#include <math.h>",
        "#include <math.h>\nstatic inline double rd_sign(double x) { return (x > 0.0) - (x < 0.0); }",
        1,
    );
    s += "int main(int argc, char **argv) {\n    if (argc < 2) return 2;\n    int which = atoi(argv[1]);\n    int n;\n    if (scanf(\"%d\", &n) != 1) return 1;\n";
    s += "    static double buf[100000];\n    for (int s = 0; s < n; s++) {\n        switch (which) {\n";
    for (i, c) in cases.iter().enumerate() {
        let total: usize = c.prog.inputs.iter().map(|g| g.symbols.len()).sum();
        s += &format!("        case {i}: {{\n            for (int k = 0; k < {total}; k++) if (scanf(\"%lf\", &buf[k]) != 1) return 1;\n");
        let mut off = 0;
        let mut args = Vec::new();
        for g in &c.prog.inputs {
            if g.by_name {
                let fields: Vec<String> = parameter_fields(&c.prog)
                    .iter()
                    .enumerate()
                    .map(|(i, (_, f))| format!(".{f} = buf[{}]", off + i))
                    .collect();
                let t = parameter_type(&c.prog, Lang::C).unwrap();
                s += &format!("            {t} p = {{ {} }};\n", fields.join(", "));
                args.push("&p".to_string());
            } else {
                args.push(format!("buf + {off}"));
            }
            off += g.symbols.len();
        }
        let no = c.prog.outputs.len();
        s += &format!(
            "            double out[{}];\n            {}({}, out);\n            for (int k = 0; k < {no}; k++) printf(\"%.17g \", out[k]);\n            printf(\"\\n\");\n            break;\n        }}\n",
            no.max(1),
            c.prog.name,
            args.join(", ")
        );
    }
    s += "        }\n    }\n    return 0;\n}\n";
    s
}

#[test]
fn generated_rust_and_c_agree_with_numeric_models() {
    let cases = all_cases();
    let dir = tmp_dir("rc");
    // Rust
    let rs = dir.join("gen.rs");
    std::fs::write(&rs, rust_harness(&cases)).unwrap();
    let bin = dir.join("gen_rs");
    // unoptimized: the values are the same (Rust does not contract or reorder floating-point
    // operations at any level) and rustc compiles the large generated file faster
    let st = Command::new("rustc")
        .args(["--edition", "2021", "-C", "opt-level=0", "-o"])
        .arg(&bin)
        .arg(&rs)
        .status()
        .expect("rustc runs");
    assert!(st.success(), "generated Rust does not compile: {rs:?}");
    let outs: Vec<Vec<Vec<f64>>> = cases
        .iter()
        .enumerate()
        .map(|(i, c)| run(&bin, &[i.to_string()], &stdin_text(c)))
        .collect();
    let worst_rs = check(&cases, &outs, "rust");
    // C
    let cs = dir.join("gen.c");
    std::fs::write(&cs, c_harness(&cases)).unwrap();
    let cbin = dir.join("gen_c");
    // unoptimized too: -std=c99 turns floating-point contraction off and x86-64 has no excess
    // precision, so the values do not depend on the level; -O1 took most of this test's time
    let st = Command::new("cc")
        .args([
            "-std=c99",
            "-O0",
            "-Wall",
            "-Wextra",
            "-pedantic",
            "-Werror",
            "-o",
        ])
        .arg(&cbin)
        .arg(&cs)
        .arg("-lm")
        .status()
        .expect("cc runs");
    assert!(st.success(), "generated C does not compile: {cs:?}");
    let outs: Vec<Vec<Vec<f64>>> = cases
        .iter()
        .enumerate()
        .map(|(i, c)| run(&cbin, &[i.to_string()], &stdin_text(c)))
        .collect();
    let worst_c = check(&cases, &outs, "c");
    println!(
        "{} programs; worst relative error: Rust {worst_rs:e}, C {worst_c:e}",
        cases.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The same programs interpreted (Program::evaluate) agree, and Python/NumPy code agrees when
/// python3 with numpy is available.
#[test]
fn interpreted_and_python_agree() {
    let cases = all_cases();
    let outs: Vec<Vec<Vec<f64>>> = cases
        .iter()
        .map(|c| {
            c.inputs
                .iter()
                .map(|set| {
                    let mut env: HashMap<String, f64> = HashMap::new();
                    for (g, vals) in c.prog.inputs.iter().zip(set) {
                        for (s, v) in g.symbols.iter().zip(vals) {
                            if let Some(s) = s {
                                env.insert(s.clone(), *v);
                            }
                        }
                    }
                    c.prog.evaluate(&|s| env.get(s).copied()).unwrap()
                })
                .collect()
        })
        .collect();
    check(&cases, &outs, "interpreted");
    if !crate::harness::numpy("Python emitter not executed") {
        return;
    }
    let dir = tmp_dir("py");
    let mut py = String::new();
    for c in &cases {
        py += &emit(&c.prog, Lang::Python);
        py.push('\n');
    }
    // one interpreter for every case (a process per case parsed the whole file again each
    // time): the cases' states one after the other on stdin, a `#` line after each's outputs
    py += "import sys\nv = [float(x) for x in sys.stdin.read().split()]\npos = 0\nfuns = [";
    // (function, [(size, names of a group passed by name or None)])
    let sizes: Vec<String> = cases
        .iter()
        .map(|c| {
            let s: Vec<String> = c
                .prog
                .inputs
                .iter()
                .map(|g| {
                    let names = if g.by_name {
                        format!("{}_PARAMETERS", c.prog.name.to_uppercase())
                    } else {
                        "None".into()
                    };
                    format!("({}, {names})", g.symbols.len())
                })
                .collect();
            format!("({}, [{}])", c.prog.name, s.join(", "))
        })
        .collect();
    py += &sizes.join(", ");
    py += "]\nfor f, sz in funs:\n    n = int(v[pos]); pos += 1\n    for _ in range(n):\n        args = []\n        for k, names in sz:\n            x = v[pos:pos + k]; pos += k\n            args.append(np.array(x) if names is None else dict(zip(names, x)))\n        print(' '.join(repr(float(x)) for x in f(*args)))\n    print('#')\n";
    let file = dir.join("gen.py");
    std::fs::write(&file, py).unwrap();
    let input: String = cases.iter().map(stdin_text).collect();
    let mut child = Command::new("python3")
        .arg(&file)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // written from another thread: the outputs fill the pipe while the input is still read
    let writer = std::thread::spawn(move || stdin.write_all(input.as_bytes()).unwrap());
    let o = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(o.status.success(), "python failed");
    let text = String::from_utf8(o.stdout).unwrap();
    let outs: Vec<Vec<Vec<f64>>> = text
        .split_terminator("#\n")
        .map(|case| {
            case.lines()
                .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
                .collect()
        })
        .collect();
    assert_eq!(outs.len(), cases.len(), "one output block per case");
    let worst = check(&cases, &outs, "python");
    println!("python worst relative error {worst:e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The MATLAB emitter: every program written as a function file `NAME.m` and run by GNU Octave
/// on the same states agrees with the numeric models. `.ci/run` installs Octave and sets
/// ROBODYN_REQUIRE=all, so that a missing install fails there instead of skipping.
#[test]
fn matlab_code_runs_in_octave_and_agrees() {
    let octave = common::tool_available(
        "octave-cli",
        &["--norc", "--quiet", "--eval", "exit(0)"],
        "octave",
        "generated MATLAB (Debian package `octave`)",
    );
    if !octave {
        return;
    }
    let cases = all_cases();
    let dir = tmp_dir("m");
    // one driver script: read the states of a case, call the function, print its outputs
    let mut driver = String::from(
        "1;\nfunction run_case(name, sz, fields, infile, outfile)\n\
         \x20 f = str2func(name);\n\
         \x20 fid = fopen(infile, 'r'); v = fscanf(fid, '%f'); fclose(fid);\n\
         \x20 n = v(1); pos = 2; fo = fopen(outfile, 'w');\n\
         \x20 for s = 1:n\n\
         \x20   args = cell(1, numel(sz));\n\
         \x20   for k = 1:numel(sz)\n\
         \x20     args{k} = v(pos:pos + sz(k) - 1); pos = pos + sz(k);\n\
         \x20   end\n\
         \x20   if ~isempty(fields)\n\
         \x20     args{end} = cell2struct(num2cell(args{end}), fields, 1);\n\
         \x20   end\n\
         \x20   out = f(args{:});\n\
         \x20   fprintf(fo, '%.17g ', out); fprintf(fo, '\\n');\n\
         \x20 end\n\
         \x20 fclose(fo);\n\
         end\n",
    );
    for (i, c) in cases.iter().enumerate() {
        let code = emit(&c.prog, Lang::Matlab);
        assert!(
            code.contains(&format!("function out = {}(", c.prog.name)),
            "{}: MATLAB function header",
            c.what
        );
        std::fs::write(dir.join(format!("{}.m", c.prog.name)), code).unwrap();
        std::fs::write(dir.join(format!("in{i}.txt")), stdin_text(c)).unwrap();
        let sizes: Vec<String> = c
            .prog
            .inputs
            .iter()
            .map(|g| g.symbols.len().to_string())
            .collect();
        // the fields of the parameter struct (the last argument), if the function takes one
        let fields: Vec<String> = parameter_fields(&c.prog)
            .iter()
            .map(|(_, f)| format!("'{f}'"))
            .collect();
        driver += &format!(
            "run_case('{}', [{}], {{{}}}, 'in{i}.txt', 'out{i}.txt');\n",
            c.prog.name,
            sizes.join(" "),
            fields.join("; ")
        );
    }
    std::fs::write(dir.join("driver.m"), driver).unwrap();
    let o = Command::new("octave-cli")
        .args(["--norc", "--quiet", "driver.m"])
        .current_dir(&dir)
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "octave failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let outs: Vec<Vec<Vec<f64>>> = (0..cases.len())
        .map(|i| {
            std::fs::read_to_string(dir.join(format!("out{i}.txt")))
                .unwrap()
                .lines()
                .map(|l| l.split_whitespace().map(|t| t.parse().unwrap()).collect())
                .collect()
        })
        .collect();
    let worst = check(&cases, &outs, "matlab (octave)");
    println!(
        "matlab (octave) worst relative error {worst:e} over {} programs",
        cases.len()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The constant G found numerically (loop closure + constraint Jacobian) equals the G written by
/// hand from Example 10.1.
#[test]
fn sr400_constant_g_matches_example_10_1() {
    let robot = Robot::new(sr400()).unwrap();
    let g = constant_g(&robot).unwrap();
    assert_eq!(g, sr400_g());
    // a random tree has no loop: a clear error
    let t = robodyn_testing::random_tree(&mut rng(5), 4, &TreeOptions::default());
    assert!(constant_g(&t).is_err());
}

/// Base parameters of Table 10.2: the closed-chain model generated with the 42 base parameters as
/// symbols, evaluated with the grouped values computed from the standard parameters, gives the
/// same Gamma_cl as G^T rnea with all standard parameters, on consistent closed-loop states.
#[test]
fn sr400_base_parameters_reproduce_the_closed_chain_torques() {
    let desc = sr400();
    let robot = Robot::new(desc.clone()).unwrap();
    let base = sr400_base::table_10_2();
    let opt = GenOptions {
        model: ModelKind::Closed,
        base: Some(base.clone()),
        g: Some(sr400_g().map(Expr::num)),
        ..Default::default()
    };
    let prog = generate(&desc, &opt).unwrap();
    let std_env = env_of(&desc);
    let grouped: HashMap<String, f64> = base
        .grouped
        .iter()
        .map(|g| (g.name.clone(), g.expr.eval(&std_env).unwrap()))
        .collect();
    let params = prog.inputs.iter().find(|g| g.by_name).unwrap();
    let n_base = params
        .symbols
        .iter()
        .flatten()
        .filter(|s| {
            grouped.contains_key(*s)
                || [
                    "XY4", "XZ4", "YZ4", "MX4", "XY5", "XZ5", "YZ5", "MX5", "XY6", "XZ6", "YZ6",
                    "ZZ6", "MX6", "MY6", "MY2", "MY7", "MY8", "IA4", "IA5", "IA6",
                ]
                .contains(&s.as_str())
        })
        .count();
    assert_eq!(n_base, 42, "Table 10.2 has 42 base parameters");
    let g = sr400_g();
    let mut r = rng(42);
    for _ in 0..5 {
        let [qa, qda, qdda] = random_state(&mut r, 6);
        let [q, qd, qdd] = sr400_state(&qa, &qda, &qdda);
        let tau = DVector::from_vec(numeric_rnea(&robot, &q, &qd, &qdd));
        let expected = g.transpose() * tau;
        let vals: HashMap<String, f64> = (1..=8)
            .flat_map(|j| {
                [
                    (format!("q{j}"), q[j - 1]),
                    (format!("QP{j}"), qd[j - 1]),
                    (format!("QDP{j}"), qdd[j - 1]),
                ]
            })
            .collect();
        let got = prog
            .evaluate(&|s| {
                vals.get(s)
                    .or_else(|| grouped.get(s))
                    .copied()
                    .or_else(|| std_env(s))
            })
            .unwrap();
        let e = rel_err(&got, expected.as_slice());
        assert!(
            e < 1e-10,
            "base-parameter model off by {e:e}: {got:?} vs {expected}"
        );
    }
}

/// The options remove exactly what they say: the symmetric / no-friction / no-rotor models of the
/// SR400 and of a random tree agree with `rnea` on the robot whose corresponding parameters were
/// set to zero in the description.
#[test]
fn options_match_robots_with_those_parameters_zero() {
    let mut r = rng(77);
    let trees = [
        sr400(),
        random_tree_description(&mut r, 5, &TreeOptions::default()),
    ];
    for desc in trees {
        for (symmetric, friction, rotor) in [
            (true, true, true),
            (false, false, true),
            (true, false, false),
        ] {
            let mut zeroed = desc.clone();
            for l in &mut zeroed.links {
                for (k, name) in STANDARD_PARAMETERS.iter().enumerate() {
                    let z = (symmetric && ["XY", "XZ", "YZ", "MX", "MY"].contains(name))
                        || (!friction && ["FS", "FV"].contains(name))
                        || (!rotor && *name == "IA");
                    if z {
                        l.params[k] = Expr::zero();
                    }
                }
            }
            let robot = Robot::new(zeroed).unwrap();
            let opt = GenOptions {
                symmetric,
                friction,
                rotor,
                ..Default::default()
            };
            let prog = generate(&desc, &opt).unwrap();
            let env = env_of(&desc);
            let joints = movable(&desc);
            let [q, qd, qdd] = random_state(&mut r, desc.nl);
            let expected: Vec<f64> = numeric_rnea(&robot, &q, &qd, &qdd)
                .iter()
                .enumerate()
                .filter(|(k, _)| joints.contains(&(k + 1)))
                .map(|(_, x)| *x)
                .collect();
            let got = prog
                .evaluate(&|s| {
                    let i = s.trim_end_matches(|c: char| c.is_ascii_digit()).len();
                    let j: Option<usize> = s[i..].parse().ok();
                    match (&s[..i], j) {
                        ("q", Some(j)) => Some(q[j - 1]),
                        ("QP", Some(j)) => Some(qd[j - 1]),
                        ("QDP", Some(j)) => Some(qdd[j - 1]),
                        _ => env(s),
                    }
                })
                .unwrap();
            let e = rel_err(&got, &expected);
            assert!(
                e < 1e-10,
                "{} {symmetric} {friction} {rotor}: {e:e}",
                desc.name
            );
        }
    }
}

/// Closed chains whose G depends on q: the generated W is the derivative of the loop closure
/// (central differences of q_p solved at q_a +- h, h = 1e-5: truncation ~1e-10, closure
/// tolerance 1e-12 / h ~1e-7, so 1e-6 relative), and the generated Gamma_cl satisfies the
/// virtual power balance Gamma_cl . qd_a = Gamma_tr . qd_tr with Gamma_tr the numeric tree
/// torques (10.40 read as power).
#[test]
fn generated_w_is_the_derivative_of_loop_closure() {
    for (k, (label, robot, qa0, qp0, range)) in common::cases().into_iter().enumerate() {
        let desc = robot.description().clone();
        let cc = ClosedChain::new(&robot).unwrap();
        let gen = |model| {
            let opt = GenOptions {
                model,
                ..Default::default()
            };
            generate(&desc, &opt).unwrap()
        };
        let (wprog, cprog) = (gen(ModelKind::W), gen(ModelKind::Closed));
        let env = env_of(&desc);
        for s in closed_states(&cc, qa0, qp0, range, 900 + k as u64) {
            let st = &s.state;
            let value = |name: &str| -> Option<f64> {
                let i = name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
                let j: Option<usize> = name[i..].parse().ok();
                match (&name[..i], j) {
                    ("q", Some(j)) => Some(st.q[j - 1]),
                    ("QP", Some(j)) => Some(st.qd[j - 1]),
                    ("QDP", Some(j)) => Some(st.qdd[j - 1]),
                    _ => env(name),
                }
            };
            let w = wprog.evaluate(&value).unwrap();
            let (pj, aj) = (cc.passive_coordinates().frames(), cc.coordinates().frames());
            let qa: Vec<f64> = aj.iter().map(|&j| st.q[j - 1]).collect();
            let qp: Vec<f64> = pj.iter().map(|&j| st.q[j - 1]).collect();
            let b = cc.branch_from(&qa, &qp).unwrap();
            let h = 1e-5;
            let mut worst = 0.0f64;
            for (c, _) in aj.iter().enumerate() {
                let solve = |d: f64| {
                    let mut x = qa.clone();
                    x[c] += d;
                    robodyn::loop_closure(&cc, &mut b.clone(), &x).unwrap().q_p
                };
                let (plus, minus) = (solve(h), solve(-h));
                for r in 0..pj.len() {
                    let fd = (plus[r] - minus[r]) / (2.0 * h);
                    let got = w[r * aj.len() + c];
                    worst = worst.max((got - fd).abs() / fd.abs().max(1.0));
                }
            }
            assert!(
                worst < 1e-6,
                "{label}: generated W off the finite differences by {worst:e}"
            );
            // virtual power
            let gcl = cprog.evaluate(&value).unwrap();
            let qda: Vec<f64> = aj.iter().map(|&j| st.qd[j - 1]).collect();
            let p_cl: f64 = gcl.iter().zip(&qda).map(|(g, v)| g * v).sum();
            let p_tr: f64 = s.gamma_tr.iter().zip(&st.qd).map(|(g, v)| g * v).sum();
            let scale = s.gamma_tr.amax() * st.qd.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let power_err = (p_cl - p_tr).abs() / scale.max(1.0);
            assert!(power_err < 1e-10, "{label}: power {p_cl} vs {p_tr}");
            println!("{label}: W vs finite differences {worst:.1e}, virtual power {power_err:.1e}");
        }
    }
}

/// The canonical order of expressions is total when rationals and floats meet (it compared a
/// rational and a float as equal, which broke transitivity: sorting the terms of Talos's
/// symbolic model, whose folded links mix URDF floats with exact constants, panicked).
#[test]
fn expression_order_is_total_on_mixed_numbers() {
    use robodyn_symbolic::cmp_expr;
    use std::cmp::Ordering;
    let r = |n: i64, d: i64| Expr::parse(&format!("{n}/{d}")).unwrap();
    // floats: no short decimal (Expr::num keeps those exact)
    let f = |x: f64| Expr::num(x + 1e-13);
    let items = [
        r(1, 2),
        f(0.25),
        r(3, 1),
        f(0.5),
        f(3.0),
        r(-7, 3),
        f(-2.0),
        r(1, 3),
    ];
    for a in &items {
        for b in &items {
            assert_eq!(cmp_expr(a, b), cmp_expr(b, a).reverse(), "{a} vs {b}");
            // distinct numbers are never equal (equality must be transitive)
            if cmp_expr(a, b) == Ordering::Equal {
                assert_eq!(a.eval(&|_| None).unwrap(), b.eval(&|_| None).unwrap());
            }
            for c in &items {
                if cmp_expr(a, b) == Ordering::Less && cmp_expr(b, c) == Ordering::Less {
                    assert_eq!(cmp_expr(a, c), Ordering::Less, "{a} < {b} < {c}");
                }
            }
        }
    }
    let mut v = items.to_vec();
    v.sort_by(cmp_expr);
    let values: Vec<f64> = v.iter().map(|e| e.eval(&|_| None).unwrap()).collect();
    assert!(values.windows(2).all(|w| w[0] <= w[1]), "{values:?}");
}
