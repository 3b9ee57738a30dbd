//! `robodyn identify` on hostile or mistaken input (issue 24, items 2, 3, 5, 6, 8, 10; issue 30,
//! item 5): every command as a user types it, on a log the CLI itself simulates (the SCARA,
//! which has friction and rotor inertias, tracking a sum of sines), edited the way the mistake
//! happens. Each test failed before the fix: an abort, a panic, exit 0 with a wrong or silent
//! result, or a misleading error.

mod common;
use common::{robot, run, tmp};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;

fn robodyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap()
}

/// Run, assert a clean error exit (code 1: not a panic's 101 nor an abort's 134), return stderr.
fn refused(args: &[&str]) -> String {
    let out = robodyn(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "robodyn {args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    err
}

/// The SCARA's log: 6 s at 500 Hz of PD tracking of sines, with t, q, qd, qdd, tau (and the
/// simulator's energy column). Made once per test binary.
fn scara_log() -> &'static PathBuf {
    static LOG: OnceLock<PathBuf> = OnceLock::new();
    LOG.get_or_init(|| {
        let reference = tmp("identify_hostile", "reference.csv");
        let mut s = String::from("t,q1,q2,q3,q4\n");
        for k in 0..=600 {
            let t = k as f64 * 0.01;
            let q = [
                0.8 * (1.3 * t).sin() + 0.3 * (3.1 * t + 0.5).sin(),
                0.7 * (1.7 * t + 1.0).sin() + 0.2 * (4.3 * t).sin(),
                0.05 * (2.1 * t).sin() + 0.02 * (5.3 * t + 1.0).sin(),
                (2.3 * t + 2.0).sin() + 0.4 * (3.7 * t).sin(),
            ];
            s.push_str(&format!("{t},{},{},{},{}\n", q[0], q[1], q[2], q[3]));
        }
        std::fs::write(&reference, s).unwrap();
        let log = tmp("identify_hostile", "scara_log.csv");
        run(&[
            "simulate",
            &robot("scara.toml"),
            "--duration",
            "6",
            "--dt",
            "0.0005",
            "--output-step",
            "0.002",
            "--track",
            reference.to_str().unwrap(),
            "--kp",
            "400",
            "--kd",
            "40",
            "--coulomb-smoothing",
            "0",
            "--output",
            log.to_str().unwrap(),
        ]);
        log
    })
}

/// The log's header and rows (as text fields).
fn fields(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (head, rows)
}

/// Write an edited copy of the SCARA log: `edit(header, rows)` changes it in place.
fn edited(name: &str, edit: impl FnOnce(&mut Vec<String>, &mut Vec<Vec<String>>)) -> String {
    let (mut head, mut rows) = fields(scara_log());
    edit(&mut head, &mut rows);
    let mut s = head.join(",") + "\n";
    for r in &rows {
        s.push_str(&r.join(","));
        s.push('\n');
    }
    let path = tmp("identify_hostile", name);
    std::fs::write(&path, s).unwrap();
    path.to_str().unwrap().to_string()
}

fn column(head: &[String], name: &str) -> usize {
    head.iter().position(|h| h == name).unwrap()
}

/// The SCARA log with the columns `names` set to `value` on every row.
fn with_columns(file: &str, names: &[String], value: &str) -> String {
    edited(file, |head, rows| {
        let cols: Vec<usize> = names.iter().map(|n| column(head, n)).collect();
        for r in rows.iter_mut() {
            for &c in &cols {
                r[c] = value.into();
            }
        }
    })
}

/// The SCARA log with the sign of tau2 flipped (a torque channel wired the wrong way).
fn flipped_tau2(file: &str) -> String {
    edited(file, |head, rows| {
        let c = column(head, "tau2");
        for r in rows.iter_mut() {
            let v: f64 = r[c].parse().unwrap();
            r[c] = format!("{}", -v);
        }
    })
}

