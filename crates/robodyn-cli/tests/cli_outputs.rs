//! Outputs all or nothing (issue 24 items 11-14): every file a command writes goes to a
//! temporary file in its directory and replaces the target only when the command succeeds. A
//! failing run leaves the previous file byte for byte; two writers leave one whole file; two
//! outputs naming one file are refused before anything is written.

mod common;

use common::process::{robodyn_in_shell, robodyn_within, Run};
use common::robot;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const LIMIT: f64 = 60.0;
const PREVIOUS: &str = "the previous file\n";

/// A fresh directory for one test.
fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("robodyn_outputs_{tag}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The run failed cleanly (exit code 1, an error naming `names`).
fn failed(r: &Run, names: &[&str]) {
    r.assert_no_crash("robodyn");
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    for n in names {
        assert!(r.stderr.contains(n), "`{n}` not in: {}", r.stderr);
    }
}

/// The directory holds exactly `files` (no temporary file left behind).
fn only(d: &Path, files: &[&str]) {
    let mut got: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    got.sort();
    let mut want: Vec<String> = files.iter().map(|f| f.to_string()).collect();
    want.sort();
    assert_eq!(got, want, "in {}", d.display());
}

/// `simulate --output o.csv --plot /nonexistent/p.svg`: refused before the run, o.csv kept.
#[test]
fn plot_in_a_missing_directory_keeps_the_output() {
    let d = dir("plotdir");
    let o = d.join("o.csv");
    std::fs::write(&o, PREVIOUS).unwrap();
    let plot = d.join("missing").join("p.svg");
    let rx90 = robot("rx90.toml");
    let args = [
        "simulate",
        &rx90,
        "--duration",
        "0.05",
        "--output",
        s(&o),
        "--plot",
        s(&plot),
    ];
    failed(&robodyn_within(&args, LIMIT), &[s(&plot)]);
    assert_eq!(std::fs::read_to_string(&o).unwrap(), PREVIOUS);
    only(&d, &["o.csv"]);
}

/// A run failing at t = 0 (a gravity that overflows the model) replaced the output by a header
/// before; a table whose last row overflows wrote the rows before it.
#[test]
fn a_failing_run_leaves_the_previous_file() {
    let d = dir("failing");
    let o = d.join("o.csv");
    let rx90 = robot("rx90.toml");
    std::fs::write(&o, PREVIOUS).unwrap();
    let args = [
        "simulate",
        &rx90,
        "--set",
        "G3=1e308",
        "--duration",
        "0.05",
        "--output",
        s(&o),
    ];
    failed(&robodyn_within(&args, LIMIT), &[]);
    assert_eq!(std::fs::read_to_string(&o).unwrap(), PREVIOUS);
    // idm, ddm, regressor on a table whose second row overflows
    let input = d.join("states.csv");
    let mut table = String::from("q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6\n");
    table += "0.1,0.2,0.3,0.4,0.5,0.6,1,1,1,1,1,1\n";
    table += "0.1,0.2,0.3,0.4,0.5,0.6,1e200,1,1,1,1,1\n";
    std::fs::write(&input, table).unwrap();
    for cmd in ["idm", "ddm", "regressor"] {
        let r = robodyn_within(
            &[cmd, &rx90, "--input", s(&input), "--output", s(&o)],
            LIMIT,
        );
        failed(&r, &["row 2"]);
        assert_eq!(std::fs::read_to_string(&o).unwrap(), PREVIOUS, "{cmd}");
    }
    // identify's report with a plot it cannot write
    only(&d, &["o.csv", "states.csv"]);
}

/// A full disk (here a file-size limit: the write fails with EFBIG) leaves the previous file and
/// no temporary file.
#[test]
fn a_full_disk_leaves_the_previous_file() {
    let d = dir("full");
    let o = d.join("o.csv");
    std::fs::write(&o, PREVIOUS).unwrap();
    let rx90 = robot("rx90.toml");
    // 64 kB at most (ulimit -f counts 512-byte blocks); the signal ignored, so write() fails
    let r = robodyn_in_shell(
        "trap '' XFSZ; ulimit -f 128",
        &[
            "simulate",
            &rx90,
            "--duration",
            "5",
            "--dt",
            "0.001",
            "--output",
            s(&o),
        ],
        LIMIT,
    );
    failed(&r, &[s(&o)]);
    assert_eq!(std::fs::read_to_string(&o).unwrap(), PREVIOUS);
    only(&d, &["o.csv"]);
}

/// Two outputs naming one file, however spelt, are refused before anything is written.
#[test]
fn two_outputs_on_one_file_are_refused() {
    let d = dir("same");
    std::fs::create_dir_all(d.join("sub")).unwrap();
    let x = d.join("x.csv");
    std::fs::write(&x, PREVIOUS).unwrap();
    let link = d.join("link.svg");
    std::os::unix::fs::symlink(&x, &link).unwrap();
    let rx90 = robot("rx90.toml");
    let other = d.join("sub").join("..").join("x.csv");
    let new = d.join("new.csv");
    let new_again = d.join("sub").join("..").join("new.csv");
    for (output, plot) in [(&x, &x), (&x, &other), (&x, &link), (&new, &new_again)] {
        let args = [
            "simulate",
            &rx90,
            "--duration",
            "0.05",
            "--output",
            s(output),
            "--plot",
            s(plot),
        ];
        failed(
            &robodyn_within(&args, LIMIT),
            &["same file", "nothing was written"],
        );
        assert_eq!(std::fs::read_to_string(&x).unwrap(), PREVIOUS);
        assert!(!new.exists());
    }
    let args = [
        "excite",
        &robot("tx40.toml"),
        "--period",
        "2",
        "--harmonics",
        "2",
    ];
    let r = robodyn_within(
        &[&args[..], &["--output", s(&x), "--plot", s(&other)]].concat(),
        LIMIT,
    );
    failed(&r, &["same file"]);
    let args = [
        "identify",
        &robot("rx90.toml"),
        "--data",
        s(&x),
        "--output",
        s(&new),
        "--plot",
        s(&new_again),
    ];
    failed(&robodyn_within(&args, LIMIT), &["same file"]);
    assert_eq!(std::fs::read_to_string(&x).unwrap(), PREVIOUS);
    only(&d, &["x.csv", "link.svg", "sub"]);
}

/// The regressor's and the simulation's outputs of two processes writing one file at the same
/// time: the file is whole, equal to one of the two runs' own outputs (before, rows of both
/// were mixed).
#[test]
fn two_writers_leave_one_whole_file() {
    let d = dir("writers");
    let rx90 = robot("rx90.toml");
    let states = |k: usize| -> PathBuf {
        let p = d.join(format!("states{k}.csv"));
        let mut t = String::from("q1,q2,q3,q4,q5,q6\n");
        for r in 0..3000 {
            let x = (r * (k + 1)) as f64 * 1e-3;
            t += &format!("{x},{},0.3,0.4,0.5,0.6\n", x / 2.0);
        }
        std::fs::write(&p, t).unwrap();
        p
    };
    let (s1, s2) = (states(1), states(2));
    let target = d.join("out.csv");
    let cases: Vec<[Vec<String>; 2]> = vec![
        [1, 2].map(|k| {
            let input = if k == 1 { &s1 } else { &s2 };
            ["regressor", &rx90, "--input", s(input)]
                .map(String::from)
                .to_vec()
        }),
        [1, 2].map(|k| {
            let duration = if k == 1 { "0.8" } else { "0.9" };
            ["simulate", &rx90, "--duration", duration, "--dt", "0.001"]
                .map(String::from)
                .to_vec()
        }),
    ];
    for runs in cases {
        // each run's own output, written alone
        let alone: Vec<Vec<u8>> = runs
            .iter()
            .enumerate()
            .map(|(k, args)| {
                let f = d.join(format!("alone{k}.csv"));
                let mut a: Vec<&str> = args.iter().map(String::as_str).collect();
                a.extend(["--output", s(&f)]);
                assert_eq!(robodyn_within(&a, LIMIT).code, Some(0));
                std::fs::read(&f).unwrap()
            })
            .collect();
        assert_ne!(alone[0], alone[1]);
        for trial in 0..4 {
            let children: Vec<std::process::Child> = runs
                .iter()
                .map(|args| {
                    Command::new(env!("CARGO_BIN_EXE_robodyn"))
                        .args(args)
                        .args(["--output", s(&target)])
                        .stdin(Stdio::null())
                        .stdout(Stdio::null())
                        .stderr(Stdio::null())
                        .spawn()
                        .unwrap()
                })
                .collect();
            for mut c in children {
                assert!(c.wait().unwrap().success());
            }
            let got = std::fs::read(&target).unwrap();
            assert!(
                got == alone[0] || got == alone[1],
                "{:?} trial {trial}: a mixture of the two runs ({} bytes)",
                runs[0][0],
                got.len()
            );
        }
    }
    only(
        &d,
        &[
            "states1.csv",
            "states2.csv",
            "out.csv",
            "alone0.csv",
            "alone1.csv",
        ],
    );
}

/// A new output gets the usual permissions (0666 less the umask, not a temporary file's 0600);
/// a replaced one keeps its own; a symbolic link stays a link to the new content; a device
/// (`/dev/null`) is written, never replaced.
#[test]
fn outputs_keep_permissions_links_and_devices() {
    use std::os::unix::fs::PermissionsExt;
    let d = dir("modes");
    let rx90 = robot("rx90.toml");
    let new = d.join("new.csv");
    let r = robodyn_in_shell(
        "umask 022",
        &["idm", &rx90, "--q=0,0,0,0,0,0", "--output", s(&new)],
        LIMIT,
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode(&new), 0o644);
    std::fs::set_permissions(&new, std::fs::Permissions::from_mode(0o640)).unwrap();
    let r = robodyn_within(
        &["idm", &rx90, "--q=1,0,0,0,0,0", "--output", s(&new)],
        LIMIT,
    );
    assert_eq!(r.code, Some(0));
    assert_eq!(mode(&new), 0o640);
    let link = d.join("link.csv");
    std::os::unix::fs::symlink(&new, &link).unwrap();
    let r = robodyn_within(
        &["idm", &rx90, "--q=2,0,0,0,0,0", "--output", s(&link)],
        LIMIT,
    );
    assert_eq!(r.code, Some(0));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let direct = robodyn_within(&["idm", &rx90, "--q=2,0,0,0,0,0"], LIMIT).stdout;
    assert_eq!(std::fs::read_to_string(&new).unwrap(), direct);
    let r = robodyn_within(
        &["idm", &rx90, "--q=2,0,0,0,0,0", "--output", "/dev/null"],
        LIMIT,
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    use std::os::unix::fs::FileTypeExt;
    assert!(std::fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    only(&d, &["new.csv", "link.csv"]);
}

/// Every command that writes a file writes it whole: convert, generate, base-params
/// --write-robot, inertia, closure-free commands with --output (a new file appears only on
/// success; a failing one leaves no file behind).
#[test]
fn every_file_output_appears_whole_or_not_at_all() {
    let d = dir("every");
    let rx90 = robot("rx90.toml");
    let f = |n: &str| d.join(n);
    let runs: Vec<(Vec<String>, PathBuf)> = vec![
        (
            vec!["convert".into(), rx90.clone(), s(&f("a.par")).into()],
            f("a.par"),
        ),
        (
            ["generate", &rx90, "--lang", "c", "--output", s(&f("g.c"))]
                .map(String::from)
                .to_vec(),
            f("g.c"),
        ),
        (
            ["base-params", &rx90, "--write-robot", s(&f("b.toml"))]
                .map(String::from)
                .to_vec(),
            f("b.toml"),
        ),
        (
            ["inertia", &rx90, "--output", s(&f("i.csv"))]
                .map(String::from)
                .to_vec(),
            f("i.csv"),
        ),
    ];
    for (args, file) in &runs {
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let r = robodyn_within(&a, LIMIT);
        assert_eq!(r.code, Some(0), "{a:?}: {}", r.stderr);
        assert!(std::fs::metadata(file).unwrap().len() > 0, "{a:?}");
    }
    // base-params --write-robot to a format it cannot write: an error before the report, no
    // file
    let r = robodyn_within(
        &["base-params", &rx90, "--write-robot", s(&f("c.urdf"))],
        LIMIT,
    );
    failed(&r, &["URDF"]);
    assert!(r.stdout.is_empty(), "{}", r.stdout);
    assert!(!f("c.urdf").exists());
    // generate with a model the robot does not have: no file
    let r = robodyn_within(
        &["generate", &rx90, "--model", "w", "--output", s(&f("w.c"))],
        LIMIT,
    );
    failed(&r, &[]);
    only(&d, &["a.par", "g.c", "b.toml", "i.csv"]);
}
