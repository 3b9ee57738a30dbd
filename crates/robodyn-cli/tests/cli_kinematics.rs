//! `fk`, `jacobian`, `com`, `ik` as a user runs them, each checked by another route through the
//! CLI itself: Jacobians against central differences of `fk`'s placements, the centre of mass's
//! Jacobian against differences of `com`, `fk`'s velocity against J q̇, `ik`'s solutions by `fk`
//! (a round trip), a closed chain's J_a along its branch; and the errors.

mod common;
use common::{robot, run};
use nalgebra::{DMatrix, Matrix3, Matrix4, Vector3};
use std::process::Command;

fn list(v: &[f64]) -> String {
    format!("--q={}", values(v))
}

/// Comma-separated values, every digit kept.
fn values(v: &[f64]) -> String {
    let s: Vec<String> = v.iter().map(|x| format!("{x:e}")).collect();
    s.join(",")
}

/// `fk --format json` of one frame: its 4x4 placement.
fn placement(file: &str, q: &[f64], frame: &str) -> Matrix4<f64> {
    let out = run(&["fk", file, &list(q), "--frame", frame, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let t = &v[0]["T"];
    Matrix4::from_fn(|i, j| t[i][j].as_f64().unwrap())
}

/// A CSV matrix whose first column labels the rows.
fn labelled(text: &str) -> (Vec<String>, DMatrix<f64>) {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let head: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .skip(1)
        .map(String::from)
        .collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').skip(1).map(|x| x.parse().unwrap()).collect())
        .collect();
    let m = DMatrix::from_fn(rows.len(), head.len(), |i, j| rows[i][j]);
    (head, m)
}

fn jacobian(file: &str, q: &[f64], frame: &str, reference: &str) -> DMatrix<f64> {
    labelled(&run(&[
        "jacobian",
        file,
        &list(q),
        "--frame",
        frame,
        "--reference",
        reference,
    ]))
    .1
}

/// Central differences of the placement: [linear velocity of the origin; angular velocity]
/// per unit joint rate, in R_0 (the local-world-aligned Jacobian).
fn differences(file: &str, q: &[f64], frame: &str) -> DMatrix<f64> {
    let h = 1e-6;
    let mut out = DMatrix::zeros(6, q.len());
    for k in 0..q.len() {
        let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
        qp[k] += h;
        qm[k] -= h;
        let (tp, tm) = (placement(file, &qp, frame), placement(file, &qm, frame));
        let dp = (tp.fixed_view::<3, 1>(0, 3) - tm.fixed_view::<3, 1>(0, 3)) / (2.0 * h);
        let r: Matrix3<f64> = placement(file, q, frame).fixed_view::<3, 3>(0, 0).into();
        let dr = (tp.fixed_view::<3, 3>(0, 0) - tm.fixed_view::<3, 3>(0, 0)) / (2.0 * h);
        let w = dr * r.transpose(); // [w]x
        let w = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
        out.fixed_view_mut::<3, 1>(0, k).copy_from(&dp);
        out.fixed_view_mut::<3, 1>(3, k).copy_from(&w);
    }
    out
}

// Truncation O(h^2) ~ 1e-12 and rounding of the printed 17 digits / h ~ 1e-10: 1e-7 is far
// above both, and far below a wrong column (entries of order 0.1 to 1).
const FD: f64 = 1e-7;

#[test]
fn jacobian_equals_differences_of_fk() {
    let q = [0.3, -0.7, 0.4, 1.1, -0.5, 0.9];
    for (file, frame) in [
        (robot("rx90.toml"), "6"),
        (robot("rx90.urdf"), "6"),
        (robot("tx40.toml"), "6"),
    ] {
        let j = jacobian(&file, &q, frame, "local_world_aligned");
        let d = differences(&file, &q, frame);
        assert!(
            (&j - &d).amax() < FD,
            "{file}: J - FD = {:e}",
            (&j - &d).amax()
        );
        // local = R^T blockwise of the local-world-aligned one
        let t = placement(&file, &q, frame);
        let r: Matrix3<f64> = t.fixed_view::<3, 3>(0, 0).into();
        let local = jacobian(&file, &q, frame, "local");
        for k in 0..q.len() {
            let l = r.transpose() * j.fixed_view::<3, 1>(0, k);
            let a = r.transpose() * j.fixed_view::<3, 1>(3, k);
            assert!((local.fixed_view::<3, 1>(0, k) - l).amax() < 1e-12);
            assert!((local.fixed_view::<3, 1>(3, k) - a).amax() < 1e-12);
        }
    }
}

#[test]
fn fk_velocity_is_j_times_qd() {
    let file = robot("rx90.toml");
    let (q, qd) = (
        [0.2, 0.5, -0.3, 0.8, 0.4, -1.0],
        [0.7, -0.2, 0.5, 1.3, -0.9, 0.4],
    );
    let qd_arg = format!("--qd={}", qd.map(|x| x.to_string()).join(","));
    let out = run(&["fk", &file, &list(&q), &qd_arg, "--frame", "6"]);
    let (head, m) = labelled(&out);
    let j = jacobian(&file, &q, "6", "local_world_aligned");
    let v = &j * nalgebra::DVector::from_column_slice(&qd);
    for (r, name) in ["vx", "vy", "vz", "wx", "wy", "wz"].iter().enumerate() {
        let c = head.iter().position(|h| h == name).unwrap();
        assert!(
            (m[(0, c)] - v[r]).abs() < 1e-12,
            "{name}: {} vs {}",
            m[(0, c)],
            v[r]
        );
    }
}

#[test]
fn com_jacobian_equals_differences_of_com() {
    let file = robot("rx90.toml");
    let q = [0.3, -0.7, 0.4, 1.1, -0.5, 0.9];
    let com = |q: &[f64]| -> Vector3<f64> {
        let (head, rows) = common::csv(&run(&["com", &file, &list(q)]));
        assert_eq!(head[..4], ["mass", "x", "y", "z"]);
        Vector3::new(rows[0][1], rows[0][2], rows[0][3])
    };
    let out = run(&["com", &file, &list(&q), "--jacobian"]);
    let jtext = out.split("\n\n").nth(1).unwrap();
    let (_, j) = labelled(jtext);
    let h = 1e-6;
    for k in 0..q.len() {
        let (mut qp, mut qm) = (q.to_vec(), q.to_vec());
        qp[k] += h;
        qm[k] -= h;
        let d = (com(&qp) - com(&qm)) / (2.0 * h);
        assert!((j.fixed_view::<3, 1>(0, k) - d).amax() < FD, "column {k}");
    }
}

#[test]
fn ik_solutions_reproduce_the_pose_and_contain_the_start() {
    for file in [robot("rx90.toml"), robot("tx40.toml")] {
        let q = [0.3, -0.7, 0.4, 1.1, -0.5, 0.9];
        let t = placement(&file, &q, "6");
        let pose: Vec<String> = t.transpose().iter().map(|x| format!("{x:e}")).collect();
        let out = run(&[
            "ik",
            &file,
            "--frame",
            "6",
            &format!("--pose={}", pose.join(",")),
        ]);
        let mut lines = out.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(&head[6..], ["within_limits", "singular"]);
        let sols: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').take(6).map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(sols.len(), 8, "{file}: a generic pose has 8 solutions");
        for s in &sols {
            let e = (placement(&file, s, "6") - t).amax();
            assert!(e < 1e-10, "{file}: solution {s:?} misses the pose by {e:e}");
        }
        let wrap = |x: f64| (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU);
        assert!(
            sols.iter().any(|s| s.iter().zip(&q).all(|(a, b)| {
                let d = (wrap(*a) - wrap(*b)).abs();
                d.min(std::f64::consts::TAU - d) < 1e-9
            })),
            "{file}: the start q is not among the solutions"
        );
    }
}

#[test]
fn closed_chain_jacobian_follows_the_branch() {
    // SR400: J_a = J_tr G against differences of fk along q_a (fk completes q_p on the branch)
    let file = robot("sr400.toml");
    let q = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6];
    let j = jacobian(&file, &q, "6", "local_world_aligned");
    assert_eq!(j.shape(), (6, 6));
    let d = differences(&file, &q, "6");
    assert!((&j - &d).amax() < FD, "J_a - FD = {:e}", (&j - &d).amax());
}

fn fails(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "robodyn {args:?}: {err}");
    assert!(out.stdout.is_empty(), "nothing on stdout on failure");
    err
}