/// The SCARA log without its qd, qdd columns (positions and torques, as a robot logs them).
fn positions_only(file: &str) -> String {
    edited(file, |head, rows| {
        let keep: Vec<usize> = (0..head.len())
            .filter(|&c| !head[c].starts_with("qd"))
            .collect();
        *head = keep.iter().map(|&c| head[c].clone()).collect();
        for r in rows.iter_mut() {
            *r = keep.iter().map(|&c| r[c].clone()).collect();
        }
    })
}

/// `prefix<j>` for the SCARA's joints 1..4.
fn names(prefixes: &[&str]) -> Vec<String> {
    prefixes
        .iter()
        .flat_map(|p| (1..=4).map(move |j| format!("{p}{j}")))
        .collect()
}

fn json(args: &[&str]) -> serde_json::Value {
    let mut a = args.to_vec();
    a.extend(["--format", "json"]);
    serde_json::from_str(&run(&a)).unwrap()
}

fn value(v: &serde_json::Value, name: &str) -> f64 {
    v["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no parameter {name}"))["value"]
        .as_f64()
        .unwrap()
}

/// 24.2: a log whose second line is 2 GB of zeros (`truncate -s 2G` after a header) and
/// `/dev/zero` are refused with the line and the bound, quickly and without an abort (rc 134
/// before: the CSV reader grew one record until the allocation failed).
#[test]
fn huge_lines_are_refused_with_their_line_number() {
    let scara = robot("scara.toml");
    let path = tmp("identify_hostile", "two_gigabytes.csv");
    let header = b"t,q1,q2,q3,q4,tau1,tau2,tau3,tau4\n";
    let mut f = std::fs::File::create(&path).unwrap();
    f.write_all(header).unwrap();
    f.set_len(header.len() as u64 + (2u64 << 30)).unwrap(); // sparse: no disk used
    drop(f);
    let e = refused(&["identify", &scara, "--data", path.to_str().unwrap()]);
    assert!(
        e.contains("two_gigabytes.csv:2:") && e.contains("longer than 1048576 bytes"),
        "{e}"
    );
    std::fs::remove_file(&path).unwrap();
    let e = refused(&["identify", &scara, "--data", "/dev/zero"]);
    assert!(
        e.contains("/dev/zero:1:") && e.contains("longer than"),
        "{e}"
    );
}

/// 24.3: fewer gains than motors panicked in the observation pass; more were silently
/// truncated. Both are refused with the counts; one gain per motor works.
#[test]
fn gains_must_be_one_per_motor() {
    let scara = robot("scara.toml");
    let currents = edited("currents.csv", |head, _| {
        for h in head.iter_mut() {
            if let Some(j) = h.strip_prefix("tau") {
                *h = format!("i{j}");
            }
        }
    });
    for (gains, count) in [("1,2", 2), ("1,1,1,1,1", 5)] {
        let e = refused(&[
            "identify",
            &scara,
            "--data",
            &currents,
            "--estimator",
            "ols",
            "--gains",
            gains,
        ]);
        assert!(
            e.contains(&format!("--gains has {count} values for 4 motors")),
            "{e}"
        );
    }
    // unit gains on currents equal to the torques: the robot's parameters
    let v = json(&[
        "identify",
        &scara,
        "--data",
        &currents,
        "--estimator",
        "ols",
        "--gains",
        "1,1,1,1",
    ]);
    assert!((value(&v, "FV3") - 10.0).abs() < 1e-8, "{v}");
}

/// 24.5: gains with a log of torques (no current columns) scaled the torques silently (ZZR1
/// 39.5 instead of 1.25 on the log): refused.
#[test]
fn gains_without_currents_are_refused() {
    let e = refused(&[
        "identify",
        &robot("scara.toml"),
        "--data",
        scara_log().to_str().unwrap(),
        "--estimator",
        "ols",
        "--gains",
        "2,2,2,2",
    ]);
    assert!(
        e.contains("--gains given but the log has joint torques"),
        "{e}"
    );
}

