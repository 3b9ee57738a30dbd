//! `robodyn fk`, `jacobian` and `com` of a floating-base robot (the bundled RX-90 on a free base
//! body, `robots/rx90float.toml`): states of nq / nv values with the base first, from the command
//! line or a table with the base columns `simulate` writes. Checked against the library (the
//! numbers go through the CSV text), against the state itself (the base frame's placement is
//! the base pose of q), and, through the tables, against `simulate`'s own centre of mass and
//! linear momentum (the composite-link route of the centroidal momentum, another algorithm):
//! G of `com --input` is the simulation's com_x..z and M times its velocity the momentum.

mod common;

use common::process::robodyn_within;
use common::{csv, robot, run, tmp};
use robodyn::nalgebra::{DMatrix, UnitQuaternion, Vector3};
use robodyn::{KinematicsData, Reference};

fn floating() -> robodyn::Robot {
    robodyn::io::load(robot("rx90float.toml")).unwrap()
}

/// A deterministic state: q (13) with a unit quaternion, v and a (12).
fn state() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let f = |i: usize, s: f64| ((i * 7 + 5) as f64 * 0.37 + s).sin();
    let mut q: Vec<f64> = (0..13).map(|i| f(i, 0.1)).collect();
    let quat = UnitQuaternion::from_scaled_axis(Vector3::new(f(1, 0.5), f(2, 0.9), f(3, 1.3)));
    q[3..7].copy_from_slice(&[quat.i, quat.j, quat.k, quat.w]);
    let v = (0..12).map(|i| f(i, 0.7)).collect();
    let a = (0..12).map(|i| 2.0 * f(i, 1.9)).collect();
    (q, v, a)
}

/// CSV text whose first column is a label: the other columns' header and each row's numbers.
fn labelled(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let head = lines.next().unwrap().split(',').skip(1).map(String::from);
    let rows = lines
        .map(|l| l.split(',').skip(1).map(|x| x.parse().unwrap()).collect())
        .collect();
    (head.collect(), rows)
}

fn list(x: &[f64]) -> String {
    x.iter()
        .map(|v| format!("{v:e}"))
        .collect::<Vec<_>>()
        .join(",")
}

fn assert_close(ours: &[f64], reference: &[f64], tol: f64, what: &str) {
    let scale = reference.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    assert_eq!(ours.len(), reference.len(), "{what}");
    for (k, (a, b)) in ours.iter().zip(reference).enumerate() {
        assert!(
            (a - b).abs() <= tol * scale,
            "{what}[{k}]: {a} vs {b} (scale {scale})"
        );
    }
}

