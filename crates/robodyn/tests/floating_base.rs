//! Floating bases (issue 27) beyond the Pinocchio cross-check (floating_pinocchio.rs):
//! - the direct model inverts the inverse one, idm(ddm(tau)) = tau, on random floating trees
//!   (fixed frames, prismatic joints, friction, rotor inertia, external wrenches), by both
//!   methods, and the two methods agree;
//! - the inertia matrix is A of the inverse model: idm(a) - idm(0) = A a (a linear-map check
//!   of the composite route against Newton–Euler);
//! - OpenSYMORO's rx90float.par loads, and its inverse model with the base held still (v_0 = 0,
//!   a_0 = 0, identity pose) gives the joint torques of the fixed RX-90 (rx90.par) with the same
//!   values, and a base wrench equal to what the fixed robot's joint 1 transmits to its base;
//! - a floating state is checked (lengths nq / nv, the quaternion's norm), and the functions
//!   that do not support floating bases refuse them with an error.

use nalgebra::DMatrix;
use robodyn::io::LoadOptions;
use robodyn::{
    direct_dynamics_into, h_vector_into, inertia_matrix_into, inverse_dynamics_into, Data, Method,
    Robot,
};
use robodyn_testing::{self as testing, TreeOptions};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn external(file: &str) -> PathBuf {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/cases/external/symoro-robots"
    ))
    .join(file)
}

fn max_gap(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let d = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    d / b.iter().map(|y| y.abs()).fold(1.0, f64::max)
}

#[test]
fn direct_inverts_inverse_on_random_floating_trees() {
    let mut rng = testing::rng(2727);
    for case in 0..60 {
        let n = 1 + case % 12;
        let robot = testing::random_floating_tree(&mut rng, n, &TreeOptions::default());
        let (nv, dof) = (robot.nv(), robot.dof());
        assert_eq!((robot.nq(), nv), (dof + 7, dof + 6));
        let mut data = Data::new(&robot);
        let env = robot.environment();
        let [q, v, a] = testing::random_floating_state(&mut rng, dof);
        let mut tau = vec![0.0; nv];
        inverse_dynamics_into(&robot, &mut data, env, &q, &v, &a, &mut tau).unwrap();
        for method in Method::ALL {
            let mut back = vec![0.0; nv];
            direct_dynamics_into(&robot, &mut data, env, &q, &v, &tau, method, &mut back).unwrap();
            let e = max_gap(&back, &a);
            assert!(
                e < 1e-9,
                "case {case}, {}: idm(ddm) gap {e:e}",
                method.name()
            );
        }
        // A a = idm(a) - H (A from composite links, H and idm from Newton-Euler)
        let mut am = DMatrix::zeros(nv, nv);
        inertia_matrix_into(&robot, &mut data, &q, &mut am).unwrap();
        let mut h = vec![0.0; nv];
        h_vector_into(&robot, &mut data, env, &q, &v, &mut h).unwrap();
        let lin: Vec<f64> = (&am * nalgebra::DVector::from_column_slice(&a))
            .iter()
            .zip(&h)
            .map(|(x, y)| x + y)
            .collect();
        let e = max_gap(&lin, &tau);
        assert!(e < 1e-10, "case {case}: A a + H vs idm gap {e:e}");
        assert!(
            (&am - am.transpose()).amax() < 1e-12,
            "case {case}: A symmetric"
        );
    }
}

/// Symbol values for the OpenSYMORO RX-90 files: a deterministic value per name, positive (the
/// masses, rotor inertias and friction must be), the same in both files.
fn values(robot_symbols: &[String]) -> BTreeMap<String, f64> {
    robot_symbols
        .iter()
        .map(|s| {
            let h = s
                .bytes()
                .fold(17u64, |h, b| h.wrapping_mul(31).wrapping_add(b as u64));
            let x = 0.1 + (h % 1000) as f64 / 1000.0;
            // the same gravity: G = {0, 0, G3} in rx90.par, {GX, GY, GZ} in rx90float.par
            let x = match s.as_str() {
                "GX" | "GY" => 0.0,
                "GZ" | "G3" => -9.81,
                _ => x,
            };
            (s.clone(), x)
        })
        .collect()
}

