//! SYMORO's meaning of the parameters in the base-parameter methods: a parameter written as a
//! literal 0 does not exist (a symbol with value 0 does), the file's own parameter names (never
//! clashing with the made-up ones), files without numeric values (generic geometry), float
//! noise of URDF geometry, the closed-chain sampler's start (a singular q = 0 is left for a
//! regular start on the parallelogram branch, a singular `assembly` is refused), and the size
//! limit of the numerical method (an error before allocating).

use robodyn::algorithms::base_parameters::closed::StartOrigin;
use robodyn::algorithms::base_parameters::{
    compare_methods, geometry_robot, numeric_base_parameters, numeric_base_parameters_auto,
    standard_values, symbolic_base_parameters, ClosedChainSampler, NumericOptions, ParameterNames,
    Summary, TreeSampler,
};
use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode, ZeroParameters};
use robodyn::{Expr, RobotDescription};
use robodyn_testing::{random_tree, rng, TreeOptions};
use std::path::Path;

fn bundled(name: &str) -> RobotDescription {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name);
    robodyn::io::load_description(&p).unwrap()
}

/// Both methods on `desc`: (symbolic, numeric) base sets must agree; returns the count.
fn both(desc: &RobotDescription, sel: &ParameterSelection) -> usize {
    let sb = symbolic_base_parameters(desc, sel).unwrap();
    let (robot, _) = geometry_robot(desc).unwrap();
    let opt = NumericOptions {
        selection: sel.clone(),
        samples: None,
        seed: 5,
    };
    let (nb, _) = numeric_base_parameters_auto(&robot, &opt).unwrap();
    let cmp = compare_methods(&sb, &nb, &ParameterNames::of(desc));
    assert!(cmp.same(), "{}: {}", desc.name, cmp.note());
    sb.count()
}

/// RX-90 (`robots/rx90.par`, every parameter a symbol) with XY6, IA6 and every FS written as
/// literal 0: those 8 were base parameters alone (Table of the RX-90: XY6, IA6, FS1..FS6), so
/// 8 fewer base parameters, as OpenSYMORO counts (52 -> 44). A symbol whose value is 0 stays.
#[test]
fn a_literal_zero_is_not_a_parameter_a_symbol_with_value_zero_is() {
    let mut desc = bundled("rx90.par");
    // rx90.par writes its friction as literal zeros: make it symbols FSj, FVj (value 0.1)
    for j in 1..=6 {
        for (p, n) in [(11, "FS"), (12, "FV")] {
            desc.link_mut(j).params[p] = Expr::symbol(format!("{n}{j}"));
            desc.symbols.insert(format!("{n}{j}"), 0.1);
        }
    }
    let sel = |d: &RobotDescription, z| {
        ParameterSelection::from_description(d, RotorMode::Actuated, Friction::Actuated)
            .with_zero_parameters(d, z)
    };
    let full = both(&desc, &sel(&desc, ZeroParameters::Absent));
    // the same robot with the symbols XY6, IA6, FS1..FS6 given the value 0: still parameters
    for name in ["XY6", "IA6", "FS1", "FS2", "FS3", "FS4", "FS5", "FS6"] {
        desc.symbols.insert(name.into(), 0.0);
    }
    assert_eq!(both(&desc, &sel(&desc, ZeroParameters::Absent)), full);
    // written as literal 0
    desc.link_mut(6).params[1] = Expr::zero();
    desc.link_mut(6).params[10] = Expr::zero();
    for j in 1..=6 {
        desc.link_mut(j).params[11] = Expr::zero();
    }
    assert_eq!(both(&desc, &sel(&desc, ZeroParameters::Absent)), full - 8);
    // and as values (TOML / URDF meaning): every parameter exists
    assert_eq!(both(&desc, &sel(&desc, ZeroParameters::Value)), full);
    assert_eq!(
        ZeroParameters::for_path(Path::new("a.PAR")),
        ZeroParameters::Absent
    );
    assert_eq!(
        ZeroParameters::for_path(Path::new("a.urdf")),
        ZeroParameters::Value
    );
}

