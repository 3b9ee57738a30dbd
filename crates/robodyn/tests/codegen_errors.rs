//! Errors of the generator are values with clear messages; emitters' output is well formed.

use robodyn::codegen::{constant_g, generate, BaseParameters, GenOptions, ModelKind};
use robodyn::model::{JointType, LinkDesc};
use robodyn::{Expr, Robot, RobotDescription};
use robodyn_symbolic::{emit, Lang};

/// A planar four-bar (crank 1, coupler 1.5, rocker 1.2, ground 2): G depends on q.
fn four_bar() -> RobotDescription {
    let mut d = RobotDescription::new("four-bar", 3, 4);
    let set = |d: &mut RobotDescription, j: usize, ant: usize, len: f64, act: bool| {
        let f = d.frame_mut(j);
        f.ant = ant;
        f.d = Expr::num(len);
        f.actuated = act;
    };
    set(&mut d, 1, 0, 0.0, true);
    set(&mut d, 2, 1, 1.0, false);
    set(&mut d, 3, 0, 2.0, false);
    set(&mut d, 4, 2, 1.5, false);
    set(&mut d, 5, 3, 1.2, false);
    d.frame_mut(5).joint = JointType::Fixed;
    let mut r = robodyn_testing::rng(4);
    for j in 1..=3 {
        let mut l = LinkDesc::zero(format!("l{j}"));
        for (k, v) in robodyn_testing::random_inertial(&mut r).iter().enumerate() {
            l.params[k] = Expr::num(*v);
        }
        d.links[j - 1] = l;
    }
    d
}

/// G depending on q: constant_g says so; the general closed model needs the loops closed at the
/// reference configuration (the file's `assembly`, else q = 0) and is generated once they are.
#[test]
fn general_closed_chain_needs_a_closed_reference() {
    let mut d = four_bar();
    let robot = Robot::new(d.clone()).unwrap();
    let e = constant_g(&robot).unwrap_err().to_string();
    assert!(e.contains("not constant"), "{e}");
    let opt = GenOptions {
        model: ModelKind::Closed,
        ..Default::default()
    };
    // the four-bar does not close at q = 0 (no assembly given)
    let e = generate(&d, &opt).unwrap_err().to_string();
    assert!(
        e.contains("four-bar") && e.contains("do not close at the reference configuration"),
        "{e}"
    );
    // with a closed assembly configuration the model is generated
    let cc = robodyn::ClosedChain::new(&robot).unwrap();
    let sol = [[1.0, 1.0], [-1.0, 1.0], [1.0, -1.0], [2.0, 2.0]]
        .iter()
        .find_map(|g| {
            let mut b = cc.branch_from(&[0.3], g).ok()?;
            robodyn::loop_closure(&cc, &mut b, &[0.3]).ok()
        })
        .expect("the four-bar closes at q1 = 0.3");
    d.assembly = Some(sol.q_tree.iter().copied().collect());
    let prog = generate(&d, &opt).unwrap();
    assert_eq!(prog.outputs.len(), 1);
    assert_eq!(prog.outputs[0].name, "GAMCL1");
    // the closed model of a tree is refused
    let t = robodyn_testing::random_tree_description(
        &mut robodyn_testing::rng(1),
        3,
        &Default::default(),
    );
    for model in [ModelKind::Closed, ModelKind::W] {
        let opt = GenOptions {
            model,
            ..Default::default()
        };
        let e = generate(&t, &opt).unwrap_err().to_string();
        assert!(e.contains("closed loops"), "{e}");
    }
}

#[test]
fn numeric_needs_values() {
    let mut d = RobotDescription::new("symbolic", 2, 2);
    d.frame_mut(2).d = Expr::symbol("L1");
    let opt = GenOptions {
        numeric: true,
        ..Default::default()
    };
    let e = generate(&d, &opt).unwrap_err().to_string();
    assert!(e.contains("L1"), "{e}");
    // symbolic generation needs no value
    let p = generate(&d, &GenOptions::default()).unwrap();
    assert!(p.input_symbols().contains(&"L1".to_string()));
}

#[test]
fn base_file_errors_name_the_line() {
    let ok = BaseParameters::parse("# SR400\nXXR2 = XX2 - YY2\nzero: YY2 MZ2\n", "b.txt").unwrap();
    assert_eq!(ok.grouped.len(), 1);
    assert_eq!(ok.grouped[0].replaces, "XX2");
    assert!(ok.zero.contains("MZ2"));
    let e = BaseParameters::parse("XXR2 = XX2\nFOO3 = 1\n", "b.txt")
        .unwrap_err()
        .to_string();
    assert!(e.contains("b.txt:2") && e.contains("FOO3"), "{e}");
    let e = BaseParameters::parse("zero: XX1 QQ2\n", "b.txt")
        .unwrap_err()
        .to_string();
    assert!(e.contains("b.txt:1") && e.contains("QQ2"), "{e}");
    let e = BaseParameters::parse("XXR2 = (XX2\n", "b.txt")
        .unwrap_err()
        .to_string();
    assert!(e.contains("b.txt:1"), "{e}");
}

#[test]
fn emitters_are_well_formed() {
    let d = robodyn_testing::random_tree_description(
        &mut robodyn_testing::rng(3),
        3,
        &Default::default(),
    );
    let p = generate(&d, &GenOptions::default()).unwrap();
    let n = p.assignments.len() + p.outputs.len();
    let tex = emit(&p, Lang::Latex);
    assert!(tex.contains("\\begin{align*}") && tex.contains("\\end{align*}"));
    assert_eq!(tex.matches(" &= ").count(), n);
    let jl = emit(&p, Lang::Julia);
    assert!(jl.contains(&format!("function {}!(out, q, qd, qdd, p)", p.name)));
    assert!(jl.contains("out[1] = ") && jl.trim_end().ends_with("end"));
    assert!(!jl.contains("q[0]"), "Julia is 1-based");
    let text = emit(&p, Lang::Text);
    let c = p.count();
    assert!(text.contains(&format!(
        "Operations: {} multiplications, {} additions",
        c.mul, c.add
    )));
    assert_eq!(
        text.lines()
            .filter(|l| !l.starts_with('#') && l.contains(" = "))
            .count(),
        n
    );
}
