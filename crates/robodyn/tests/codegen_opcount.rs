//! The operation count of a program equals the number of arithmetic operators in its emitted C
//! code (an independent route: counting tokens of the printed code, not walking expressions).

use robodyn::codegen::{generate, GenOptions, ModelKind};
use robodyn_symbolic::{emit, Lang};
use robodyn_testing::{random_tree_description, rng, TreeOptions};

/// Multiplications (`*`, `/`) and additions (binary `+`, `-`) of one C expression; a numeric
/// literal `(p.0/q.0)` is one constant, a leading or nested unary minus is a sign change.
fn count_tokens(expr: &str) -> (usize, usize) {
    // 1. numeric literals -> `L`
    let b = expr.as_bytes();
    let mut s = String::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i] as char;
        let prev_ident = s
            .chars()
            .last()
            .is_some_and(|p| p.is_ascii_alphanumeric() || p == '_');
        if c.is_ascii_digit() && !prev_ident {
            while i < b.len() && ((b[i] as char).is_ascii_digit() || b[i] == b'.') {
                i += 1;
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                i += 1;
                if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
                    i += 1;
                }
                while i < b.len() && (b[i] as char).is_ascii_digit() {
                    i += 1;
                }
            }
            s.push('L');
            continue;
        }
        s.push(c);
        i += 1;
    }
    // 2. a rational constant (L/L) is one literal
    let s = s.replace("(L/L)", "L").replace("(-L/L)", "L");
    // 3. operators
    let mut mul = 0;
    let mut add = 0;
    let mut prev: Option<char> = None;
    for c in s.chars() {
        match c {
            '*' | '/' => mul += 1,
            '+' => add += 1,
            '-' if prev.is_some_and(|p| p.is_ascii_alphanumeric() || p == '_' || p == ')') => {
                add += 1
            }
            _ => {}
        }
        if c != ' ' {
            prev = Some(c);
        }
    }
    (mul, add)
}

fn check(prog: &robodyn_symbolic::Program) {
    let c = emit(prog, Lang::C);
    let (mut mul, mut add) = (0, 0);
    for line in c.lines() {
        let line = line.trim();
        let body = if let Some(rest) = line.strip_prefix("const double ") {
            let (name, e) = rest.split_once(" = ").unwrap();
            // input reads `q1 = q[0]`, `XX1 = p->XX1` cost nothing
            if (e.contains('[') || e.contains("->")) && !e.contains(' ') {
                continue;
            }
            let _ = name;
            e.trim_end_matches(';').to_string()
        } else if line.starts_with("out[") {
            let (_, e) = line.split_once(" = ").unwrap();
            e.split(";  //").next().unwrap().to_string()
        } else {
            continue;
        };
        let (m, a) = count_tokens(&body);
        mul += m;
        add += a;
    }
    let k = prog.count();
    assert_eq!((mul, add), (k.mul, k.add), "{}", prog.name);
}

#[test]
fn counts_equal_operators_of_the_printed_code() {
    let desc = robodyn::io::load_description(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/sr400.toml"
    )))
    .unwrap();
    for model in [ModelKind::Idm, ModelKind::Inertia, ModelKind::Ddm] {
        for numeric in [false, true] {
            let opt = GenOptions {
                model,
                numeric,
                ..Default::default()
            };
            check(&generate(&desc, &opt).unwrap());
        }
    }
    // the geometric and kinematic models, every frame choice of codegen_kinematics.rs
    for c in crate::codegen_kinematics::kinematic_cases() {
        check(&c.prog);
    }
    let mut r = rng(8);
    for n in [3, 6] {
        let d = random_tree_description(&mut r, n, &TreeOptions::default());
        for model in [ModelKind::Idm, ModelKind::H] {
            let opt = GenOptions {
                model,
                ..Default::default()
            };
            check(&generate(&d, &opt).unwrap());
        }
    }
}
