//! The parameters of generated code (issue 30.11): a `--numeric` model takes no parameter
//! argument in any language; a symbolic one takes them by name (a struct in C and Rust, a
//! mapping in Python, fields in Julia and MATLAB), and `codegen::parameter_values` gives their
//! values from the robot file. Running the generated code is `codegen_compile.rs`'s job (every
//! language, every robot, against the numeric models, with the values passed by name).

use robodyn::codegen::{generate, parameter_values, BaseParameters, GenOptions};
use robodyn::model::STANDARD_PARAMETERS;
use robodyn::{Robot, RobotDescription};
use robodyn_symbolic::{emit, parameter_fields, parameter_type, Lang};
use robodyn_testing::{random_state, rng};
use std::path::Path;

fn load(name: &str) -> RobotDescription {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name);
    robodyn::io::load_description(&path).unwrap()
}

/// A standard parameter's value read from the description by hand (link j's entry k).
fn standard_value(desc: &RobotDescription, name: &str) -> Option<f64> {
    let i = name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    let (p, j) = (&name[..i], name[i..].parse::<usize>().ok()?);
    let k = STANDARD_PARAMETERS.iter().position(|&x| x == p)?;
    desc.links[j - 1].params[k]
        .eval(&|s| desc.symbols.get(s).copied())
        .ok()
}

#[test]
fn numeric_models_take_no_parameter_argument() {
    let desc = load("rx90.toml");
    let opt = GenOptions {
        numeric: true,
        name: Some("rx90_idm".into()),
        ..GenOptions::default()
    };
    let prog = generate(&desc, &opt).unwrap();
    assert!(prog.inputs.iter().all(|g| !g.by_name && g.name != "p"));
    let sig = [
        (
            Lang::C,
            "void rx90_idm(const double *q, const double *qd, const double *qdd, double *out)",
        ),
        (Lang::Python, "def rx90_idm(q, qd, qdd, out=None):"),
        (
            Lang::Rust,
            "pub fn rx90_idm(q: &[f64], qd: &[f64], qdd: &[f64], out: &mut [f64])",
        ),
        (Lang::Julia, "function rx90_idm!(out, q, qd, qdd)"),
        (Lang::Matlab, "function out = rx90_idm(q, qd, qdd)"),
    ];
    for (lang, s) in sig {
        let code = emit(&prog, lang);
        assert!(code.contains(s), "{lang:?}:\n{code}");
        assert!(!code.contains("(void)p"), "{lang:?}");
    }
    assert!(parameter_values(&desc, &opt, &prog).is_empty());
    assert_eq!(parameter_type(&prog, Lang::C), None);
}

#[test]
fn symbolic_models_take_their_parameters_by_name() {
    let desc = load("rx90.toml");
    let opt = GenOptions {
        name: Some("rx90_idm".into()),
        ..GenOptions::default()
    };
    let prog = generate(&desc, &opt).unwrap();
    let fields = parameter_fields(&prog);
    assert!(fields.len() > 50, "{}", fields.len());
    let c = emit(&prog, Lang::C);
    assert!(c.contains("typedef struct {\n    double D3;"), "{c}");
    assert!(c.contains("} rx90_idm_params;"));
    assert!(c.contains(
        "void rx90_idm(const double *q, const double *qd, const double *qdd, const \
         rx90_idm_params *p, double *out)"
    ));
    assert!(c.contains("const double XX2 = p->XX2;"));
    let rs = emit(&prog, Lang::Rust);
    assert!(
        rs.contains("pub struct Rx90IdmParams {\n    pub D3: f64,"),
        "{rs}"
    );
    assert!(rs.contains("p: &Rx90IdmParams, out: &mut [f64]"));
    let py = emit(&prog, Lang::Python);
    assert!(py.contains("RX90_IDM_PARAMETERS = (\"D3\", "), "{py}");
    assert!(py.contains("def rx90_idm(q, qd, qdd, p, out=None):"));
    assert!(py.contains("    XX2 = p[\"XX2\"]"));
    assert!(emit(&prog, Lang::Julia).contains("    XX2 = p.XX2"));
    assert!(emit(&prog, Lang::Matlab).contains("    XX2 = p.XX2;"));
    // the header names every field; no position of p is a convention to remember
    assert!(!c.contains("p[0]"));
}

/// `parameter_values` gives the file's values by name (symbols and standard parameters read by
/// hand here); with them, the program gives the torques of Newton-Euler.
#[test]
fn parameter_values_are_the_robot_files() {
    let desc = load("rx90.toml");
    let opt = GenOptions::default();
    let prog = generate(&desc, &opt).unwrap();
    let values = parameter_values(&desc, &opt, &prog);
    assert_eq!(values.len(), parameter_fields(&prog).len());
    for (name, v) in &values {
        let expected = desc
            .symbols
            .get(name)
            .copied()
            .or_else(|| standard_value(&desc, name))
            .unwrap();
        assert_eq!(*v, Some(expected), "{name}");
    }
    let robot = Robot::new(desc.clone()).unwrap();
    let [q, qd, qdd] = random_state(&mut rng(7), 6);
    let env = |s: &str| {
        let j = |k: &str| s.strip_prefix(k)?.parse::<usize>().ok();
        j("q")
            .map(|j| q[j - 1])
            .or_else(|| j("QP").map(|j| qd[j - 1]))
            .or_else(|| j("QDP").map(|j| qdd[j - 1]))
            .or_else(|| values.iter().find(|(n, _)| n == s).and_then(|(_, v)| *v))
    };
    let got = prog.evaluate(&env).unwrap();
    let tau = robodyn::inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
    for (a, b) in got.iter().zip(tau.iter()) {
        assert!((a - b).abs() <= 1e-10 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

/// Base parameters: a grouped parameter's value is its grouping expression on the file's
/// standard parameters (the SR400's MR3-style sums); a file without values gives None.
#[test]
fn grouped_parameter_values() {
    let desc = load("sr400.toml");
    let base = BaseParameters::symbolic(&desc, true, false).unwrap();
    let opt = GenOptions {
        base: Some(base.clone()),
        friction: false,
        ..GenOptions::default()
    };
    let prog = generate(&desc, &opt).unwrap();
    let values = parameter_values(&desc, &opt, &prog);
    let env = |s: &str| {
        desc.symbols
            .get(s)
            .copied()
            .or_else(|| standard_value(&desc, s))
    };
    let mut grouped = 0;
    for g in &base.grouped {
        if let Some((_, v)) = values.iter().find(|(n, _)| *n == g.name) {
            // the same sum, evaluated in another order
            let expected = g.expr.eval(&env).unwrap();
            let got = v.unwrap();
            assert!(
                (got - expected).abs() <= 1e-12 * expected.abs().max(1.0),
                "{}: {got} vs {expected}",
                g.name
            );
            grouped += 1;
        }
    }
    assert!(grouped > 10, "{grouped} grouped parameters in the model");
    // a file with symbols and no values: every value is None
    let mut free = desc.clone();
    free.symbols.clear();
    for l in &mut free.links {
        l.params = robodyn::model::LinkDesc::symbolic(1).params;
    }
    let prog = generate(&free, &GenOptions::default()).unwrap();
    let values = parameter_values(&free, &GenOptions::default(), &prog);
    assert!(!values.is_empty() && values.iter().all(|(_, v)| v.is_none()));
}
