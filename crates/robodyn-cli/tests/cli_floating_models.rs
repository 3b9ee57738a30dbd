//! `robodyn idm`, `ddm` and `inertia` of a floating-base robot (the bundled RX-90 on a free base
//! body, `robots/rx90float.toml`, with gravity): states of nq / nv values with the base first,
//! from the command line or a table whose base columns are named as `simulate` writes them, and
//! nv results named likewise. Checked against the library row by row (the numbers go through
//! the CSV text), against the hand-derived free fall (at rest under no force every body falls
//! with g: ddm gives the base acceleration R' g and idm of it is zero) and by the round trip
//! ddm(idm(a)) = a through the tables; the commands that do not support floating bases refuse
//! them by name.

mod common;

use common::process::robodyn_within;
use common::{csv, robot, run, tmp};
use robodyn::nalgebra::{UnitQuaternion, Vector3};

const GRAVITY: &str = "G3=-9.81";

fn floating() -> robodyn::Robot {
    let values = [("G3".to_string(), -9.81)].into_iter().collect();
    robodyn::io::load_with(robot("rx90float.toml"), &values).unwrap()
}

/// Deterministic states: q (13) with a unit quaternion, v and a (12).
fn state(k: usize) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let f = |i: usize, s: f64| ((i * 7 + k * 13) as f64 * 0.37 + s).sin();
    let mut q: Vec<f64> = (0..13).map(|i| f(i, 0.1)).collect();
    let quat = UnitQuaternion::from_scaled_axis(Vector3::new(f(1, 0.5), f(2, 0.9), f(3, 1.3)));
    q[3..7].copy_from_slice(&[quat.i, quat.j, quat.k, quat.w]);
    let v = (0..12).map(|i| f(i, 0.7)).collect();
    let a = (0..12).map(|i| 2.0 * f(i, 1.9)).collect();
    (q, v, a)
}

fn list(x: &[f64]) -> String {
    x.iter()
        .map(|v| format!("{v:e}"))
        .collect::<Vec<_>>()
        .join(",")
}

fn assert_close(ours: &[f64], reference: &[f64], what: &str) {
    let scale = reference.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    assert_eq!(ours.len(), reference.len(), "{what}");
    for (k, (a, b)) in ours.iter().zip(reference).enumerate() {
        assert!(
            (a - b).abs() <= 1e-12 * scale,
            "{what}[{k}]: {a} vs {b} (scale {scale})"
        );
    }
}

const BASE_TAU: [&str; 6] = [
    "base_fx", "base_fy", "base_fz", "base_mx", "base_my", "base_mz",
];
const BASE_QDD: [&str; 6] = [
    "base_ax", "base_ay", "base_az", "base_dwx", "base_dwy", "base_dwz",
];

#[test]
fn one_state_from_the_command_line_equals_the_library() {
    let r = floating();
    let rx = robot("rx90float.toml");
    let (q, v, a) = state(1);
    let out = run(&[
        "idm",
        &rx,
        "--set",
        GRAVITY,
        "--q",
        &list(&q),
        "--qd",
        &list(&v),
        "--qdd",
        &list(&a),
    ]);
    let (head, rows) = csv(&out);
    let joints: Vec<String> = (1..=6).map(|j| format!("tau{j}")).collect();
    assert_eq!(head[..6], BASE_TAU);
    assert_eq!(head[6..], joints[..]);
    let tau = robodyn::inverse_dynamics(&r, &q, &v, &a).unwrap();
    assert!(tau.as_slice()[..6].iter().any(|x| x.abs() > 1.0));
    assert_close(&rows[0], tau.as_slice(), "idm");

    let t: Vec<f64> = (0..12).map(|k| (k as f64 - 5.0) * 0.8).collect();
    for method in ["composite", "aba"] {
        let out = run(&[
            "ddm",
            &rx,
            "--set",
            GRAVITY,
            "--q",
            &list(&q),
            "--qd",
            &list(&v),
            "--tau",
            &list(&t),
            "--method",
            method,
        ]);
        let (head, rows) = csv(&out);
        assert_eq!(head[..6], BASE_QDD);
        let m = robodyn::Method::from_name(method).unwrap();
        let qdd = robodyn::direct_dynamics(&r, &q, &v, &t, m).unwrap();
        assert_close(&rows[0], qdd.as_slice(), method);
    }

    let out = run(&["inertia", &rx, "--q", &list(&q)]);
    let (head, rows) = csv(&out);
    assert_eq!(
        head,
        [
            "base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz", "1", "2", "3", "4",
            "5", "6"
        ]
    );
    let m = robodyn::inertia_matrix(&r, &q).unwrap();
    assert_eq!(rows.len(), 12);
    for (i, row) in rows.iter().enumerate() {
        let reference: Vec<f64> = m.row(i).iter().copied().collect();
        assert_close(row, &reference, &format!("A row {i}"));
    }
}