#[test]
fn kinematic_commands_refuse_bad_input() {
    let rx90 = robot("rx90.urdf");
    let e = fails(&["fk", &rx90, "--frame", "elbw"]);
    assert!(e.contains("elbw") && e.contains("elbow"), "{e}");
    let e = fails(&["jacobian", &rx90, "--frame", "6", "--q=1,2"]);
    assert!(e.contains('q') && e.contains('6') && e.contains('2'), "{e}");
    let e = fails(&["com", &rx90, "--q=1,2,3,4,5,nan"]);
    assert!(
        e.to_lowercase().contains("nan") || e.contains("finite"),
        "{e}"
    );
    let e = fails(&["ik", &rx90, "--pose=1,2,3"]);
    assert!(e.contains("--pose has 3 numbers"), "{e}");
    let e = fails(&["ik", &rx90, "--pose=1,0,0,0, 0,2,0,0, 0,0,1,0, 0,0,0,1"]);
    assert!(e.contains("rotation") || e.contains("orthonormal"), "{e}");
    let e = fails(&["ik", &robot("scara.toml"), "--pose=0.5,0,0,0,0,0"]);
    assert!(e.contains("numeric") || e.contains("class"), "{e}");
}

/// `--input` state tables: every row of `fk`, `jacobian` and `com --jacobian` equals the same
/// command on that row's state given with --q/--qd (the state-table path against the
/// single-state one, itself checked against differences above); the table's other columns are
/// carried; a table without q columns is refused.
#[test]
fn state_tables_equal_the_single_states() {
    let rx90 = robot("rx90.urdf");
    let states = [
        [0.1, -0.4, 0.9, 0.3, -0.7, 1.2],
        [-1.0, 0.5, 0.2, -0.6, 1.1, 0.0],
        [0.7, 0.2, -1.3, 1.4, 0.4, -0.9],
    ];
    let qd = [0.3, -0.2, 0.5, 0.1, -0.4, 0.6];
    let file = common::tmp("kin_table", "states.csv");
    let mut text = String::from("t,q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6\n");
    for (i, q) in states.iter().enumerate() {
        let v: Vec<String> = q.iter().chain(&qd).map(|x| format!("{x:e}")).collect();
        text += &format!("{},{}\n", i as f64 * 0.01, v.join(","));
    }
    std::fs::write(&file, text).unwrap();
    let input = file.to_str().unwrap();
    let qd_arg = format!("--qd={}", &list(&qd)[4..]);
    let nums = |line: &str, skip: usize| -> Vec<f64> {
        line.split(',')
            .skip(skip)
            .map(|x| x.parse().unwrap())
            .collect()
    };
    let close = |a: &[f64], b: &[f64], what: &str| {
        assert_eq!(a.len(), b.len(), "{what}");
        for (x, y) in a.iter().zip(b) {
            assert!(
                (x - y).abs() <= 1e-12 * y.abs().max(1.0),
                "{what}: {a:?} vs {b:?}"
            );
        }
    };
    // fk: t, row, frame, then the single state's columns
    let table = run(&[
        "fk", &rx90, "--input", input, "--frame", "link6", "--frame", "elbow",
    ]);
    let lines: Vec<&str> = table.lines().collect();
    assert!(
        lines[0].starts_with("t,row,frame,x,y,z,roll,pitch,yaw,vx"),
        "{}",
        lines[0]
    );
    assert_eq!(lines.len(), 1 + 2 * states.len());
    for (i, q) in states.iter().enumerate() {
        for (k, frame) in ["link6", "elbow"].iter().enumerate() {
            let line = lines[1 + 2 * i + k];
            assert!(line.contains(&format!(",{},{frame},", i + 1)), "{line}");
            let one = run(&["fk", &rx90, &list(q), &qd_arg, "--frame", frame]);
            let expected = nums(one.lines().nth(1).unwrap(), 1);
            close(
                &nums(line, 3),
                &expected,
                &format!("fk row {} {frame}", i + 1),
            );
        }
    }
    // jacobian: six lines per state
    let table = run(&["jacobian", &rx90, "--input", input, "--frame", "link6"]);
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 1 + 6 * states.len());
    for (i, q) in states.iter().enumerate() {
        let one = jacobian(&rx90, q, "link6", "local_world_aligned");
        for r in 0..6 {
            let got = nums(lines[1 + 6 * i + r], 3);
            let expected: Vec<f64> = one.row(r).iter().copied().collect();
            close(&got, &expected, &format!("J row {} line {r}", i + 1));
        }
    }
    // com --jacobian: one line per state, J's rows after the centre of mass
    let table = run(&["com", &rx90, "--input", input, "--jacobian"]);
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 1 + states.len());
    for (i, q) in states.iter().enumerate() {
        let one = run(&["com", &rx90, &list(q), &qd_arg, "--jacobian"]);
        let mut expected = nums(one.lines().nth(1).unwrap(), 0);
        for l in one.lines().skip(4) {
            expected.extend(nums(l, 1));
        }
        close(
            &nums(lines[1 + i], 2),
            &expected,
            &format!("com row {}", i + 1),
        );
    }
    // no q columns: refused with the file named
    let bad = common::tmp("kin_table", "bad.csv");
    std::fs::write(&bad, "t,x\n0,1\n").unwrap();
    let e = fails(&["fk", &rx90, "--input", bad.to_str().unwrap()]);
    assert!(e.contains("bad.csv") && e.contains("q1"), "{e}");
    let e = fails(&[
        "jacobian", &rx90, "--input", input, "--frame", "6", "--format", "json",
    ]);
    assert!(e.contains("--input"), "{e}");
}

