//! The regressor and the base parameters of floating-base robots (issue 27, item 4):
//! - the floating regressor (nv x (13 NL + 10)) times K is the floating inverse model
//!   (Newton–Euler with the base as the root, an independent recursion that never forms Y_j) on
//!   random floating trees (fixed frames, prismatic joints, friction, rotor inertias) and on
//!   Talos, HyQ and Solo12 URDFs loaded with a free-flyer root;
//! - the numerical base parameters on the full nv rows: the base link's 10 parameters are all
//!   base parameters, the base-parameter regressor reproduces the inverse model
//!   (Phi_b beta = tau) on fresh random states (not those of the method), and least squares on
//!   simulated torques recovers beta (identification round trip);
//! - a floating state of the wrong size is an error.

use nalgebra::{DMatrix, DVector};
use robodyn::algorithms::base_parameters::{
    compare_methods, numeric_base_parameters, symbolic_base_parameters, NumericBase,
    NumericOptions, ParameterNames, TreeSampler,
};
use robodyn::algorithms::regressor::{
    parameter_count, regressor_parameters, Friction, ParameterSelection, RotorMode,
    BASE_LINK_PARAMETERS, PARAMS_PER_LINK,
};
use robodyn::io::LoadOptions;
use robodyn::{inverse_dynamics_into, regressor_into, Data, Robot};
use robodyn_testing::{self as testing, TreeOptions};

mod common;
use common::{example_robot_data, find_file};

fn no_wrenches() -> TreeOptions {
    TreeOptions {
        wrenches: false,
        friction: true,
        ..TreeOptions::default()
    }
}

/// max |a - b| / max(1, max |b|).
fn gap(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    d / b.iter().map(|y| y.abs()).fold(1.0, f64::max)
}

/// Phi K and the inverse model at one floating state.
fn both(robot: &Robot, data: &mut Data, state: &[Vec<f64>; 3]) -> (Vec<f64>, Vec<f64>) {
    let [q, v, a] = state;
    let env = robot.environment();
    let mut phi = DMatrix::zeros(robot.nv(), parameter_count(robot));
    regressor_into(robot, data, env, q, v, a, &mut phi).unwrap();
    let k = DVector::from_vec(regressor_parameters(robot));
    let by_phi = (&phi * k).as_slice().to_vec();
    let mut tau = vec![0.0; robot.nv()];
    inverse_dynamics_into(robot, data, env, q, v, a, &mut tau).unwrap();
    (by_phi, tau)
}

#[test]
fn floating_regressor_times_k_is_the_inverse_model_on_random_trees() {
    let mut rng = testing::rng(4027);
    for case in 0..60 {
        let n = 1 + case % 10;
        let robot = testing::random_floating_tree(&mut rng, n, &no_wrenches());
        assert_eq!(
            parameter_count(&robot),
            PARAMS_PER_LINK * robot.nl() + BASE_LINK_PARAMETERS
        );
        let mut data = Data::new(&robot);
        for _ in 0..5 {
            let state = testing::random_floating_state(&mut rng, robot.dof());
            let (by_phi, tau) = both(&robot, &mut data, &state);
            let e = gap(&by_phi, &tau);
            assert!(e < 1e-10, "case {case}: Phi K vs Newton-Euler gap {e:e}");
            // the base rows carry the base's own parameters: a massive base changes them
            assert!(tau[..6].iter().any(|x| x.abs() > 1e-6), "case {case}");
        }
    }
}

fn floating_urdf(name: &str) -> Option<Robot> {
    let dir = example_robot_data(&format!(
        "floating {name}: regressor, base parameters not checked"
    ))?;
    let path = find_file(&dir, name).expect("in example-robot-data");
    let robot =
        robodyn::io::load_with_options(&path, &Default::default(), &LoadOptions::floating())
            .unwrap();
    assert!(robot.is_floating());
    Some(robot)
}

#[test]
fn floating_regressor_of_example_robot_data_urdfs() {
    for name in ["talos_full_v2.urdf", "hyq_no_sensors.urdf", "solo12.urdf"] {
        let Some(robot) = floating_urdf(name) else {
            return;
        };
        let mut rng = testing::rng(12);
        let mut data = Data::new(&robot);
        for _ in 0..20 {
            let state = testing::random_floating_state(&mut rng, robot.dof());
            let (by_phi, tau) = both(&robot, &mut data, &state);
            let e = gap(&by_phi, &tau);
            assert!(e < 1e-10, "{name}: Phi K vs Newton-Euler gap {e:e}");
        }
    }
}