#[test]
fn free_fall_by_hand() {
    let rx = robot("rx90float.toml");
    let (mut q, _, _) = state(2);
    let rot =
        UnitQuaternion::from_quaternion(robodyn::nalgebra::Quaternion::new(q[6], q[3], q[4], q[5]));
    let g = rot.inverse() * Vector3::new(0.0, 0.0, -9.81);
    q[0..3].copy_from_slice(&[1.0, -2.0, 3.0]);
    // at rest, no force: the base accelerates with g (in its frame), the joints not at all
    let out = run(&["ddm", &rx, "--set", GRAVITY, "--q", &list(&q)]);
    let (_, rows) = csv(&out);
    let mut expected = vec![0.0; 12];
    expected[..3].copy_from_slice(g.as_slice());
    for (k, (a, b)) in rows[0].iter().zip(&expected).enumerate() {
        assert!((a - b).abs() < 1e-12, "qdd[{k}] = {a}, expected {b}");
    }
    // that acceleration needs no wrench and no torque
    let out = run(&[
        "idm",
        &rx,
        "--set",
        GRAVITY,
        "--q",
        &list(&q),
        "--qdd",
        &list(&expected),
    ]);
    let (_, rows) = csv(&out);
    assert!(
        rows[0].iter().all(|x| x.abs() < 1e-10),
        "free fall needs no force: {:?}",
        rows[0]
    );
    // held still, the base carries the whole weight: 20 kg base + 33 kg arm (the file)
    let out = run(&["idm", &rx, "--set", GRAVITY, "--q", &list(&q)]);
    let (_, rows) = csv(&out);
    let f = Vector3::new(rows[0][0], rows[0][1], rows[0][2]);
    assert!((f.norm() - 53.0 * 9.81).abs() < 1e-9, "{}", f.norm());
}

/// A table of states with the base columns as `simulate` names them.
fn states_table(rows: usize) -> String {
    let mut text = String::from(
        "t,base_x,base_y,base_z,base_qx,base_qy,base_qz,base_qw,q1,q2,q3,q4,q5,q6,\
         base_vx,base_vy,base_vz,base_wx,base_wy,base_wz,qd1,qd2,qd3,qd4,qd5,qd6,\
         base_ax,base_ay,base_az,base_dwx,base_dwy,base_dwz,qdd1,qdd2,qdd3,qdd4,qdd5,qdd6\n",
    );
    for k in 0..rows {
        let (q, v, a) = state(10 + k);
        text += &format!(
            "{},{},{},{}\n",
            k as f64 * 0.01,
            list(&q),
            list(&v),
            list(&a)
        );
    }
    text
}

