//! Motor–joint transmissions in the models (issue 31, item 4): with m = R q, the motors' IA, FS,
//! FV (motor units) add R^T (IA m_dd + FV m_d + FS sign(m_d)) to the joint-side torques and
//! R^T IA R to A(q). Cross-checked against
//! - the identification's observation rows (its own motor columns, built from the regressor)
//!   times the robot's standard parameters: an independent route to the same torques;
//! - the torques of the links alone (the robot without its transmission and with the motors'
//!   parameters zero) plus the drive torques computed here by hand;
//! - round trips idm(ddm(tau)) = tau with both direct methods;
//! - the energy balance of a free motion: links' T + U (the Lagrangian-route energies of the
//!   robot without motors) plus 1/2 (R qd)' IA (R qd) computed here, conserved.

use robodyn::algorithms::energy::total_energy;
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::parameters::{ParameterModel, ParameterOptions};
use robodyn::model::{param, RobotDescription, Transmission, PARAMS_PER_LINK};
use robodyn::simulation::{simulate, Integrator, Recorder, SimOptions, TorqueInput, TreeDynamics};
use robodyn::{
    direct_dynamics, inertia_matrix, inverse_dynamics, ClosedChain, Expr, Method, Robot,
};
use robodyn_testing::{random_state, random_tree_description, rng, TreeOptions};
use std::path::PathBuf;

/// The TX40 with motor drive parameters (motor units) on its coupled wrist (motor 6 turns with
/// q5 + q6) and some inertia of link 6 about its axis.
fn tx40() -> RobotDescription {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/tx40.toml");
    let mut d = robodyn::io::load_description(&path).unwrap();
    let motors = [
        (3e-5, 0.2, 8e-3),
        (3e-5, 0.25, 5e-3),
        (5e-5, 0.12, 1e-3),
        (1.2e-5, 0.04, 5e-4),
        (1.8e-5, 0.06, 6e-4),
        (9e-6, 0.07, 6e-4),
    ];
    for (l, (ia, fs, fv)) in d.links.iter_mut().zip(motors) {
        l.params[param::IA] = Expr::num(ia);
        l.params[param::FS] = Expr::num(fs);
        l.params[param::FV] = Expr::num(fv);
    }
    for i in [param::XX, param::YY, param::ZZ] {
        d.links[5].params[i] = Expr::num(1e-3);
    }
    assert!(d.transmission.is_some(), "tx40.toml has the wrist coupling");
    d
}

/// A random 5-link tree (fixed frames, prismatic joints, wrenches, motors' IA, FS, FV) with a
/// random invertible R over its movable joints.
fn random_robot(seed: u64, friction: bool) -> RobotDescription {
    let mut r = rng(seed);
    let opt = TreeOptions {
        wrenches: friction,
        ..TreeOptions::default()
    };
    let mut d = random_tree_description(&mut r, 5, &opt);
    // motor-side values: the gear ratios below (10..50) reflect them by their squares
    for l in &mut d.links {
        for (p, f) in [(param::IA, 1e-3), (param::FS, 2e-2), (param::FV, 1e-3)] {
            let v = if friction || p == param::IA {
                f * l.params[p].eval(&|_| None).unwrap()
            } else {
                0.0
            };
            l.params[p] = Expr::num(v);
        }
    }
    let joints = d.movable_joints();
    let n = joints.len();
    // diagonal gear ratios, then couplings: well conditioned, not triangular
    let mut s = seed;
    let mut next = || {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let matrix = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    if i == j {
                        10.0 + 40.0 * (next() + 0.5)
                    } else {
                        12.0 * next()
                    }
                })
                .collect()
        })
        .collect();
    d.transmission = Some(Transmission { joints, matrix });
    d
}

/// The same robot without its transmission and with the motors' IA, FS, FV zero: the links
/// alone.
fn links_alone(d: &RobotDescription) -> Robot {
    let mut d = d.clone();
    let t = d.transmission.take().unwrap();
    for &j in &t.joints {
        for p in [param::IA, param::FS, param::FV] {
            d.links[j - 1].params[p] = Expr::zero();
        }
    }
    Robot::new(d).unwrap()
}

/// R^T (IA R qdd + FV R qd + FS sign(R qd)) by hand, over the movable joints (the
/// transmission's joints are all of them here).
fn drive_torques(d: &RobotDescription, qd: &[f64], qdd: &[f64]) -> Vec<f64> {
    let t = d.transmission.as_ref().unwrap();
    let k = Robot::new(d.clone()).unwrap().standard_parameters();
    let mut tau = vec![0.0; qd.len()];
    for (m, row) in t.matrix.iter().enumerate() {
        let at = |p: usize| k[PARAMS_PER_LINK * (t.joints[m] - 1) + p];
        let md: f64 = row.iter().zip(qd).map(|(a, b)| a * b).sum();
        let mdd: f64 = row.iter().zip(qdd).map(|(a, b)| a * b).sum();
        let f = at(param::IA) * mdd + at(param::FV) * md + at(param::FS) * sign(md);
        for (c, a) in row.iter().enumerate() {
            tau[c] += a * f;
        }
    }
    tau
}