#[test]
fn floating_regressor_checks_its_state() {
    let mut rng = testing::rng(3);
    let robot = testing::random_floating_tree(&mut rng, 3, &no_wrenches());
    let mut data = Data::new(&robot);
    let env = robot.environment();
    let [q, v, a] = testing::random_floating_state(&mut rng, robot.dof());
    let mut phi = DMatrix::zeros(robot.nv(), parameter_count(&robot));
    // joint vectors alone (the fixed-base sizes) are refused
    let n = robot.dof();
    let e = regressor_into(&robot, &mut data, env, &q[7..], &v[6..], &a[6..], &mut phi);
    assert!(
        e.unwrap_err().to_string().contains("nq = 7 + "),
        "q of N entries"
    );
    // a Phi of the fixed-base shape is refused
    let mut small = DMatrix::zeros(n, PARAMS_PER_LINK * robot.nl());
    let e = regressor_into(&robot, &mut data, env, &q, &v, &a, &mut small).unwrap_err();
    assert!(e.to_string().contains("link 0's 10"), "{e}");
    // a quaternion that is not unit
    let mut bad = q.clone();
    bad[6] += 0.1;
    let e = regressor_into(&robot, &mut data, env, &bad, &v, &a, &mut phi).unwrap_err();
    assert!(e.to_string().contains("quaternion"), "{e}");
}

/// The numerical method with every drive parameter of the actuated joints.
fn numeric(robot: &Robot, seed: u64) -> NumericBase {
    let sel = ParameterSelection::new(robot, RotorMode::Actuated, Friction::Actuated);
    let opt = NumericOptions {
        selection: sel,
        samples: None,
        seed,
    };
    numeric_base_parameters(robot, &mut TreeSampler, &opt).unwrap()
}

/// The base-parameter regressor Phi_b (the base columns of Phi) at one state.
fn base_regressor(
    robot: &Robot,
    data: &mut Data,
    nb: &NumericBase,
    s: &[Vec<f64>; 3],
) -> DMatrix<f64> {
    let mut phi = DMatrix::zeros(robot.nv(), parameter_count(robot));
    regressor_into(
        robot,
        data,
        robot.environment(),
        &s[0],
        &s[1],
        &s[2],
        &mut phi,
    )
    .unwrap();
    phi.select_columns(&nb.base)
}

/// The checks every floating robot passes: link 0's 10 parameters are base parameters (kept
/// alone: nothing of link 0 is grouped), Phi_b beta = tau on fresh random states, and least
/// squares on those states' torques recovers beta. Returns the count.
fn check_floating_base(
    robot: &Robot,
    nb: &NumericBase,
    rng: &mut impl rand::Rng,
    what: &str,
) -> usize {
    let k0 = PARAMS_PER_LINK * robot.nl();
    for p in 0..BASE_LINK_PARAMETERS {
        assert!(
            nb.base.contains(&(k0 + p)),
            "{what}: link 0's parameter {p} not a base parameter"
        );
        assert!(
            !nb.grouped.contains(&(k0 + p)) && !nb.no_effect.contains(&(k0 + p)),
            "{what}"
        );
    }
    let beta = DVector::from_vec(nb.base_values(&regressor_parameters(robot)));
    let mut data = Data::new(robot);
    let (mut ys, mut taus) = (Vec::new(), Vec::new());
    let states = (2 * nb.count()).div_ceil(robot.nv()) + 2;
    for _ in 0..states {
        let s = testing::random_floating_state(rng, robot.dof());
        let yb = base_regressor(robot, &mut data, nb, &s);
        let mut tau = vec![0.0; robot.nv()];
        let [q, v, a] = &s;
        inverse_dynamics_into(robot, &mut data, robot.environment(), q, v, a, &mut tau).unwrap();
        let e = gap((&yb * &beta).as_slice(), &tau);
        assert!(e < 1e-10, "{what}: Phi_b beta vs Newton-Euler gap {e:e}");
        ys.push(yb);
        taus.extend(tau);
    }
    // identification round trip: least squares on the stacked Phi_b recovers beta
    let rows = ys.iter().map(|y| y.nrows()).sum();
    let mut w = DMatrix::zeros(rows, nb.count());
    let mut r = 0;
    for y in &ys {
        w.view_mut((r, 0), y.shape()).copy_from(y);
        r += y.nrows();
    }
    let est = w
        .svd(true, true)
        .solve(&DVector::from_vec(taus), 1e-12)
        .unwrap();
    let e = gap(est.as_slice(), beta.as_slice());
    assert!(e < 1e-8, "{what}: least squares recovers beta to {e:e}");
    nb.count()
}

#[test]
fn floating_numeric_base_parameters_on_random_trees() {
    let mut rng = testing::rng(5027);
    for case in 0..30 {
        let n = 1 + case % 8;
        let robot = testing::random_floating_tree(&mut rng, n, &no_wrenches());
        let nb = numeric(&robot, case as u64);
        let count = check_floating_base(&robot, &nb, &mut rng, &format!("case {case}"));
        // Khalil's general rules bound the links' part: 7 per revolute joint (YY, MZ, M
        // grouped), 4 per prismatic one (the inertia tensor grouped), plus the drive parameters
        let desc = robot.description();
        let (mut bound, mut drives) = (BASE_LINK_PARAMETERS, 0);
        for j in 1..=robot.nl() {
            let f = desc.frame(j);
            bound += match f.joint {
                robodyn::model::JointType::Revolute => 7,
                robodyn::model::JointType::Prismatic => 4,
                robodyn::model::JointType::Fixed => 0,
            };
            drives += 3 * usize::from(f.actuated && f.joint.is_movable());
        }
        assert!(
            count <= bound + drives,
            "case {case}: {count} > {bound} + {drives}"
        );
    }
}