/// `jacobian --time-variation` is J̇: central differences of the CLI's own J along the motion,
/// (J(q + h qd) - J(q - h qd)) / 2h, in the three references (fixed base); a closed chain is
/// refused with the reason.
#[test]
fn jacobian_time_variation_equals_differences_of_j() {
    let file = robot("rx90.urdf");
    let q = [0.3, -0.7, 0.5, 1.1, -0.4, 0.9];
    let qd = [0.8, -0.5, 1.2, -0.9, 0.6, 1.4];
    let h = 1e-5;
    for reference in ["world", "local", "local_world_aligned"] {
        let dj = labelled(&run(&[
            "jacobian",
            &file,
            &list(&q),
            &format!("--qd={}", values(&qd)),
            "--frame",
            "6",
            "--reference",
            reference,
            "--time-variation",
        ]))
        .1;
        let at = |s: f64| {
            let x: Vec<f64> = q.iter().zip(&qd).map(|(a, b)| a + s * h * b).collect();
            jacobian(&file, &x, "6", reference)
        };
        let fd = (at(1.0) - at(-1.0)) / (2.0 * h);
        assert_eq!(dj.shape(), (6, 6));
        let gap = (&dj - &fd).amax();
        assert!(
            gap < 1e-7 * fd.amax().max(1.0),
            "{reference}: dJ - FD = {gap:e}"
        );
        assert!(dj.amax() > 0.1, "{reference}: dJ is not zero here");
    }
    let e = fails(&[
        "jacobian",
        &robot("sr400.toml"),
        "--q=0.1,0.2,0.3,0.4,0.5,0.6",
        "--frame",
        "6",
        "--time-variation",
    ]);
    assert!(e.contains("closed chain") && e.contains("drift"), "{e}");
}