/// sign(x) in {-1, 0, 1} (`f64::signum(0.0)` is 1).
fn sign(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x.signum()
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

fn scale(a: &[f64]) -> f64 {
    a.iter().fold(1.0f64, |m, x| m.max(x.abs()))
}

fn cases() -> Vec<(&'static str, RobotDescription)> {
    vec![
        ("tx40", tx40()),
        ("random 11", random_robot(11, true)),
        ("random 12", random_robot(12, true)),
        ("random 13", random_robot(13, true)),
    ]
}

/// The IDM with the transmission equals the links' torques plus the drive torques by hand, and
/// the identification's rows (regressor and motor columns) times the standard parameters.
#[test]
fn inverse_model_adds_the_reflected_drives() {
    for (name, d) in cases() {
        let robot = Robot::new(d.clone()).unwrap();
        assert!(robot.motor_drives().is_some_and(|m| !m.is_inert()));
        let alone = links_alone(&d);
        let mut access = ModelAccess::new(d.clone()).unwrap();
        let opt = ParameterOptions {
            joint_drives: false,
            ..ParameterOptions::default()
        };
        let mut model = ParameterModel::build(&mut access, &opt).unwrap();
        let x = model.values(&robot.standard_parameters());
        let (n, p) = (robot.dof(), model.count());
        let mut r = rng(7);
        for _ in 0..5 {
            let [q, qd, qdd] = random_state(&mut r, n);
            let tau = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
            let tau = tau.as_slice();
            // links alone + drives by hand
            let links = inverse_dynamics(&alone, &q, &qd, &qdd).unwrap();
            let drives = drive_torques(&d, &qd, &qdd);
            let by_hand: Vec<f64> = links.iter().zip(&drives).map(|(a, b)| a + b).collect();
            let e = max_diff(tau, &by_hand) / scale(tau);
            assert!(e < 1e-12, "{name}: IDM vs links + drives: {e:e}");
            assert!(
                max_diff(tau, links.as_slice()) > 1e-3 * scale(tau),
                "{name}: the drives must matter for the test to mean something"
            );
            // the identification's observation rows
            let (mut w, mut tau_e) = (vec![0.0; n * p], vec![0.0; n]);
            model
                .rows(&mut access, &q, &qd, &qdd, &mut w, &mut tau_e)
                .unwrap();
            let rows: Vec<f64> = (0..n)
                .map(|i| tau_e[i] + (0..p).map(|c| w[i * p + c] * x[c]).sum::<f64>())
                .collect();
            let e = max_diff(tau, &rows) / scale(tau);
            assert!(e < 1e-8, "{name}: IDM vs identification rows: {e:e}");
        }
    }
}

/// ddm then idm gives the torques back (both methods), and A(q) is the links' plus R^T IA R.
#[test]
fn direct_model_inverts_the_inverse_model() {
    for (name, d) in cases() {
        let robot = Robot::new(d.clone()).unwrap();
        let alone = links_alone(&d);
        let n = robot.dof();
        let mut r = rng(8);
        for _ in 0..5 {
            let [q, qd, qdd] = random_state(&mut r, n);
            let tau = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
            for method in Method::ALL {
                let back = direct_dynamics(&robot, &q, &qd, tau.as_slice(), method).unwrap();
                let e = max_diff(back.as_slice(), &qdd) / scale(&qdd);
                assert!(e < 1e-9, "{name} {method:?}: ddm(idm(qdd)) vs qdd: {e:e}");
                let again = inverse_dynamics(&robot, &q, &qd, back.as_slice()).unwrap();
                let e = max_diff(again.as_slice(), tau.as_slice()) / scale(tau.as_slice());
                assert!(e < 1e-9, "{name} {method:?}: idm(ddm(tau)) vs tau: {e:e}");
            }
            // A = A_links + R^T IA R: A e_k is the drive-inertia torque of qdd = e_k
            let a = inertia_matrix(&robot, &q).unwrap();
            let a_links = inertia_matrix(&alone, &q).unwrap();
            let zero = vec![0.0; n];
            for k in 0..n {
                let mut e = zero.clone();
                e[k] = 1.0;
                let col = drive_torques(&d, &zero, &e);
                for i in 0..n {
                    let want = a_links[(i, k)] + col[i];
                    assert!((a[(i, k)] - want).abs() < 1e-12 * a.amax(), "{name}: A");
                }
            }
        }
    }
}

/// A free motion without friction: the links' energy plus the motors' 1/2 (R qd)' IA (R qd)
/// is conserved, and the simulation's energy column is that sum.
#[test]
fn simulation_conserves_energy_with_the_motors_inertia() {
    for seed in [21, 22] {
        let d = random_robot(seed, false);
        let robot = Robot::new(d.clone()).unwrap();
        let alone = links_alone(&d);
        let n = robot.dof();
        let [q0, qd0, _] = random_state(&mut rng(seed + 100), n);
        let opts = SimOptions {
            duration: 3.0,
            integrator: Integrator::Dopri5 {
                rtol: 1e-11,
                atol: 1e-11,
                h0: None,
                h_max: None,
            },
            output_dt: 0.05,
            max_steps: None,
        };
        let mut rec = Recorder::default();
        for method in Method::ALL {
            rec.rows.clear();
            let mut dynamics = TreeDynamics::new(&robot, method);
            let input = TorqueInput::Constant(vec![0.0; n]);
            simulate(
                &mut dynamics,
                &input,
                &q0,
                &qd0,
                &opts,
                &mut rec,
                &mut |_| {},
            )
            .unwrap();
            let reported = rec.series("energy").unwrap();
            let (mut energy, mut motors_max) = (Vec::new(), 0.0f64);
            for (row, e_sim) in rec.rows.iter().zip(&reported) {
                let (q, qd) = (&row[1..1 + n], &row[1 + n..1 + 2 * n]);
                let zero = vec![0.0; n];
                // 1/2 qd' (R^T IA R) qd from the drive torques of qdd = qd
                let motors = 0.5
                    * drive_torques(&d, &zero, qd)
                        .iter()
                        .zip(qd)
                        .map(|(a, b)| a * b)
                        .sum::<f64>();
                motors_max = motors_max.max(motors);
                let e = total_energy(&alone, q, qd).unwrap() + motors;
                assert!(
                    (e - e_sim).abs() < 1e-9 * e.abs().max(1.0),
                    "{e} vs {e_sim}"
                );
                energy.push(e);
            }
            let span = energy
                .iter()
                .fold(0.0f64, |m, e| m.max((e - energy[0]).abs()));
            let size = energy[0].abs().max(motors_max);
            eprintln!(
                "seed {seed} {method:?}: energy drift {:e}, motors' T up to {motors_max:e}",
                span / size
            );
            assert!(span < 1e-7 * size, "seed {seed} {method:?}: drift {span:e}");
            assert!(
                motors_max > 1e-2 * size,
                "the motors must carry energy: {motors_max:e}"
            );
        }
    }
}

/// What the models cannot apply yet is refused with a reason: a singular R, a floating base,
/// a closed chain with motors' parameters.
#[test]
fn unsupported_transmissions_are_refused() {
    let mut d = tx40();
    d.transmission.as_mut().unwrap().matrix[5] = vec![0.0, 0.0, 0.0, 0.0, 45.0, 0.0];
    let e = Robot::new(d).unwrap_err().to_string();
    assert!(e.contains("singular"), "{e}");
    let mut d = tx40();
    d.transmission.as_mut().unwrap().joints[5] = 5;
    let e = Robot::new(d).unwrap_err().to_string();
    assert!(e.contains("twice"), "{e}");
    // the SR400 (closed chain) with a transmission on its actuated joints and a motor inertia
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml");
    let mut d = robodyn::io::load_description(&path).unwrap();
    let joints = d.actuated_joints();
    let n = joints.len();
    let matrix = (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j)) * 20.0).collect())
        .collect();
    d.transmission = Some(Transmission { joints, matrix });
    d.links[0].params[param::IA] = Expr::num(1e-4);
    let robot = Robot::new(d).unwrap();
    let e = ClosedChain::new(&robot).unwrap_err().to_string();
    assert!(e.contains("transmission"), "{e}");
}