/// MX2 of the RX-90 written as 0: as in SYMORO a base parameter takes its place
/// (MXR2 = D3 (M3 + M4 + M5 + M6), Theorem 10.1 with link 3 at d = D3), found by both methods
/// with the same value.
#[test]
fn an_absent_parameter_can_hold_grouped_ones() {
    let mut desc = bundled("rx90.par");
    let mx2 = 13 + 6;
    desc.link_mut(2).params[6] = Expr::zero();
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::None)
        .with_zero_parameters(&desc, ZeroParameters::Absent);
    let sb = symbolic_base_parameters(&desc, &sel).unwrap();
    let r = sb
        .base
        .iter()
        .position(|&i| i == mx2)
        .expect("MXR2 is a base parameter");
    let want = Expr::parse("D3*(M3 + M4 + M5 + M6)").unwrap();
    assert!(
        (sb.equations[r].clone() - want).expand().is_zero(),
        "{}",
        sb.equations[r]
    );
    let (robot, _) = geometry_robot(&desc).unwrap();
    let opt = NumericOptions {
        selection: sel,
        samples: None,
        seed: 2,
    };
    let nb = numeric_base_parameters(&robot, &mut TreeSampler, &opt).unwrap();
    assert_eq!(nb.base, sb.base);
    // values from the file's numbers (rx90.par carries them in its robodyn comment)
    let k = standard_values(&desc);
    let kn: Vec<f64> = k.iter().map(|v| v.unwrap()).collect();
    let vs = sb.values(&desc, &k);
    let vn = nb.base_values(&kn);
    let rn = nb.base.iter().position(|&i| i == mx2).unwrap();
    assert!((vs[r].unwrap() - vn[rn]).abs() < 1e-9 * vn[rn].abs().max(1.0));
}

/// A file that names link 1's mass `M11` (as SYMORO+'s Orthoglide does) on a robot with 11
/// links: the reports use the file's names and link 11's mass, written as a number, gets a name
/// that is no symbol of the file; the grouped names insert R after the parameter (`MR11`).
#[test]
fn equations_use_the_files_names_without_clash() {
    let mut r = rng(8);
    let robot = random_tree(&mut r, 11, &TreeOptions::default());
    let mut desc = robot.description().clone();
    // link j's parameters named `<P><j>1` (XX11 for link 1, ..., M111 for link 11), except link
    // 11 whose mass is a number
    for j in 1..=11 {
        for (p, name) in robodyn::model::STANDARD_PARAMETERS.iter().enumerate() {
            desc.link_mut(j).params[p] = Expr::symbol(format!("{name}{j}1"));
        }
    }
    desc.link_mut(11).params[9] = Expr::num(2.5);
    let names = ParameterNames::of(&desc);
    assert_eq!(names.name(9), "M11");
    assert_eq!(names.grouped(9), "MR11");
    let m11 = 13 * 10 + 9;
    assert_ne!(
        names.name(m11),
        "M11",
        "link 11's mass must not take link 1's name"
    );
    let file_symbols: std::collections::BTreeSet<String> = desc
        .links
        .iter()
        .flat_map(|l| l.params.iter().flat_map(|e| e.symbols()))
        .collect();
    assert!(!file_symbols.contains(names.name(m11)));
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::Actuated);
    let sb = symbolic_base_parameters(&desc, &sel).unwrap();
    let rep = Summary::from_symbolic(&desc, &sb, &names);
    for b in &rep.base {
        // every name is the file's or made unique, and equations use the file's names
        assert!(
            !b.regrouped || !file_symbols.contains(&b.name),
            "{} clashes with a symbol of the file",
            b.name
        );
        for tok in b
            .equation
            .split(|c: char| !c.is_ascii_alphanumeric() && c != '_')
        {
            let canonical_only = tok.len() > 1
                && robodyn::algorithms::base_parameters::symbolic::standard_index(tok, 11)
                    .is_some()
                && !file_symbols.contains(tok)
                && !tok.ends_with('_');
            assert!(!canonical_only, "{tok} is a robodyn name in {}", b.equation);
        }
    }
    assert_eq!(both(&desc, &sel), sb.count());
}

/// A SYMORO file without any value (geometry and inertia symbolic): the numerical method takes
/// generic values for the geometry, agrees with the rules, and gives no values.
#[test]
fn numeric_method_without_values_uses_generic_geometry() {
    let mut desc = bundled("rx90.par");
    desc.symbols.clear();
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::Actuated)
        .with_zero_parameters(&desc, ZeroParameters::Absent);
    let (robot, generic) = geometry_robot(&desc).unwrap();
    let names: Vec<&str> = generic.iter().map(|(s, _)| s.as_str()).collect();
    assert!(names.contains(&"D3") && names.contains(&"RL4"), "{names:?}");
    let opt = NumericOptions {
        selection: sel.clone(),
        samples: None,
        seed: 1,
    };
    let nb = numeric_base_parameters(&robot, &mut TreeSampler, &opt).unwrap();
    let k = standard_values(&desc);
    // only rx90.par's literal-zero friction has values
    assert!(k
        .iter()
        .enumerate()
        .all(|(i, v)| v.is_none() == (i % 13 < 11)));
    let rep = Summary::from_numeric(&desc, &nb, &ParameterNames::of(&desc), &k);
    assert!(rep.base.iter().all(|b| b.value.is_none()));
    assert!(!rep.has_values());
    let text = robodyn::report::base_parameters::text(&rep);
    assert!(text.contains("Values: none"), "{text}");
    assert_eq!(both(&desc, &sel), nb.count());
}