/// 24.6: all torques zero gave "perfect fit", every parameter 0 +- 0, `inf` relative standard
/// deviations and exit 0 (even with --strict): an identification with nothing to fit is an
/// error, with OLS too.
#[test]
fn zero_torques_are_nothing_to_fit() {
    let scara = robot("scara.toml");
    let zero = with_columns("zero_torques.csv", &names(&["tau"]), "0");
    for extra in [&[][..], &["--strict"][..]] {
        let mut args = vec!["identify", &scara, "--data", &zero, "--estimator", "ols"];
        args.extend(extra);
        let e = refused(&args);
        assert!(e.contains("there is nothing to identify"), "{e}");
    }
}

/// 24.8: a torque channel of the wrong sign gives negative friction and rotor inertia with
/// exit 0 and no word: each physically impossible value is a warning naming the parameter and
/// why, in the text and the JSON report (and --strict fails on it).
#[test]
fn physically_impossible_values_are_warned_about() {
    let scara = robot("scara.toml");
    let flipped = flipped_tau2("flipped_tau2.csv");
    let args = ["identify", &scara, "--data", &flipped, "--estimator", "ols"];
    let v = json(&args);
    let impossible: Vec<&serde_json::Value> = v["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|w| w["kind"] == "physically_impossible")
        .collect();
    let named = |p: &str| impossible.iter().any(|w| w["parameters"][0] == p);
    for p in ["FS2", "FV2", "IA2"] {
        assert!(value(&v, p) < 0.0, "{p} {}", value(&v, p));
        assert!(named(p), "no warning on {p}: {:?}", v["warnings"]);
    }
    let fs2 = impossible
        .iter()
        .find(|w| w["parameters"][0] == "FS2")
        .unwrap();
    assert!(
        fs2["message"]
            .as_str()
            .unwrap()
            .contains("a Coulomb friction coefficient cannot be negative"),
        "{fs2}"
    );
    // the original log has none
    let clean = json(&[
        "identify",
        &scara,
        "--data",
        scara_log().to_str().unwrap(),
        "--estimator",
        "ols",
    ]);
    assert!(
        !clean["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .any(|w| w["kind"] == "physically_impossible"),
        "{:?}",
        clean["warnings"]
    );
    let text = run(&args);
    assert!(
        text.contains("FV2 = ")
            && text.contains("a viscous friction coefficient cannot be negative"),
        "{text}"
    );
    let mut strict = args.to_vec();
    strict.push("--strict");
    refused(&strict);
}

/// 24.10: Unix time stamps (t ~ 1.7e9 s at 5 kHz) were refused as "not sampled uniformly"
/// (their differences carry 2.4e-7 s of rounding): accepted, with the parameters of the same
/// log whose time starts at 0.
#[test]
fn unix_time_stamps_are_uniform() {
    let scara = robot("scara.toml");
    let stamped = |name: &str, t0: f64| {
        edited(name, |head, rows| {
            let c = column(head, "t");
            for (k, r) in rows.iter_mut().enumerate() {
                r[c] = format!("{:.4}", t0 + k as f64 * 0.0002);
            }
        })
    };
    let unix = stamped("unix_time.csv", 1.7e9);
    let zero = stamped("zero_time.csv", 0.0);
    let args = |data: &str| {
        json(&[
            "identify",
            &scara,
            "--data",
            data,
            "--estimator",
            "ols",
            "--validation",
            "none",
        ])
    };
    let (a, b) = (args(&unix), args(&zero));
    assert!((a["processing"]["sample_rate"].as_f64().unwrap() - 5000.0).abs() < 1e-3);
    for (p, q) in a["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .zip(b["parameters"].as_array().unwrap())
    {
        let (x, y) = (p["value"].as_f64().unwrap(), q["value"].as_f64().unwrap());
        assert!(
            (x - y).abs() <= 1e-9 * y.abs().max(1e-3),
            "{}: {x} vs {y}",
            p["name"]
        );
    }
}

/// 24.10: a torque of 1.797e308 was reported as "IA3 has no effect ... not excited": the
/// number is refused at its line and column.
#[test]
fn overflowing_numbers_are_named_at_their_line() {
    let huge = edited("huge_torque.csv", |head, rows| {
        let c = column(head, "tau3");
        rows[99][c] = "1.797e308".into();
    });
    let e = refused(&["identify", &robot("scara.toml"), "--data", &huge]);
    assert!(
        e.contains("huge_torque.csv:101: column `tau3`: 1.797e308 is too large"),
        "{e}"
    );
}

/// 24.10: `--data -` read a file named `-` (or, piped, the stream twice: "13 fields vs 4"):
/// standard input is read once, with the result of the same log from a file.
#[test]
fn data_from_standard_input() {
    let scara = robot("scara.toml");
    let log = scara_log();
    let mut child = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args([
            "identify",
            &scara,
            "--data",
            "-",
            "--estimator",
            "ols",
            "--format",
            "json",
        ])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let bytes = std::fs::read(log).unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // written in pieces from another thread, as a pipe delivers it
    let writer = std::thread::spawn(move || {
        for chunk in bytes.chunks(4096) {
            stdin.write_all(chunk).unwrap();
        }
    });
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let piped: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let file = json(&[
        "identify",
        &scara,
        "--data",
        log.to_str().unwrap(),
        "--estimator",
        "ols",
    ]);
    assert_eq!(piped["processing"]["source"], "<stdin>");
    assert_eq!(piped["processing"]["samples"], 3001);
    assert_eq!(piped["parameters"], file["parameters"]);
}

/// 24.10: options out of range were accepted silently (NaN) or blamed on the direct dynamic
/// model (`--iv-bandwidth 0`): each is refused as the option it is.
#[test]
fn bad_numeric_options_are_refused_by_name() {
    let scara = robot("scara.toml");
    let log = scara_log().to_str().unwrap().to_string();
    for (flag, value) in [
        ("--iv-bandwidth", "0"),
        ("--iv-bandwidth", "nan"),
        ("--min-speed", "nan"),
        ("--min-speed", "-1"),
        ("--essential-max-std", "nan"),
        ("--essential-tolerance", "nan"),
        ("--bandwidth", "inf"),
        ("--coulomb-band", "-1e-3"),
    ] {
        let given = format!("{flag}={value}");
        let out = robodyn(&[
            "identify",
            &scara,
            "--data",
            &log,
            "--estimator",
            "iv",
            "--essential",
            &given,
        ]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{flag} {value} accepted");
        assert!(
            err.contains(&format!("invalid value '{value}' for '{flag}")),
            "{flag} {value}: {err}"
        );
    }
}

/// 24.10: a log with the column q1 twice was used silently (state tables refuse it): refused
/// with both columns, as the state tables do.
#[test]
fn repeated_columns_are_refused() {
    let twice = edited("q1_twice.csv", |head, rows| {
        head.push("q1".into());
        for r in rows.iter_mut() {
            r.push("0.5".into());
        }
    });
    let e = refused(&["identify", &robot("scara.toml"), "--data", &twice]);
    assert!(
        e.contains("q1_twice.csv:1: column `q1` appears twice (columns 2 and 19)"),
        "{e}"
    );
}

/// `--differentiate` was ignored when the log had qd, qdd (the log's were used while the
/// report said "differentiated"): with the log's velocities wrong, differentiating the
/// positions gives the robot's parameters back.
#[test]
fn differentiate_replaces_the_logs_derivatives() {
    let scara = robot("scara.toml");
    let wrong = with_columns("wrong_qd.csv", &names(&["qd", "qdd"]), "0");
    let positions = positions_only("positions_for_differentiate.csv");
    let identify = |data: &str, extra: &[&str]| {
        let mut args = vec!["identify", &scara, "--data", data, "--estimator", "ols"];
        args.extend(extra);
        json(&args)
    };
    let v = identify(&wrong, &["--differentiate"]);
    assert_eq!(v["processing"]["derivatives_from_log"], false);
    assert_eq!(
        v["parameters"],
        identify(&positions, &[])["parameters"],
        "--differentiate did not replace the log's qd, qdd"
    );
}

/// 30.5: where the velocities are differentiated, the Coulomb sign has a dead band (3e-3 rad/s
/// or m/s by default), stated in the report (text and JSON) and settable; where the log gives
/// them, the exact sign.
#[test]
fn coulomb_dead_band_is_stated_and_settable() {
    let scara = robot("scara.toml");
    let positions = positions_only("positions_only.csv");
    let band = |v: &serde_json::Value| v["processing"]["coulomb_band"].as_f64().unwrap();
    let args = [
        "identify",
        &scara,
        "--data",
        &positions,
        "--estimator",
        "ols",
    ];
    assert_eq!(band(&json(&args)), 3e-3);
    let text = run(&args);
    assert!(text.contains("dead band, 0 where |qd| <= 0.003"), "{text}");
    let mut set = args.to_vec();
    set.extend(["--coulomb-band", "0.02"]);
    assert_eq!(band(&json(&set)), 0.02);
    let given = json(&[
        "identify",
        &scara,
        "--data",
        scara_log().to_str().unwrap(),
        "--estimator",
        "ols",
    ]);
    assert_eq!(band(&given), 0.0);
}

/// Warnings were printed twice (in the report on standard output and on standard error): once,
/// in the report when it goes to standard output, on standard error when it goes to a file.
#[test]
fn warnings_are_printed_once() {
    let scara = robot("scara.toml");
    let flipped = flipped_tau2("flipped_for_warnings.csv");
    // three warnings on FS2, FV2, IA2 (physically impossible)
    let out = robodyn(&["identify", &scara, "--data", &flipped, "--estimator", "ols"]);
    assert!(out.status.success());
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert_eq!(stdout.matches("FV2 = ").count(), 1, "{stdout}");
    assert!(!stderr.contains("FV2 = "), "{stderr}");
    let file = tmp("identify_hostile", "report.txt");
    let out = robodyn(&[
        "identify",
        &scara,
        "--data",
        &flipped,
        "--estimator",
        "ols",
        "--output",
        file.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    assert_eq!(
        String::from_utf8_lossy(&out.stderr)
            .matches("FV2 = ")
            .count(),
        1
    );
    assert_eq!(
        std::fs::read_to_string(&file)
            .unwrap()
            .matches("FV2 = ")
            .count(),
        1
    );
}

/// `excite` checked `--rate` and `--periods` after the design (minutes) and not the size of the
/// output at all (`--rate 1e12` wrote until the disk was full): both are checked first, with the
/// flags named; a period or rate that is not a positive number is refused by name.
#[test]
fn excite_checks_its_output_size_first() {
    let rx90 = robot("rx90.toml");
    let out = tmp("identify_hostile", "never.csv");
    let out_arg = out.to_str().unwrap();
    let excite = |extra: &[&str]| {
        let mut a = vec!["excite", &rx90, "--qd-max", "1", "--qdd-max", "5"];
        a.extend(["--output", out_arg, "--harmonics", "3"]);
        if !extra.contains(&"--period") {
            a.extend(["--period", "4"]);
        }
        a.extend(extra);
        robodyn(&a)
    };
    for (extra, message) in [
        (["--rate", "1e12"], "= 4e12 rows: at most 1e8"),
        (["--periods", "0"], "--periods must be at least 1"),
        (["--rate", "nan"], "invalid value 'nan' for '--rate"),
        (["--period", "0"], "invalid value '0' for '--period"),
    ] {
        let o = excite(&extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(
            !o.status.success() && err.contains(message),
            "{extra:?}: {err}"
        );
    }
    assert!(!out.exists());
}