#[test]
fn tables_equal_the_library_and_ddm_undoes_idm() {
    let r = floating();
    let rx = robot("rx90float.toml");
    let input = tmp("floating_models", "states.csv");
    std::fs::write(&input, states_table(5)).unwrap();
    let out = run(&[
        "idm",
        &rx,
        "--set",
        GRAVITY,
        "--input",
        input.to_str().unwrap(),
    ]);
    let (head, rows) = csv(&out);
    assert_eq!(head[0], "t");
    assert_eq!(head[1..7], BASE_TAU);
    assert_eq!(rows.len(), 5);
    for (k, row) in rows.iter().enumerate() {
        let (q, v, a) = state(10 + k);
        let tau = robodyn::inverse_dynamics(&r, &q, &v, &a).unwrap();
        assert_close(&row[1..], tau.as_slice(), &format!("idm row {k}"));
    }
    // ddm on the states with those forces gives the accelerations back
    let (_, states) = csv(&states_table(5));
    let mut text = String::from(
        "t,base_x,base_y,base_z,base_qx,base_qy,base_qz,base_qw,q1,q2,q3,q4,q5,q6,\
         base_vx,base_vy,base_vz,base_wx,base_wy,base_wz,qd1,qd2,qd3,qd4,qd5,qd6,",
    );
    text += &head[1..].join(",");
    text.push('\n');
    for (s, row) in states.iter().zip(&rows) {
        text += &format!("{},{}\n", list(&s[..26]), list(&row[1..]));
    }
    let forces = tmp("floating_models", "forces.csv");
    std::fs::write(&forces, text).unwrap();
    for method in ["composite", "aba"] {
        let out = run(&[
            "ddm",
            &rx,
            "--set",
            GRAVITY,
            "--input",
            forces.to_str().unwrap(),
            "--method",
            method,
        ]);
        let (head, back) = csv(&out);
        assert_eq!(head[1..7], BASE_QDD);
        for (k, row) in back.iter().enumerate() {
            let (_, _, a) = state(10 + k);
            for (i, (x, y)) in row[1..].iter().zip(&a).enumerate() {
                assert!(
                    (x - y).abs() < 1e-9,
                    "{method} row {k} qdd[{i}]: {x} vs {y}"
                );
            }
        }
    }
}

#[test]
fn wrong_states_and_other_commands_are_refused_clearly() {
    let rx = robot("rx90float.toml");
    let fail = |args: &[&str]| -> String {
        let r = robodyn_within(args, 60.0);
        r.assert_no_crash("floating refusal");
        assert_eq!(r.code, Some(1), "{args:?} should fail: {}", r.stdout);
        r.stderr
    };
    // joint values only: the base entries are asked for, by name
    let e = fail(&["idm", &rx, "--q", "0,0,0,0,0,0"]);
    assert!(
        e.contains("7 base entries") && e.contains("base_qw") && e.contains("13 values"),
        "{e}"
    );
    let e = fail(&[
        "ddm",
        &rx,
        "--q",
        "0,0,0,0,0,0,1,0,0,0,0,0,0",
        "--qd",
        "0,0,0,0,0,0",
    ]);
    assert!(
        e.contains("--qd has 6 values") && e.contains("12 values"),
        "{e}"
    );
    // a quaternion that is not unit
    let e = fail(&["idm", &rx, "--q", "0,0,0,0,0,0,2,0,0,0,0,0,0"]);
    assert!(e.contains("quaternion"), "{e}");
    // a table without the base columns names them
    let input = tmp("floating_models", "joints_only.csv");
    std::fs::write(&input, "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n").unwrap();
    let e = fail(&["idm", &rx, "--input", input.to_str().unwrap()]);
    assert!(e.contains("base_qw"), "{e}");
    let e = fail(&["inertia", &rx]);
    assert!(e.contains("give --q") && e.contains("quaternion"), "{e}");
    // commands without floating support say so (never a fixed-base answer)
    for args in [
        vec![
            "ik",
            rx.as_str(),
            "--frame",
            "6",
            "--pose",
            "0.2,0,0.5,0,0,0",
        ],
        vec!["generate", rx.as_str(), "--model", "inertia"],
    ] {
        let e = fail(&args);
        assert!(e.contains("floating base"), "{args:?}: {e}");
    }
}

