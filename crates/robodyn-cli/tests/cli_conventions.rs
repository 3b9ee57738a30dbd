//! The conventions of docs/cli.md, one test each: non-finite results refused, a closed pipe ends
//! quietly, `-` for standard input and output, `--set` checked and parsed as `--q`, `--input`
//! defaults and carried columns, `--set` of a standard parameter a file writes as a number, shortest round-trip numbers, units in `--help`, `simulate`
//! options checked before the output file is touched, the step limit named, joint limits
//! (URDF `<limit>`) shown and checked, the plot's content.

mod common;

use common::{csv, robot, run, tmp};
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Output, Stdio};

fn robodyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap()
}

/// Run with `stdin` as standard input.
fn robodyn_stdin(args: &[&str], stdin: &[u8]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    child.stdin.take().unwrap().write_all(stdin).unwrap();
    child.wait_with_output().unwrap()
}

/// Expect exit code 1 (no panic), nothing on standard output; return standard error.
fn fails(args: &[&str]) -> String {
    let out = robodyn(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "robodyn {args:?}: {err}");
    assert!(out.stdout.is_empty(), "robodyn {args:?} printed a result");
    err
}

#[test]
fn non_finite_torques_are_refused() {
    let rx90 = robot("rx90.toml");
    let e = fails(&[
        "idm",
        &rx90,
        "--q",
        "0,0,0,0,0,0",
        "--qd",
        "1e200,1e200,1e200,1e200,1e200,1e200",
    ]);
    assert!(e.contains("not a finite number"), "{e}");
    let e = fails(&["idm", &rx90, "--q", "0,1,1,0,0,0", "--set", "G3=-1e308"]);
    assert!(e.contains("not a finite number"), "{e}");
    // an infinite value is refused as a value
    let e = fails(&["idm", &rx90, "--q", "0,0,0,0,0,0", "--set", "G3=1e308*10"]);
    assert!(e.contains("infinite"), "{e}");
}