#[test]
fn fk_jacobian_com_of_one_floating_state_equal_the_library() {
    let r = floating();
    let rx = robot("rx90float.toml");
    let (q, v, a) = state();
    let (ql, vl, al) = (list(&q), list(&v), list(&a));
    let mut data = KinematicsData::new(&r);
    robodyn::forward_kinematics_into(&r, &mut data, &q, &v, &a).unwrap();
    // fk: the base frame "0" is at the base pose of q; frame 6 as the library computes it
    let out = run(&[
        "fk", &rx, "--q", &ql, "--qd", &vl, "--qdd", &al, "--frame", "0", "--frame", "6",
    ]);
    let (head, rows) = labelled(&out);
    assert_eq!(head[..6], ["x", "y", "z", "roll", "pitch", "yaw"]);
    let base = &rows[0];
    let quat =
        UnitQuaternion::from_quaternion(robodyn::nalgebra::Quaternion::new(q[6], q[3], q[4], q[5]));
    let (roll, pitch, yaw) = quat.euler_angles();
    assert_close(
        &base[..6],
        &[q[0], q[1], q[2], roll, pitch, yaw],
        1e-12,
        "base pose",
    );
    // the base's velocity in the world: R v_lin, R w
    let (lin, w) = (
        Vector3::new(v[0], v[1], v[2]),
        Vector3::new(v[3], v[4], v[5]),
    );
    let (vw, ww) = (quat * lin, quat * w);
    assert_close(
        &base[6..12],
        &[vw.x, vw.y, vw.z, ww.x, ww.y, ww.z],
        1e-12,
        "base velocity",
    );
    let f6 = r.frame_id("6").unwrap();
    let t = robodyn::frame_placement(&r, &data, &f6).unwrap();
    let lwa = Reference::LocalWorldAligned;
    let vel = robodyn::frame_velocity(&r, &data, &f6, lwa).unwrap();
    let acc = robodyn::frame_classical_acceleration(&r, &data, &f6, lwa).unwrap();
    let mut expected: Vec<f64> = t.pos.iter().copied().collect();
    expected.extend(robodyn::algorithms::kinematics::rpy(&t.rot));
    expected.extend(vel.to_vector().iter().chain(acc.to_vector().iter()));
    assert_close(&rows[1], &expected, 1e-12, "frame 6");
    // jacobian: 6 x nv, the base columns first, named as simulate names the velocities
    let out = run(&[
        "jacobian",
        &rx,
        "--q",
        &ql,
        "--frame",
        "6",
        "--reference",
        "local",
    ]);
    let (head, rows) = labelled(&out);
    let names: Vec<String> = r.velocity_names();
    assert_eq!(head, names);
    assert_eq!(&head[..6], robodyn::model::BASE_VELOCITY_NAMES);
    let mut j = DMatrix::zeros(6, 12);
    robodyn::frame_jacobian_into(&r, &data, &f6, Reference::Local, &mut j).unwrap();
    for (k, row) in rows.iter().enumerate() {
        let lib: Vec<f64> = j.row(k).iter().copied().collect();
        assert_close(row, &lib, 1e-12, &format!("J row {k}"));
    }
    // com: mass, G, its velocity and acceleration, the 3 x nv Jacobian
    let out = run(&[
        "com", &rx, "--q", &ql, "--qd", &vl, "--qdd", &al, "--format", "json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let g = robodyn::algorithms::kinematics::center_of_mass(&r, &mut data, None).unwrap();
    let got: Vec<f64> = ["mass", "x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"]
        .iter()
        .map(|k| json[k].as_f64().unwrap())
        .collect();
    let mut lib = vec![g.mass];
    lib.extend(g.position.iter().chain(&g.velocity).chain(&g.acceleration));
    assert_close(&got, &lib, 1e-12, "com");
    let total = robodyn::algorithms::kinematics::total_mass(&r);
    assert!(
        (g.mass - total).abs() < 1e-12 * total,
        "the base is weighed"
    );
    let out = run(&["com", &rx, "--q", &ql, "--jacobian", "--format", "json"]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["joints"].as_array().unwrap().len(), 12);
    let mut jg = DMatrix::zeros(3, 12);
    robodyn::algorithms::kinematics::center_of_mass_jacobian_into(&r, &mut data, None, &mut jg)
        .unwrap();
    for k in 0..3 {
        let row: Vec<f64> = json["J"][k]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let lib: Vec<f64> = jg.row(k).iter().copied().collect();
        assert_close(&row, &lib, 1e-12, &format!("Jcom row {k}"));
    }
}

#[test]
fn com_of_a_simulated_table_is_the_simulations_centre_of_mass() {
    let rx = robot("rx90float.toml");
    let sim = tmp("floating_kinematics", "sim.csv");
    run(&[
        "simulate",
        &rx,
        "--set",
        "G3=-9.81",
        "--duration",
        "0.5",
        "--output-step",
        "0.05",
        "--base-pose",
        "0.1,-0.2,1,0,0,0.3826834323650898,0.9238795325119139",
        "--base-twist",
        "0.2,0,0.1,0.5,-0.3,2",
        "--output",
        sim.to_str().unwrap(),
    ]);
    let (sh, srows) = csv(&std::fs::read_to_string(&sim).unwrap());
    let col = |name: &str| sh.iter().position(|h| h == name).unwrap();
    let out = run(&["com", &rx, "--input", sim.to_str().unwrap()]);
    let (head, rows) = csv(&out);
    assert_eq!(rows.len(), srows.len());
    let at = |name: &str| head.iter().position(|h| h == name).unwrap();
    let mass = rows[0][at("mass")];
    for (k, (row, s)) in rows.iter().zip(&srows).enumerate() {
        assert_eq!(row[at("row")] as usize, k + 1);
        let g: Vec<f64> = ["x", "y", "z"].iter().map(|c| row[at(c)]).collect();
        let sg: Vec<f64> = ["com_x", "com_y", "com_z"]
            .iter()
            .map(|c| s[col(c)])
            .collect();
        assert_close(&g, &sg, 1e-9, &format!("row {k}: G"));
        let p: Vec<f64> = ["vx", "vy", "vz"]
            .iter()
            .map(|c| mass * row[at(c)])
            .collect();
        let sp: Vec<f64> = ["momentum_x", "momentum_y", "momentum_z"]
            .iter()
            .map(|c| s[col(c)])
            .collect();
        assert_close(&p, &sp, 1e-9, &format!("row {k}: M vG"));
    }
    // fk and jacobian read the same table (base columns as simulate writes them)
    let out = run(&["fk", &rx, "--input", sim.to_str().unwrap(), "--frame", "0"]);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), srows.len() + 1, "{out}");
    let first: Vec<&str> = lines[1].split(',').collect();
    let x_at = lines[0].split(',').position(|h| h == "x").unwrap();
    let x: f64 = first[x_at].parse().unwrap();
    assert!((x - srows[0][col("base_x")]).abs() < 1e-12, "{x}");
    let out = run(&[
        "jacobian",
        &rx,
        "--input",
        sim.to_str().unwrap(),
        "--frame",
        "6",
    ]);
    assert!(out.lines().next().unwrap().contains("base_vx"), "{out}");
}

#[test]
fn floating_kinematics_commands_refuse_joint_only_states() {
    let rx = robot("rx90float.toml");
    let r = robodyn_within(&["fk", &rx, "--q", "0,0,0,0,0,0"], 60.0);
    r.assert_no_crash("floating fk");
    assert_eq!(r.code, Some(1), "{}", r.stdout);
    assert!(r.stderr.contains("nq = 7 + 6"), "{}", r.stderr);
    let r = robodyn_within(
        &[
            "jacobian",
            &rx,
            "--frame",
            "6",
            "--q",
            "0,0,0,0,0,0,2,0,0,0,0,0,0",
        ],
        60.0,
    );
    assert_eq!(r.code, Some(1), "{}", r.stdout);
    assert!(r.stderr.contains("quaternion"), "{}", r.stderr);
    // no --q: the base at the world origin, joints at zero (a valid state)
    let out = run(&["com", &rx]);
    assert!(out.starts_with("mass,"), "{out}");
}
