//! Generated code of the floating-base inverse dynamic model (issue 27): the customized
//! Newton–Euler with the base as the root, inputs q (nq = 7 + N: base position, quaternion
//! x y z w, joints), qd and qdd (nv = 6 + N), outputs the base wrench then the joint torques.
//!
//! Cross-checks:
//! - `floating_cases` (run by `codegen_compile.rs` through the same harnesses as every other
//!   program: compiled Rust and C, Python/NumPy, MATLAB in GNU Octave, and the interpreter)
//!   against the library's numeric `inverse_dynamics` on random floating states, to 1e-10
//!   relative: the bundled `rx90float.toml` (symbolic and numeric), OpenSYMORO's
//!   `rx90float.par` and `floatplanar2r.par` (symbolic, gravity symbols GX GY GZ), Solo12 and
//!   HyQ as floating URDFs (numeric), random floating trees (fixed frames on the base and on
//!   links, prismatic joints, friction, rotor inertia, external wrenches, a random gravity
//!   direction). One state of each gives the quaternion scaled by 1.7: the generated code
//!   normalizes it (as the library's entry check does), so the expected values are those of
//!   the unit quaternion.
//! - OpenSYMORO's rx90float with its base held still (identity pose, zero twist and
//!   acceleration) and gravity: its generated joint torques equal those of the generated fixed
//!   RX-90 (rx90.par) with the same values, two programs generated independently.
//! - The other models, base parameters and closed chains refuse a floating robot with an error
//!   naming what is generated.

use robodyn::codegen::{generate, GenOptions, ModelKind, BASE_WRENCH};
use robodyn::io::LoadOptions;
use robodyn::model::STANDARD_PARAMETERS;
use robodyn::{Robot, RobotDescription};
use robodyn_symbolic::Program;
use robodyn_testing::{random_floating_state, random_floating_tree, rng, TreeOptions};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

mod common;

/// A floating program, its input sets (q, qd, qdd, p per state) and the library's outputs.
pub(crate) struct FloatingCase {
    pub prog: Program,
    pub inputs: Vec<Vec<Vec<f64>>>,
    pub expected: Vec<Vec<f64>>,
    pub what: String,
}

/// The value of a parameter of a generated program: the robot's symbols, the standard
/// parameters `XX<j>` of link j, `XX0` of the floating base's link 0.
fn parameter(desc: &RobotDescription, s: &str) -> Option<f64> {
    if let Some(v) = desc.symbols.get(s) {
        return Some(*v);
    }
    let i = s.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (p, n) = (&s[..i], s[i..].parse::<usize>().ok()?);
    let k = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
    let l = match n {
        0 => desc.floating_base.as_ref()?,
        n => desc.links.get(n - 1)?,
    };
    l.params[k].eval(&|t| desc.symbols.get(t).copied()).ok()
}

