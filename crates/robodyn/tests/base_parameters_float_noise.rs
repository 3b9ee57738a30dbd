//! Float noise in the symbolic base parameters of a URDF (issue 15, item 8): a grouping term
//! whose float coefficient is below `FLOAT_TERM_TOLERANCE * L^k` (L the robot's largest
//! length, k the length power of the coefficient's unit) is rounding noise and is dropped. Checked
//! against the numerical method (QR of a random-sample regressor: same set) and against the
//! full model (base regressor times the grouped values = full regressor times K on random
//! states), on the bundled RX-90 URDF and on UR5, UR10 and Panda from example-robot-data.

use robodyn::algorithms::base_parameters::{
    numeric_base_parameters, symbolic_base_parameters, NumericOptions, SymbolicBase, TreeSampler,
};
use robodyn::algorithms::regressor::{parameter_name, Friction, ParameterSelection, RotorMode};
use robodyn::{Expr, Robot, RobotDescription};
use std::path::Path;

fn bundled(name: &str) -> std::path::PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots")).join(name)
}

fn names(v: &[usize]) -> Vec<String> {
    v.iter().map(|&c| parameter_name(c)).collect()
}

/// Symbolic (with the float tolerance) against numeric and against the full model.
fn check(label: &str, robot: &Robot) -> SymbolicBase {
    let sel = ParameterSelection::new(robot, RotorMode::Actuated, Friction::Actuated);
    let sb = symbolic_base_parameters(robot.description(), &sel).unwrap();
    let nopt = NumericOptions {
        selection: sel,
        samples: None,
        seed: 3,
    };
    let nb = numeric_base_parameters(robot, &mut TreeSampler, &nopt).unwrap();
    assert_eq!(
        names(&sb.base),
        names(&nb.base),
        "{label}: symbolic vs numeric set"
    );
    let err = crate::base_parameters::check_symbolic_reproduces(robot, &sb, &mut TreeSampler, 21);
    assert!(err < 1e-10, "{label}: base model error {err:e}");
    // what is left holds no coefficient of the noise's size (1e-17..1e-23 relative)
    for e in &sb.equations {
        let text = e.to_string();
        for tiny in ["e-16", "e-17", "e-18", "e-19", "e-2"] {
            assert!(!text.contains(tiny), "{label}: noise left in {text}");
        }
    }
    sb
}

#[test]
fn rx90_urdf_noise_is_dropped_and_the_rules_still_agree_with_numeric() {
    let robot = robodyn::io::load(bundled("rx90.urdf")).unwrap();
    check("rx90.urdf", &robot);
    // the RX-90 with its alpha = +-pi/2 as the floats +-1.5707963267948966 (cos = 6e-17)
    let float = Robot::new(float_rx90()).unwrap();
    let sb = check("rx90 (float angles)", &float);
    assert!(sb.dropped_float_terms > 0, "the float angles make noise");
    // the same robot from its exact .par: nothing to drop, same number of base parameters
    let exact = robodyn::io::load(bundled("rx90.par")).unwrap();
    let sel = ParameterSelection::new(&exact, RotorMode::Actuated, Friction::Actuated);
    let se = symbolic_base_parameters(exact.description(), &sel).unwrap();
    assert_eq!(se.dropped_float_terms, 0);
}

/// Exact inputs (rationals, symbols, pi/2) are never touched by the tolerance.
#[test]
fn exact_inputs_drop_nothing() {
    for name in [
        "sr400.toml",
        "sr400.par",
        "rx90.par",
        "tx40.toml",
        "torso2arms.toml",
    ] {
        let desc = robodyn::io::load_description(bundled(name)).unwrap();
        let sel =
            ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::Actuated);
        let sb = symbolic_base_parameters(&desc, &sel).unwrap();
        assert_eq!(sb.dropped_float_terms, 0, "{name}");
    }
}

/// The tolerance is unit-free: the same robot with its lengths in millimetres (b, d, r times
/// 1000) drops the same number of terms and keeps the same base set; L scales by 1000.
#[test]
fn the_tolerance_does_not_depend_on_the_length_unit() {
    let desc = float_rx90();
    let mm = scaled(&desc, 1000.0);
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::Actuated);
    let a = symbolic_base_parameters(&desc, &sel).unwrap();
    let b = symbolic_base_parameters(&mm, &sel).unwrap();
    assert!(a.dropped_float_terms > 0);
    assert_eq!(a.dropped_float_terms, b.dropped_float_terms);
    assert_eq!(a.base, b.base);
    assert!((b.length_scale / a.length_scale - 1000.0).abs() < 1e-9);
}

/// robots/rx90.par with its angles as floats, its lengths as numbers.
fn float_rx90() -> RobotDescription {
    let mut d = robodyn::io::load_description(bundled("rx90.par")).unwrap();
    let env = d.symbols.clone();
    for f in d.frames.iter_mut() {
        for e in [&mut f.alpha, &mut f.b, &mut f.d, &mut f.r] {
            *e = Expr::num(e.eval(&|s| env.get(s).copied()).unwrap());
        }
    }
    d
}

fn scaled(desc: &RobotDescription, s: f64) -> RobotDescription {
    let mut d = desc.clone();
    for f in d.frames.iter_mut() {
        for e in [&mut f.b, &mut f.d, &mut f.r] {
            *e = Expr::num(e.eval(&|_| None).unwrap() * s);
        }
    }
    d
}

/// A genuine small coefficient above the tolerance stays: a 1e-9 rad tilt of a joint axis is
/// geometry, not noise (the numerical method sees it too, as a change of the grouping values).
#[test]
fn a_term_above_the_tolerance_is_kept() {
    let desc = robodyn::io::load_description(bundled("rx90.par")).unwrap();
    let sel = ParameterSelection::from_description(&desc, RotorMode::Actuated, Friction::Actuated);
    let mut tilted = desc.clone();
    tilted.frame_mut(3).alpha = Expr::num(1e-7 + 1e-15);
    let sb = symbolic_base_parameters(&tilted, &sel).unwrap();
    // coefficients of the tilt's size (sin 1e-7 times a length or 1) are kept
    let small = sb
        .equations
        .iter()
        .flat_map(|e| match e.node() {
            robodyn_symbolic::Node::Add(v) => v.clone(),
            _ => Vec::new(),
        })
        .filter_map(|t| match t.node() {
            robodyn_symbolic::Node::Mul(f) => f[0].as_f64(),
            _ => None,
        })
        .filter(|c| (1e-9..1e-6).contains(&c.abs()))
        .count();
    assert!(small > 0, "the 1e-7 tilt makes small, real coefficients");
}

#[test]
fn example_robot_data_urdfs() {
    let Some(dir) = crate::io_urdf_pinocchio::robots_dir() else {
        return;
    };
    for name in ["ur5_robot.urdf", "ur10_robot.urdf", "panda.urdf"] {
        let path = crate::io_urdf_pinocchio::find(&dir, name)
            .unwrap_or_else(|| panic!("{name} not found under {}", dir.display()));
        let robot = robodyn::io::load(&path).unwrap();
        let sb = check(name, &robot);
        // the UR arms' URDFs give float noise terms (dropped); every angle of the Panda's is
        // an exact multiple of pi/4 (its hand turned by -pi/4 included): it has none
        if name.starts_with("ur") {
            assert!(sb.dropped_float_terms > 0, "{name}");
        }
    }
}