/// `--floating` makes a URDF's root link the floating base: with the base held still (zero base
/// velocity and acceleration, identity pose) the joint rows of `idm` are the fixed-base torques
/// of the same URDF (a different recursion: the fixed base's), and at rest the base's force is
/// the weight of the whole robot (the masses read from the file's text); `--floating` on a file whose base does not float is refused.
#[test]
fn urdf_made_floating_from_the_command_line() {
    let urdf = robot("rx90.urdf");
    let q = [0.1, -0.4, 0.3, 0.8, -0.5, 0.6];
    let qd = [0.3, -0.2, 0.5, 0.1, 0.4, -0.6];
    let qdd = [0.2, 0.1, -0.3, 0.5, -0.4, 0.7];
    let fixed = csv(&run(&[
        "idm",
        &urdf,
        "--q",
        &list(&q),
        "--qd",
        &list(&qd),
        "--qdd",
        &list(&qdd),
    ]));
    let base_q = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let qf: Vec<f64> = base_q.iter().chain(&q).copied().collect();
    let vf: Vec<f64> = [0.0; 6].iter().chain(&qd).copied().collect();
    let af: Vec<f64> = [0.0; 6].iter().chain(&qdd).copied().collect();
    let (head, rows) = csv(&run(&[
        "idm",
        &urdf,
        "--floating",
        "--q",
        &list(&qf),
        "--qd",
        &list(&vf),
        "--qdd",
        &list(&af),
    ]));
    assert_eq!(head.len(), 12, "{head:?}");
    assert_eq!(head[0], "base_fx");
    assert_close(&rows[0][6..], &fixed.1[0], "joint rows of the held base");
    // the weight of every link, the base's own included, along z: the masses read from the
    // file's text, gravity from the fixed robot
    let text = std::fs::read_to_string(&urdf).unwrap();
    let mass: f64 = text
        .split("<mass value=\"")
        .skip(1)
        .map(|s| s[..s.find('"').unwrap()].parse::<f64>().unwrap())
        .sum();
    let g = -robodyn::io::load(&urdf).unwrap().environment().gravity.z;
    assert!(g > 0.0 && mass > 0.0, "gravity {g}, mass {mass}");
    // at rest the base carries the weight only
    let zeros = list(&[0.0; 12]);
    let (_, rest) = csv(&run(&[
        "idm",
        &urdf,
        "--floating",
        "--q",
        &list(&qf),
        "--qd",
        &zeros,
        "--qdd",
        &zeros,
    ]));
    let f = &rest[0][..3];
    assert!(
        f[0].abs() + f[1].abs() <= 1e-9 * mass * g && (f[2] - mass * g).abs() <= 1e-9 * mass * g,
        "base force {f:?} at rest against M g = {}",
        mass * g
    );
    let e = robodyn_within(
        &[
            "idm",
            &robot("rx90.toml"),
            "--floating",
            "--q",
            "0,0,0,0,0,0",
        ],
        30.0,
    );
    assert!(
        e.code != Some(0) && e.stderr.contains("floating base is asked for"),
        "{}",
        e.stderr
    );
}

/// `info --floating` shows a URDF's root link as the floating base (link 0, its mass from the
/// file), as the model commands load it; without the flag the base is fixed; on a .toml file
/// whose base is fixed the flag is refused as the model commands refuse it.
#[test]
fn info_shows_the_floating_base_of_a_urdf() {
    let urdf = robot("rx90.urdf");
    let fixed = run(&["info", &urdf]);
    assert!(fixed.contains("base: fixed"), "{fixed}");
    let text = run(&["info", &urdf, "--floating"]);
    let line = text.lines().find(|l| l.starts_with("base: ")).unwrap();
    assert!(line.starts_with("base: floating (link 0 `"), "{line}");
    let json = run(&["info", &urdf, "--floating", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["base"], "floating", "{json}");
    let e = robodyn_within(&["info", &robot("rx90.toml"), "--floating"], 30.0);
    assert!(
        e.code != Some(0) && e.stderr.contains("floating base is asked for"),
        "{}",
        e.stderr
    );
}