fn generate_idm(desc: &RobotDescription, numeric: bool, name: &str) -> Program {
    let opt = GenOptions {
        model: ModelKind::Idm,
        numeric,
        name: Some(name.into()),
        ..Default::default()
    };
    generate(desc, &opt).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The floating IDM of `robot` generated and its inputs and expected outputs on `states`
/// random floating states (the last one with its quaternion scaled by 1.7).
fn case(robot: &Robot, numeric: bool, seed: u64, tag: &str, states: usize) -> FloatingCase {
    let desc = robot.description();
    let prog = generate_idm(desc, numeric, &format!("{tag}_fidm"));
    let (nq, nv, n) = (robot.nq(), robot.nv(), robot.dof());
    let sizes: Vec<usize> = prog.inputs.iter().map(|g| g.symbols.len()).collect();
    assert_eq!(&sizes[..3], [nq, nv, nv], "{tag}: q, qd, qdd over nq, nv");
    assert_eq!(prog.outputs.len(), nv, "{tag}: nv outputs");
    let names: Vec<&str> = prog.outputs[..6].iter().map(|o| o.name.as_str()).collect();
    assert_eq!(names, BASE_WRENCH, "{tag}: the base wrench first");
    let p: Vec<f64> = prog
        .inputs
        .iter()
        .filter(|g| g.by_name)
        .flat_map(|g| &g.symbols)
        .map(|s| {
            let s = s.as_deref().unwrap();
            parameter(desc, s).unwrap_or_else(|| panic!("{tag}: no value for {s}"))
        })
        .collect();
    let mut r = rng(seed);
    let mut inputs = Vec::new();
    let mut expected = Vec::new();
    for k in 0..states {
        let [q, v, a] = random_floating_state(&mut r, n);
        let tau = robodyn::inverse_dynamics(robot, &q, &v, &a).unwrap();
        expected.push(tau.as_slice().to_vec());
        let mut qin = q.clone();
        if k + 1 == states {
            qin[3..7].iter_mut().for_each(|x| *x *= 1.7);
        }
        inputs.push(vec![qin, v, a, p.clone()]);
    }
    FloatingCase {
        prog,
        inputs,
        expected,
        what: format!("{tag} floating idm"),
    }
}

fn external(file: &str) -> Option<PathBuf> {
    let dir = crate::harness::shared(
        "cases/external/symoro-robots",
        "generated floating IDM of OpenSYMORO's rx90float.par, floatplanar2r.par",
    )?;
    Some(dir.join(file))
}

/// Symbol values for the OpenSYMORO files: a deterministic positive value per name (masses,
/// rotor inertias and friction must be), the same in rx90.par and rx90float.par; gravity
/// (0, 0, -9.81) in both (G3 in rx90.par, GX GY GZ in rx90float.par).
fn values(symbols: &[String]) -> BTreeMap<String, f64> {
    symbols
        .iter()
        .map(|s| {
            let h = s
                .bytes()
                .fold(17u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
            let x = match s.as_str() {
                "GX" | "GY" => 0.0,
                "GZ" | "G3" => -9.81,
                _ => 0.1 + (h % 1000) as f64 / 1000.0,
            };
            (s.clone(), x)
        })
        .collect()
}

fn load_with_values(path: &Path, gravity: Option<[f64; 3]>) -> Robot {
    let d = robodyn::io::load_description(path).unwrap();
    let mut v = values(&d.used_symbols());
    if let Some(g) = gravity {
        for (name, x) in ["GX", "GY", "GZ"].into_iter().zip(g) {
            v.insert(name.into(), x);
        }
    }
    robodyn::io::load_with(path, &v).unwrap()
}

fn bundled(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name)
}

/// The floating cases of the compile harness of `codegen_compile.rs`.
pub(crate) fn floating_cases() -> Vec<FloatingCase> {
    let mut cases = Vec::new();
    let values = [("G3".to_string(), -9.81)].into_iter().collect();
    let rx = robodyn::io::load_with(bundled("rx90float.toml"), &values).unwrap();
    cases.push(case(&rx, false, 1, "rx90float", 4));
    cases.push(case(&rx, true, 2, "rx90float_num", 4));
    if let Some(path) = external("rx90float.par") {
        // gravity in a direction that is no axis: every row of wR_0 is used
        let r = load_with_values(&path, Some([1.5, -2.0, -9.0]));
        cases.push(case(&r, false, 3, "rx90float_par", 4));
        let r = load_with_values(&path.with_file_name("floatplanar2r.par"), None);
        cases.push(case(&r, false, 4, "floatplanar2r", 4));
    }
    if let Some(dir) = common::example_robot_data("generated floating IDM of Solo12, HyQ") {
        for (file, tag) in [("solo12.urdf", "solo12"), ("hyq_no_sensors.urdf", "hyq")] {
            let path = common::find_file(&dir, file).unwrap();
            let r =
                robodyn::io::load_with_options(&path, &BTreeMap::new(), &LoadOptions::floating())
                    .unwrap();
            assert!(r.is_floating());
            cases.push(case(&r, true, 5, tag, 3));
        }
    }
    let mut r = rng(2727);
    for (k, (n, p_fixed)) in [(3, 0.1), (6, 0.4), (9, 0.3)].into_iter().enumerate() {
        let opts = TreeOptions {
            p_fixed,
            gravity: (k > 0).then_some([2.0, -3.0, -8.5]),
            ..TreeOptions::default()
        };
        let robot = random_floating_tree(&mut r, n, &opts);
        let tag = format!("ftree{k}");
        cases.push(case(&robot, false, 10 + k as u64, &tag, 4));
        cases.push(case(&robot, true, 20 + k as u64, &format!("{tag}_num"), 3));
    }
    // a tree whose base carries fixed frames (their bodies folded into the base body, their
    // external wrenches carried onto it)
    let attached = (0..40)
        .map(|_| {
            random_floating_tree(
                &mut r,
                5,
                &TreeOptions {
                    p_fixed: 0.5,
                    ..TreeOptions::default()
                },
            )
        })
        .find(|robot| {
            robot
                .description()
                .frames
                .iter()
                .any(|f| f.ant == 0 && !f.joint.is_movable())
        })
        .expect("a random tree with a fixed frame on the base");
    cases.push(case(&attached, false, 30, "ftree_base_fixed", 4));
    cases
}

/// The generated programs, interpreted, agree with the library (the compiled languages run the
/// same cases from `codegen_compile.rs`).
#[test]
fn generated_floating_idm_interpreted_agrees_with_library() {
    let mut worst = 0.0f64;
    for c in floating_cases() {
        for (set, want) in c.inputs.iter().zip(&c.expected) {
            let mut env: BTreeMap<String, f64> = BTreeMap::new();
            for (g, vals) in c.prog.inputs.iter().zip(set) {
                for (s, v) in g.symbols.iter().zip(vals) {
                    if let Some(s) = s {
                        env.insert(s.clone(), *v);
                    }
                }
            }
            let got = c.prog.evaluate(&|s| env.get(s).copied()).unwrap();
            let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
            let e = got
                .iter()
                .zip(want)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                / scale;
            assert!(e < 1e-10, "{}: off by {e:e}", c.what);
            worst = worst.max(e);
        }
    }
    println!("floating idm, interpreted: worst relative error {worst:e}");
}

/// OpenSYMORO's rx90float held still (identity pose, zero base twist and acceleration) under
/// gravity: the generated joint torques are those of the generated fixed RX-90.
#[test]
fn rx90float_held_still_generates_the_fixed_rx90_torques() {
    let Some(path) = external("rx90float.par") else {
        return;
    };
    let float = load_with_values(&path, None);
    let fixed = load_with_values(&path.with_file_name("rx90.par"), None);
    let pf = generate_idm(float.description(), false, "rx90float_idm");
    let px = generate_idm(fixed.description(), false, "rx90_idm");
    let mut r = rng(90);
    for _ in 0..20 {
        let [q, qd, qdd] = robodyn_testing::random_state(&mut r, 6);
        let eval = |prog: &Program, robot: &Robot, base: bool| -> Vec<f64> {
            let desc = robot.description();
            let mut env: BTreeMap<String, f64> = BTreeMap::new();
            let still = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
            let rest = [0.0; 6];
            let groups: [(&[f64], &[f64]); 3] = if base {
                [(&still, &q), (&rest, &qd), (&rest, &qdd)]
            } else {
                [(&[], &q), (&[], &qd), (&[], &qdd)]
            };
            for (g, (b, j)) in prog.inputs.iter().zip(groups) {
                for (s, v) in g.symbols.iter().zip(b.iter().chain(j)) {
                    if let Some(s) = s {
                        env.insert(s.clone(), *v);
                    }
                }
            }
            prog.evaluate(&|s| env.get(s).copied().or_else(|| parameter(desc, s)))
                .unwrap()
        };
        let tf = eval(&pf, &float, true);
        let tx = eval(&px, &fixed, false);
        let scale = tx.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (a, b) in tf[6..].iter().zip(&tx) {
            assert!((a - b).abs() <= 1e-12 * scale, "{a} vs {b}");
        }
        // the base carries the robot's weight: not zero
        assert!(tf[..3].iter().any(|f| f.abs() > 1.0), "{tf:?}");
    }
}

/// The other models, base parameters and a closed chain refuse a floating robot by name.
#[test]
fn floating_refusals_name_what_is_generated() {
    let values = [("G3".to_string(), -9.81)].into_iter().collect();
    let rx = robodyn::io::load_with(bundled("rx90float.toml"), &values).unwrap();
    let desc = rx.description();
    for model in [
        ModelKind::Inertia,
        ModelKind::H,
        ModelKind::Ddm,
        ModelKind::IdmDerivatives,
    ] {
        let opt = GenOptions {
            model,
            ..Default::default()
        };
        let e = generate(desc, &opt).unwrap_err().to_string();
        assert!(
            e.contains("floating base") && e.contains(model.name()) && e.contains("`idm`"),
            "{e}"
        );
    }
    let opt = GenOptions {
        base: Some(Default::default()),
        ..Default::default()
    };
    let e = generate(desc, &opt).unwrap_err().to_string();
    assert!(e.contains("base parameters"), "{e}");
}

/// Operation counts of the generated floating IDM (numeric values, as `robodyn generate
/// --numeric` prints them) against the fixed base's, printed for the documentation; the
/// floating model costs the fixed model plus the base's terms, and fewer than twice as many.
#[test]
fn floating_idm_operation_counts() {
    let values = [("G3".to_string(), -9.81)].into_iter().collect();
    let float = robodyn::io::load_with(bundled("rx90float.toml"), &values).unwrap();
    let fixed = robodyn::io::load_with(bundled("rx90.toml"), &values).unwrap();
    let cf = generate_idm(float.description(), true, "f").count();
    let cx = generate_idm(fixed.description(), true, "x").count();
    println!("RX-90 numeric idm: fixed {cx}; floating {cf}");
    assert!(
        cf.mul > cx.mul && cf.add > cx.add,
        "fixed {cx}, floating {cf}"
    );
    assert!(
        cf.mul < 2 * cx.mul && cf.add < 2 * cx.add,
        "fixed {cx}, floating {cf}"
    );
    let Some(dir) = common::example_robot_data("operation counts of Solo12, HyQ, Talos") else {
        return;
    };
    for file in ["solo12.urdf", "hyq_no_sensors.urdf", "talos_full_v2.urdf"] {
        let path = common::find_file(&dir, file).unwrap();
        let none = BTreeMap::new();
        let fixed = robodyn::io::load_with_options(&path, &none, &LoadOptions::default()).unwrap();
        let float = robodyn::io::load_with_options(&path, &none, &LoadOptions::floating()).unwrap();
        let t = std::time::Instant::now();
        let cf = generate_idm(float.description(), true, "f").count();
        let time = t.elapsed().as_secs_f64();
        let cx = generate_idm(fixed.description(), true, "x").count();
        println!(
            "{file} ({} joints) numeric idm: fixed root {cx}; floating {cf} (generated in {time:.2} s)",
            float.dof()
        );
        assert!(cf.mul > cx.mul, "{file}: fixed {cx}, floating {cf}");
    }
}