fn load_with_values(path: &Path) -> Robot {
    let d = robodyn::io::load_description(path).unwrap();
    robodyn::io::load_with(path, &values(&d.used_symbols())).unwrap()
}

#[test]
fn rx90float_with_its_base_held_still_is_the_fixed_rx90() {
    let float = load_with_values(&external("rx90float.par"));
    let fixed = load_with_values(&external("rx90.par"));
    assert!(float.is_floating() && !fixed.is_floating());
    assert_eq!(float.base_kind().name(), "floating");
    assert_eq!((float.nq(), float.nv(), fixed.nv()), (13, 12, 6));
    let m0 = float.floating_base().unwrap().body.mass;
    assert!(m0 > 0.0, "link 0's mass read from the file: {m0}");
    let mut rng = testing::rng(90);
    let (mut df, mut dx) = (Data::new(&float), Data::new(&fixed));
    for _ in 0..50 {
        let [qj, vj, aj] = testing::random_state(&mut rng, 6);
        let q: Vec<f64> = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
            .iter()
            .chain(&qj)
            .copied()
            .collect();
        let v: Vec<f64> = [0.0; 6].iter().chain(&vj).copied().collect();
        let a: Vec<f64> = [0.0; 6].iter().chain(&aj).copied().collect();
        let mut tf = vec![0.0; 12];
        let mut tx = vec![0.0; 6];
        inverse_dynamics_into(&float, &mut df, float.environment(), &q, &v, &a, &mut tf).unwrap();
        inverse_dynamics_into(&fixed, &mut dx, fixed.environment(), &qj, &vj, &aj, &mut tx)
            .unwrap();
        let e = max_gap(&tf[6..], &tx);
        assert!(e < 1e-12, "joint torques differ by {e:e}");
        // the base wrench: link 0's weight plus what joint 1 transmits to the base,
        // 0A_1 (f_1, m_1) about O_0 (= O_1: d1 = r1 = 0 on the RX-90)
        let (rot, pos) = dx.local_placements();
        let (f1, m1) = (dx.forces()[1], dx.moments()[1]);
        let g = fixed.environment().gravity;
        let body = &float.floating_base().unwrap().body;
        let f = rot[1] * f1 - g * body.mass;
        let m = rot[1] * m1 + pos[1].cross(&(rot[1] * f1)) - body.ms.cross(&g);
        let want = [f.x, f.y, f.z, m.x, m.y, m.z];
        let e = max_gap(&tf[..6], &want);
        assert!(
            e < 1e-12,
            "base wrench differs by {e:e}: {:?} vs {want:?}",
            &tf[..6]
        );
    }
}

#[test]
fn floatplanar2r_loads_and_round_trips() {
    let d = robodyn::io::load_description(external("floatplanar2r.par")).unwrap();
    let base = d.floating_base.as_ref().expect("is_floating = True");
    assert_eq!(base.params[9].to_string(), "M0");
    let back = robodyn::io::toml_format::parse_description(
        &robodyn::io::toml_format::write_description(&d),
        None,
    )
    .unwrap()
    .0;
    assert_eq!(back, d);
}

