//! Joint-side drive parameters next to a transmission's motors (issue 31, item 5): the TX40's
//! wrist, motor 6 turning with q5 + q6 (m = R q). A noise-free log of the links' dynamics
//! (`simulated_log`, Newton-Euler) plus drive torques computed here by hand, the motors'
//! R^T (Ia R qdd + Fv R qd + Fs sign(R qd)) and joint 6's own IA qdd6 + FV qd6 + FS sign(qd6)
//! on the joint side: ordinary least squares give back the joint-side values (IAJ6, FSJ6,
//! FVJ6) and the motors', and explain the torques (4.6e-8 relative: the simulation's rounding); without the joint-side parameters
//! the same log is not explained.

use robodyn::identification::data::MemoryLog;
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::{identify, Estimator, Options};
use robodyn::io::load_description;
use std::path::PathBuf;

const MOTOR: [(f64, f64, f64); 6] = [
    (3e-5, 0.2, 8e-3),
    (3e-5, 0.25, 5e-3),
    (5e-5, 0.12, 1e-3),
    (1.2e-5, 0.04, 5e-4),
    (1.8e-5, 0.06, 6e-4),
    (9e-6, 0.07, 6e-4),
];
/// Joint 6's joint-side IA, FS, FV.
const JOINT6: (f64, f64, f64) = (2e-3, 0.15, 0.05);

fn tx40_log() -> (ModelAccess, MemoryLog) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/tx40.toml");
    let mut desc = load_description(&path).unwrap();
    // the file's link 6 has no inertia about its axis: the direct dynamics of the simulation
    // needs some (XX, YY, ZZ of link 6)
    for i in [0, 3, 5] {
        desc.links[5].params[i] = robodyn::Expr::num(1e-3);
    }
    let acc = ModelAccess::new(desc).unwrap();
    let r = acc.transmission().unwrap().matrix.clone();
    let n = 6;
    let free: Vec<f64> = (0..n * 8)
        .map(|k| 0.8 * ((k * 37 % 19) as f64 / 9.0 - 1.0))
        .collect();
    let tr = FourierTrajectory::from_free(4.0, &[0.0, -0.5, 1.0, 0.0, 0.6, 0.0], 5, &free);
    let mut log = simulated_log(&acc, &tr, 8.0, 0.004, 5.0).unwrap();
    let dot = |row: &[f64], v: &[f64]| row.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
    for s in &mut log.samples {
        let (qd, qdd) = (s.qd.clone().unwrap(), s.qdd.clone().unwrap());
        for (m, row) in r.iter().enumerate() {
            let (ia, fs, fv) = MOTOR[m];
            let (md, mdd) = (dot(row, &qd), dot(row, &qdd));
            let tau_m = ia * mdd + fv * md + fs * md.signum() * f64::from(u8::from(md != 0.0));
            for (j, y) in s.y.iter_mut().enumerate() {
                *y += row[j] * tau_m;
            }
        }
        let (ia, fs, fv) = JOINT6;
        s.y[5] += ia * qdd[5] + fv * qd[5] + fs * qd[5].signum();
    }
    (acc, log)
}

#[test]
fn joint_side_drive_parameters_of_the_coupled_wrist() {
    let (mut acc, log) = tx40_log();
    let opt = Options {
        estimator: Estimator::Ols,
        validation: None,
        ..Options::default()
    };
    let id = identify(&mut acc, &log, &opt).unwrap();
    let value = |name: &str| {
        let k = id.parameters.iter().position(|p| p.name == name);
        id.x[k.unwrap_or_else(|| panic!("{name} in {:?}", id.model.names()))]
    };
    eprintln!(
        "with joint-side parameters: relative error {:e}",
        id.relative_error
    );
    assert!(id.relative_error < 1e-6, "{}", id.relative_error);
    // joint 6's own, and no other joint's (a motor's column spans joints 1..5's)
    let joint_side: Vec<String> = id
        .parameters
        .iter()
        .filter(|p| p.name.contains('J'))
        .map(|p| p.name.clone())
        .collect();
    assert_eq!(joint_side, ["IAJ6", "FSJ6", "FVJ6"]);
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-4 * b.abs();
    for (name, truth) in [("IAJ6", JOINT6.0), ("FSJ6", JOINT6.1), ("FVJ6", JOINT6.2)] {
        assert!(
            close(value(name), truth),
            "{name} {} vs {truth}",
            value(name)
        );
    }
    for (m, &(ia, fs, fv)) in MOTOR.iter().enumerate().skip(2) {
        for (name, truth) in [("IA", ia), ("FS", fs), ("FV", fv)] {
            let name = format!("{name}{}", m + 1);
            assert!(
                close(value(&name), truth),
                "{name} {} vs {truth}",
                value(&name)
            );
        }
    }
    // the motors' parameters alone do not explain joint 6's own friction and inertia
    let mut without = opt.clone();
    without.parameters.joint_drives = false;
    let id = identify(&mut acc, &log, &without).unwrap();
    eprintln!("motors only: relative error {:e}", id.relative_error);
    assert!(id.relative_error > 1e-4, "{}", id.relative_error);
}