/// The models that do not apply transmissions yet refuse motors with drive parameters instead
/// of reading motor-unit IA, FS, FV as joint-side values (the links' numeric model has them at
/// zero once the robot carries its drives: reading it would give wrong numbers silently).
#[test]
fn models_without_transmissions_refuse_motor_drives() {
    use robodyn::algorithms::derivatives::{
        direct_dynamics_derivatives, inverse_dynamics_derivatives, RegressorDerivativesData,
    };
    use robodyn::codegen::{generate, Frames, GenOptions, ModelKind};
    let d = tx40();
    let robot = Robot::new(d.clone()).unwrap();
    let x = [0.1; 6];
    let errors = [
        inverse_dynamics_derivatives(&robot, &x, &x, &x).map(|_| ()),
        direct_dynamics_derivatives(&robot, &x, &x, &x).map(|_| ()),
        RegressorDerivativesData::new(&robot).map(|_| ()),
        d.require_no_motor_drive_parameters("base parameters"),
        generate(&d, &GenOptions::default()).map(|_| ()),
    ];
    for e in errors {
        let e = e.unwrap_err().to_string();
        assert!(e.contains("transmission"), "{e}");
    }
    // motors without parameters change nothing: the bundled TX40 is accepted everywhere
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/tx40.toml");
    let bundled = robodyn::io::load(&path).unwrap();
    inverse_dynamics_derivatives(&bundled, &x, &x, &x).unwrap();
    let plain = robodyn::io::load_description(&path).unwrap();
    plain
        .require_no_motor_drive_parameters("base parameters")
        .unwrap();
    // the geometric models do not read IA, FS, FV
    let frames = Frames {
        frame: Some(6),
        reference: Some(0),
    };
    let jacobian = GenOptions {
        model: ModelKind::Jacobian(frames),
        numeric: true,
        ..GenOptions::default()
    };
    generate(&d, &jacobian).unwrap();
}