/// rx90float.par and floatplanar2r.par (OpenSYMORO): their geometry with generic values.
fn opensymoro(file: &str) -> Robot {
    let path = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/cases/external/symoro-robots"
    ))
    .join(file);
    let desc = robodyn::io::load_description(&path).unwrap();
    let (mut robot, _) = robodyn::algorithms::base_parameters::geometry_robot(&desc).unwrap();
    // geometry_robot zeroes the parameters; the round trip needs a massive base and links
    let mut rng = testing::rng(7);
    let mut d = robot.description().clone();
    for l in d.links.iter_mut().chain(d.floating_base.as_mut()) {
        for (p, x) in testing::random_inertial(&mut rng).iter().enumerate() {
            l.params[p] = robodyn_symbolic::Expr::num(*x);
        }
    }
    robot = Robot::new(d).unwrap();
    assert!(robot.is_floating(), "{file}");
    robot
}

#[test]
fn floating_numeric_base_parameters_of_opensymoro_files() {
    let mut rng = testing::rng(90);
    // 10 (base) + 7 per revolute joint, every rotor inertia and friction parameter alone
    for (file, expected) in [
        ("floatplanar2r.par", 10 + 2 * 7 + 2 * 3),
        ("rx90float.par", 10 + 6 * 7 + 6 * 3),
    ] {
        let robot = opensymoro(file);
        let nb = numeric(&robot, 1);
        let count = check_floating_base(&robot, &nb, &mut rng, file);
        assert_eq!(count, expected, "{file}");
    }
}

#[test]
fn floating_numeric_base_parameters_of_solo12_and_hyq() {
    let mut rng = testing::rng(12);
    for name in ["solo12.urdf", "hyq_no_sensors.urdf"] {
        let Some(robot) = floating_urdf(name) else {
            return;
        };
        let nb = numeric(&robot, 1);
        let count = check_floating_base(&robot, &nb, &mut rng, name);
        assert!(count > BASE_LINK_PARAMETERS, "{name}: {count}");
    }
}

/// The symbolic rules of a floating base (Theorems 10.1 and 10.2 at every joint, no rule of the
/// links next to a fixed base) against the numerical method, the arbiter: the same count and
/// the same set, and the grouping equations give the same values as K1 + beta K2.
fn symbolic_matches_numeric(robot: &Robot, nb: &NumericBase, what: &str) {
    let desc = robot.description();
    let sel = ParameterSelection::new(robot, RotorMode::Actuated, Friction::Actuated);
    let sb = symbolic_base_parameters(desc, &sel).unwrap();
    let names = ParameterNames::of(desc);
    let cmp = compare_methods(&sb, nb, &names);
    assert!(cmp.same(), "{what}: {}", cmp.reason());
    assert_eq!(sb.count(), nb.count(), "{what}");
    let k = regressor_parameters(robot);
    let kv: Vec<Option<f64>> = k.iter().map(|&x| Some(x)).collect();
    let by_rules = sb.values(desc, &kv);
    let by_numeric = nb.base_values(&k);
    // the numerical base keeps link 0 first, the rules list it in K order: match by index
    for (r, s) in by_rules.iter().enumerate() {
        let s = s.unwrap_or_else(|| panic!("{what}: base parameter {r} has no value"));
        let at = nb
            .base
            .iter()
            .position(|&b| b == sb.base[r])
            .expect("same set");
        let n = &by_numeric[at];
        assert!(
            (s - n).abs() <= 1e-9 * n.abs().max(1.0),
            "{what}: {} = {s} by the rules, {n} numerically",
            names.name(sb.base[r])
        );
    }
}

#[test]
fn floating_symbolic_rules_match_the_numerical_method_on_random_trees() {
    let mut rng = testing::rng(6027);
    for case in 0..40 {
        let n = 1 + case % 8;
        let robot = testing::random_floating_tree(&mut rng, n, &no_wrenches());
        let nb = numeric(&robot, case as u64);
        symbolic_matches_numeric(&robot, &nb, &format!("case {case}"));
    }
}

#[test]
fn floating_symbolic_rules_of_opensymoro_files_and_urdfs() {
    for file in ["floatplanar2r.par", "rx90float.par"] {
        let robot = opensymoro(file);
        symbolic_matches_numeric(&robot, &numeric(&robot, 1), file);
    }
    for name in ["solo12.urdf", "hyq_no_sensors.urdf"] {
        let Some(robot) = floating_urdf(name) else {
            return;
        };
        symbolic_matches_numeric(&robot, &numeric(&robot, 1), name);
    }
}