#[test]
fn closed_pipe_ends_quietly() {
    // more than a pipe buffer (64 KiB) of trajectory: the writes after the reader has gone fail
    let mut child = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args([
            "simulate",
            &robot("rx90.toml"),
            "--duration",
            "20",
            "--dt",
            "0.001",
        ])
        .args(["--output", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .unwrap();
    assert!(first.starts_with("t,q1,"), "{first}");
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        !err.contains("Broken pipe") && !err.contains("panicked"),
        "{err}"
    );
}

#[test]
fn dash_is_stdin_and_stdout() {
    let text = std::fs::read(robot("rx90.urdf")).unwrap();
    let from_stdin = robodyn_stdin(&["idm", "-", "--q", "0.1,0.2,0.3,0.4,0.5,0.6"], &text);
    assert!(
        from_stdin.status.success(),
        "{}",
        String::from_utf8_lossy(&from_stdin.stderr)
    );
    let from_file = run(&["idm", &robot("rx90.urdf"), "--q", "0.1,0.2,0.3,0.4,0.5,0.6"]);
    assert_eq!(String::from_utf8(from_stdin.stdout).unwrap(), from_file);
    // --output - is standard output, not a file named `-`
    let dir = tmp("conv", "dash");
    std::fs::create_dir_all(&dir).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args([
            "idm",
            &robot("rx90.urdf"),
            "--q",
            "0.1,0.2,0.3,0.4,0.5,0.6",
            "--output",
            "-",
        ])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(String::from_utf8(out.stdout).unwrap(), from_file);
    assert!(!dir.join("-").exists());
    // --input - reads the states from standard input
    let states = b"q1,q2,q3,q4,q5,q6\n0.1,0.2,0.3,0.4,0.5,0.6\n";
    let out = robodyn_stdin(&["idm", &robot("rx90.toml"), "--input", "-"], states);
    let by_list = run(&["idm", &robot("rx90.toml"), "--q", "0.1,0.2,0.3,0.4,0.5,0.6"]);
    assert_eq!(String::from_utf8(out.stdout).unwrap(), by_list);
}

#[test]
fn set_names_a_symbol_and_takes_expressions() {
    let rx90 = robot("rx90.toml");
    let q = ["--q", "0.1,0.2,0.3,0.4,0.5,0.6"];
    let e = fails(&["idm", &rx90, "--set", "d3=0.5", q[0], q[1]]);
    assert!(e.contains("no symbol `d3`") && e.contains("D3"), "{e}");
    let e = fails(&["idm", &rx90, "--set", "=1", q[0], q[1]]);
    assert!(e.contains("name is missing"), "{e}");
    // D3 = pi/8 and D3 = 0.39269908169872414 give the same torques
    let a = run(&["idm", &rx90, "--set", "D3=pi/8", q[0], q[1]]);
    let b = run(&["idm", &rx90, "--set", "D3=0.39269908169872414", q[0], q[1]]);
    assert_eq!(a, b);
    let c = run(&["idm", &rx90, q[0], q[1]]);
    assert_ne!(a, c, "--set D3 changed nothing");
}

#[test]
fn set_names_a_standard_parameter_a_file_writes_as_a_number() {
    // a URDF has no symbols: `M3` is link 3's mass, `FS2` joint 2's Coulomb friction
    let urdf = robot("rx90.urdf");
    let q = ["--q", "0.1,0.2,0.3,0.4,0.5,0.6", "--qd", "0,1,0,0,0,0"];
    let base = csv(&run(&["idm", &urdf, q[0], q[1], q[2], q[3]])).1[0].clone();
    let fs = csv(&run(&[
        "idm", &urdf, "--set", "FS2=0.5", q[0], q[1], q[2], q[3],
    ]))
    .1[0]
        .clone();
    for (k, (a, b)) in fs.iter().zip(&base).enumerate() {
        let expected = if k == 1 { 0.5 } else { 0.0 };
        assert!(
            (a - b - expected).abs() < 1e-12,
            "joint {}: {a} - {b}",
            k + 1
        );
    }
    let heavy = run(&["idm", &urdf, "--set", "M3=100", q[0], q[1]]);
    assert_ne!(
        heavy,
        run(&["idm", &urdf, q[0], q[1]]),
        "--set M3 changed nothing"
    );
    let e = fails(&["idm", &urdf, "--set", "M33=1", q[0], q[1]]);
    assert!(e.contains("no symbol `M33`") && e.contains("1..6"), "{e}");
}

#[test]
fn input_defaults_missing_columns_and_carried_columns() {
    let rx90 = robot("rx90.toml");
    // q only: qd = qdd = 0, as with --q alone; the t column comes through in front
    let p = tmp("conv", "q_only.csv");
    std::fs::write(&p, "t,q1,q2,q3,q4,q5,q6\n0.25,0.1,0.2,0.3,0.4,0.5,0.6\n").unwrap();
    let (h, rows) = csv(&run(&["idm", &rx90, "--input", p.to_str().unwrap()]));
    let (h2, rows2) = csv(&run(&["idm", &rx90, "--q", "0.1,0.2,0.3,0.4,0.5,0.6"]));
    assert_eq!(h[0], "t");
    assert_eq!(h[1..], h2[..]);
    assert_eq!(rows[0][0], 0.25);
    assert_eq!(rows[0][1..], rows2[0][..]);
    // some qd columns but not all: every missing column in one message
    let p = tmp("conv", "partial.csv");
    std::fs::write(&p, "q1,q2,q3,q4,q5,qd1\n0,0,0,0,0,0\n").unwrap();
    let e = fails(&["idm", &rx90, "--input", p.to_str().unwrap()]);
    for c in ["`q6`", "`qd2`", "`qd6`"] {
        assert!(e.contains(c), "{c} not reported: {e}");
    }
    // a repeated column is an error
    let p = tmp("conv", "twice.csv");
    std::fs::write(&p, "q1,q2,q3,q4,q5,q6,q1\n0,0,0,0,0,0,1\n").unwrap();
    let e = fails(&["idm", &rx90, "--input", p.to_str().unwrap()]);
    assert!(e.contains("q1"), "{e}");
}

#[test]
fn numbers_are_shortest_round_trip() {
    let rx90 = robot("rx90.toml");
    let p = tmp("conv", "states.csv");
    std::fs::write(
        &p,
        "q1,q2,q3,q4,q5,q6\n0,0,0,0,0,0\n0.1,0.2,0.3,0.4,0.5,0.6\n",
    )
    .unwrap();
    let phi = run(&["regressor", &rx90, "--input", p.to_str().unwrap()]);
    // no `1.000000000000e0`, no `-0`; every field reads back to what the library computes
    for field in phi.lines().skip(1).flat_map(|l| l.split(',')) {
        assert!(!field.ends_with("e0") && field != "-0", "{field}");
        let x: f64 = field.parse().unwrap();
        if x.fract() == 0.0 && x.abs() < 1e15 {
            assert!(
                !field.contains('.') && !field.contains('e'),
                "integer written {field}"
            );
        }
    }
    let tau = run(&["idm", &rx90, "--q", "0.1,0.2,0.3,0.4,0.5,0.6"]);
    let robot = robodyn::io::load(std::path::Path::new(&rx90)).unwrap();
    let n = robot.dof();
    let want = robodyn::inverse_dynamics(
        &robot,
        &[0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
        &vec![0.0; n],
        &vec![0.0; n],
    )
    .unwrap();
    let line = tau.lines().nth(1).unwrap();
    for (field, w) in line.split(',').zip(want.iter()) {
        // reads back to the library's value exactly, in no more digits than Rust's shortest forms
        assert_eq!(field.parse::<f64>().unwrap(), *w, "{field}");
        let shortest = format!("{w}").len().min(format!("{w:e}").len());
        assert!(field.len() <= shortest, "{field} is longer than {w}");
    }
    // info: the gravity as a number, not `-981/100`
    let info = run(&["info", &rx90]);
    assert!(!info.contains("981/100"), "{info}");
}

#[test]
fn help_states_units_and_models() {
    for cmd in ["idm", "ddm", "simulate", "info", "regressor", "inertia"] {
        let h = run(&[cmd, "--help"]);
        assert!(
            h.contains("N m") && h.contains("rad/s"),
            "{cmd} --help has no units:\n{h}"
        );
    }
    let h = run(&["generate", "--help"]);
    assert!(
        h.contains("w:") || h.contains(" w,") || h.contains(", w]"),
        "{h}"
    );
}

#[test]
fn simulate_checks_options_before_touching_the_output() {
    let out = tmp("conv", "kept.csv");
    std::fs::write(&out, "precious\n").unwrap();
    let o = out.to_str().unwrap();
    let rx90 = robot("rx90.toml");
    for bad in [
        &["--duration", "0"][..],
        &["--duration", "nan"],
        &["--duration", "inf"],
        &["--duration=-1"],
        &["--duration", "1", "--dt", "0"],
        &["--duration", "1", "--rtol", "0"],
        &["--duration", "1", "--max-steps", "0"],
    ] {
        let mut args = vec!["simulate", rx90.as_str(), "--output", o];
        args.extend_from_slice(bad);
        let e = fails(&args);
        assert!(e.contains("--"), "{bad:?}: {e}");
        assert!(
            !e.contains("kept there") && !e.contains("is in"),
            "{bad:?}: {e}"
        );
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "precious\n",
            "{bad:?}"
        );
    }
    // the step limit is named as what stopped the run
    let e = fails(&[
        "simulate",
        &rx90,
        "--duration",
        "1",
        "--max-steps",
        "3",
        "--output",
        o,
    ]);
    assert!(e.contains("max_steps = 3"), "{e}");
}

/// A two-joint URDF with limits: a revolute joint (position, speed, effort) and a prismatic joint
/// that falls through its lower limit under gravity.
const LIMITED: &str = r#"<robot name="limited">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="turn" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-1.5" upper="2" velocity="3" effort="40"/></joint>
  <joint name="lift" type="prismatic"><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/>
    <limit lower="-0.2" upper="0.3" velocity="0.5" effort="100"/></joint>
</robot>
"#;

#[test]
fn urdf_limits_are_shown_and_checked() {
    let p = tmp("conv", "limited.urdf");
    std::fs::write(&p, LIMITED).unwrap();
    let r = p.to_str().unwrap();
    let info = run(&["info", r]);
    assert!(info.contains("-1.5") && info.contains("40"), "{info}");
    assert!(info.contains("-0.2") && info.contains("0.3"), "{info}");
    // free fall of the prismatic joint: q2 = -g t^2 / 2 crosses -0.2 m at t = 0.2 s, speed 0.5
    // m/s at t = 0.051 s
    let out = tmp("conv", "fall.csv");
    let o = robodyn(&[
        "simulate",
        r,
        "--duration",
        "0.5",
        "--output",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert!(err.contains("joint 2 crosses its position limit"), "{err}");
    assert!(err.contains("joint 2 crosses its speed limit"), "{err}");
    assert!(err.contains("m outside [-0.2, 0.3]"), "{err}");
    let o = robodyn(&[
        "simulate",
        r,
        "--duration",
        "0.5",
        "--stop-at-limits",
        "--output",
        out.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("--stop-at-limits"), "{err}");
    // the speed limit (t ~ 0.051 s) stops it first
    let (_, rows) = csv(&std::fs::read_to_string(&out).unwrap());
    let t_end = rows.last().unwrap()[0];
    assert!((0.04..0.07).contains(&t_end), "stopped at {t_end}");
}

#[test]
fn simulate_plot_has_title_units_and_drift() {
    let p = tmp("conv", "limited2.urdf");
    std::fs::write(&p, LIMITED).unwrap();
    let out = tmp("conv", "plot.csv");
    let svg = tmp("conv", "plot.svg");
    run(&[
        "simulate",
        p.to_str().unwrap(),
        "--duration",
        "0.3",
        "--qd0",
        "1,0",
        "--output",
        out.to_str().unwrap(),
        "--plot",
        svg.to_str().unwrap(),
    ]);
    let s = std::fs::read_to_string(&svg).unwrap();
    for want in [
        "limited:", "q [rad]", "q [m]", "E - E(0)", "t [s]", "q1", "q2",
    ] {
        assert!(s.contains(want), "plot lacks `{want}`");
    }
}