#[test]
fn floating_states_are_checked_and_unsupported_functions_refuse() {
    let mut rng = testing::rng(5);
    let robot = testing::random_floating_tree(&mut rng, 4, &TreeOptions::default());
    let mut data = Data::new(&robot);
    let env = robot.environment();
    let n = robot.dof();
    let [q, v, a] = testing::random_floating_state(&mut rng, n);
    let mut tau = vec![0.0; robot.nv()];
    // joint-sized vectors: a dimension error naming nq
    let e = inverse_dynamics_into(&robot, &mut data, env, &q[7..], &v, &a, &mut tau)
        .unwrap_err()
        .to_string();
    assert!(e.contains("nq = 7 + "), "{e}");
    // a quaternion of norm 2: refused, not renormalized silently
    let mut bad = q.clone();
    for x in &mut bad[3..7] {
        *x *= 2.0;
    }
    let e = inverse_dynamics_into(&robot, &mut data, env, &bad, &v, &a, &mut tau)
        .unwrap_err()
        .to_string();
    assert!(e.contains("quaternion") && e.contains("norm"), "{e}");
    // within the tolerance: normalized, the same torques
    let mut near = q.clone();
    for x in &mut near[3..7] {
        *x *= 1.0 + 1e-9;
    }
    let mut t2 = vec![0.0; robot.nv()];
    inverse_dynamics_into(&robot, &mut data, env, &q, &v, &a, &mut tau).unwrap();
    inverse_dynamics_into(&robot, &mut data, env, &near, &v, &a, &mut t2).unwrap();
    assert!(max_gap(&t2, &tau) < 1e-12);
    // the regressor takes nq / nv states (tests/floating_base_parameters.rs): joints alone are
    // not one; functions without floating support refuse (not a fixed-base number)
    let e = robodyn::regressor(&robot, &q[7..], &v[6..], &a[6..])
        .unwrap_err()
        .to_string();
    assert!(e.contains("nq = 7 + "), "{e}");
    let e = robodyn::ClosedChain::new(&robot).unwrap_err().to_string();
    assert!(e.contains("floating base"), "{e}");
    // the kinematics take nq / nv states (tests/floating_kinematics.rs): joints alone are not one
    let e = robodyn::frame_jacobian(
        &robot,
        &q[7..],
        &robot.frame_id_of(1).unwrap(),
        robodyn::Reference::World,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("nq = 7 + "), "{e}");
    // the generator writes the floating idm (codegen_floating.rs), and refuses the other models
    let opt = robodyn::codegen::GenOptions {
        model: robodyn::codegen::ModelKind::Inertia,
        ..Default::default()
    };
    let e = robodyn::codegen::generate(robot.description(), &opt)
        .unwrap_err()
        .to_string();
    assert!(e.contains("floating base"), "{e}");
    let e = robodyn::identification::model_access::ModelAccess::new(robot.description().clone())
        .err()
        .expect("refused")
        .to_string();
    assert!(e.contains("floating base"), "{e}");
}

#[test]
fn urdf_floating_root_joint_and_load_option_agree() {
    let urdf = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.urdf");
    let opt = robodyn::io::load_with_options(urdf, &Default::default(), &LoadOptions::floating())
        .unwrap();
    assert!(opt.is_floating());
    // the same file with a world link and a root joint of type floating
    let text = std::fs::read_to_string(urdf).unwrap();
    let root = opt
        .description()
        .floating_base
        .as_ref()
        .unwrap()
        .name
        .clone();
    let free = format!(
        "<link name=\"world\"/><joint name=\"root_joint\" type=\"floating\"><parent \
         link=\"world\"/><child link=\"{root}\"/></joint></robot>"
    );
    let with_joint = text.replacen("</robot>", &free, 1);
    let (d, _) = robodyn::io::urdf::parse_description(&with_joint, None).unwrap();
    let mut want = opt.description().clone();
    want.notes = d.notes.clone();
    want.tools = d.tools.clone();
    assert_eq!(d, want);
    // a floating base asked of a fixed .toml is an error, not ignored
    let toml = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
    let e = robodyn::io::load_with_options(toml, &Default::default(), &LoadOptions::floating())
        .unwrap_err()
        .to_string();
    assert!(e.contains("floating"), "{e}");
    // TOML: base = "floating" with [base_link]
    let text = "name = \"f\"\nbase = \"floating\"\n[base_link]\nM = 2.0\nXX = 0.1\nYY = 0.1\n\
                ZZ = 0.1\n[[frame]]\nj = 1\nant = 0\n[[link]]\nj = 1\nM = 1.0\nZZ = 0.1\n";
    let r = robodyn::io::toml_format::parse_robot(text, None).unwrap();
    assert_eq!((r.nq(), r.nv()), (8, 7));
    assert_eq!(
        r.velocity_names()[..6],
        robodyn::model::BASE_VELOCITY_NAMES.map(String::from)
    );
    // free fall: with no torque, the base falls at g (in the base frame: R' g)
    let q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.3];
    let acc =
        robodyn::direct_dynamics(&r, &q, &[0.0; 7], &[0.0; 7], Method::ArticulatedBody).unwrap();
    assert!(
        (acc[2] + 9.81).abs() < 1e-12 && acc[0].abs() < 1e-12,
        "{acc}"
    );
}