/// Float geometry (as a URDF gives it): the RX-90 with its alpha = +-pi/2 written as the floats
/// +-1.5707963267948966, whose cosines are 6e-17, not 0. The grouping terms those make are
/// dropped (and counted, for the report), none below 1e-12 of its equation stays, and the rules
/// still agree with the numerical method; with exact angles nothing is dropped.
#[test]
fn float_noise_of_the_geometry_is_not_a_grouping_term() {
    let mut desc = bundled("rx90.par");
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::None);
    let exact = symbolic_base_parameters(&desc, &sel).unwrap();
    assert_eq!(exact.dropped_float_terms, 0);
    for j in 1..=6 {
        let a = desc.frame(j).alpha.eval(&|_| None).unwrap();
        desc.frame_mut(j).alpha = Expr::num(a);
    }
    assert!(
        desc.frame(2).alpha.as_rational().is_none(),
        "alpha2 is a float"
    );
    let sb = symbolic_base_parameters(&desc, &sel).unwrap();
    assert!(
        sb.dropped_float_terms > 0,
        "the float angles make noise terms"
    );
    for e in &sb.equations {
        let coefs: Vec<f64> = match e.node() {
            robodyn_symbolic::Node::Add(v) => v
                .iter()
                .filter_map(|t| match t.node() {
                    robodyn_symbolic::Node::Mul(f) => f[0].as_f64(),
                    _ => None,
                })
                .collect(),
            _ => Vec::new(),
        };
        let big = coefs.iter().fold(1.0f64, |m, c| m.max(c.abs()));
        assert!(coefs.iter().all(|c| c.abs() >= 1e-12 * big), "noise in {e}");
    }
    assert_eq!(sb.base, exact.base);
    assert_eq!(both(&desc, &sel), exact.count());
}

/// OpenSYMORO's SR400 without assembly (here: robots/sr400.toml with its assembly removed):
/// q = 0 is the flattened parallelogram (Wp singular), so the sampler moves to a regular start
/// on the parallelogram branch, says so, and the numerical method finds Table 10.2's 42.
/// The same singular configuration given as `assembly` is refused.
#[test]
fn closed_sampler_never_starts_from_a_singular_configuration() {
    let mut desc = bundled("sr400.toml");
    desc.assembly = None;
    let robot = robodyn::Robot::new(desc.clone()).unwrap();
    let sampler = ClosedChainSampler::new(&robot).unwrap();
    let start = sampler.start().clone();
    match start.origin {
        StartOrigin::Moved { ratio_at_zero } => assert!(ratio_at_zero < 1e-2, "{ratio_at_zero}"),
        ref o => panic!("q = 0 should be refused: {o:?}"),
    }
    assert!(start.wp_ratio >= 1e-2);
    assert_eq!(start.parallelograms, vec![9]);
    assert!(start.describe().contains("parallelogram branch"));
    let sel = ParameterSelection::new(&robot, RotorMode::Actuated, Friction::None);
    let opt = NumericOptions {
        selection: sel,
        samples: None,
        seed: 1,
    };
    let (nb, _) = numeric_base_parameters_auto(&robot, &opt).unwrap();
    assert_eq!(nb.count(), 42, "Table 10.2");
    // a singular assembly given by the file is an error, not a silent move
    desc.assembly = Some(vec![0.0; 8]);
    let robot = robodyn::Robot::new(desc).unwrap();
    let e = ClosedChainSampler::new(&robot).unwrap_err().to_string();
    assert!(e.contains("assembly"), "{e}");
}

/// Beyond the size limit the numerical method says so before allocating W (2000 links, every
/// drive parameter: 26,000 columns).
#[test]
fn numeric_method_refuses_beyond_its_memory_limit() {
    let robot = random_tree(&mut rng(1), 2000, &TreeOptions::default());
    let opt = NumericOptions {
        selection: ParameterSelection::new(&robot, RotorMode::All, Friction::Actuated),
        samples: None,
        seed: 1,
    };
    let e = numeric_base_parameters(&robot, &mut TreeSampler, &opt)
        .unwrap_err()
        .to_string();
    assert!(e.contains("limit") && e.contains("GiB"), "{e}");
}
