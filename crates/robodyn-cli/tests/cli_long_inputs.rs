//! Inputs too large for memory (issue 24 item 2, the CLI's tables): a line of 2 GB or an endless
//! one (`/dev/zero`) is an error naming its line, not an abort (exit code 134); `regressor` streams
//! its rows, so a table of hundreds of thousands of states needs no more memory than a few.

mod common;

use common::process::{robodyn_in_shell, robodyn_within, Run};
use common::robot;
use std::io::Write;
use std::path::PathBuf;

const LIMIT: f64 = 60.0;

fn dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("robodyn_long_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn refused(r: &Run, line: &str) {
    r.assert_no_crash("robodyn");
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(
        r.stderr.contains(line) && r.stderr.contains("longer than"),
        "{}",
        r.stderr
    );
}

/// A header, then a line of 2 GB (a sparse file: zeros) in every reader of a table; `/dev/zero`
/// as a table (one endless line); standard input too.
#[test]
fn endless_lines_are_errors_with_their_line() {
    let rx90 = robot("rx90.toml");
    // sparse files: a header, then 2 GB of zeros
    let big = |name: &str, header: &str| -> PathBuf {
        let p = dir().join(name);
        let mut f = std::fs::File::create(&p).unwrap();
        f.write_all(header.as_bytes()).unwrap();
        f.set_len(2 << 30).unwrap();
        p
    };
    let states = big("states.csv", "t,q1,q2,q3,q4,q5,q6\n");
    let torques = big("torques.csv", "t,tau1,tau2,tau3,tau4,tau5,tau6\n");
    let (b, bt) = (states.to_str().unwrap(), torques.to_str().unwrap());
    let out = dir().join("out.csv");
    let o = out.to_str().unwrap();
    let sim = ["simulate", &rx90, "--duration", "0.01", "--output", o];
    let cases: Vec<Vec<&str>> = vec![
        vec!["idm", &rx90, "--input", b],
        vec!["ddm", &rx90, "--input", b],
        vec!["regressor", &rx90, "--input", b],
        [&sim[..], &["--torque-csv", bt]].concat(),
        [&sim[..], &["--track", b, "--kp", "1", "--kd", "1"]].concat(),
    ];
    for args in &cases {
        let file = if args.contains(&bt) { bt } else { b };
        refused(&robodyn_within(args, LIMIT), &format!("{file}:2:"));
        let zero = args
            .iter()
            .map(|a| if *a == file { "/dev/zero" } else { a })
            .collect::<Vec<_>>();
        refused(&robodyn_within(&zero, LIMIT), "/dev/zero:1:");
    }
    let r = robodyn_in_shell("exec < /dev/zero", &["idm", &rx90, "--input", "-"], LIMIT);
    refused(&r, "<stdin>:1:");
    std::fs::remove_file(&states).unwrap();
    std::fs::remove_file(&torques).unwrap();
}

/// An endless robot file or grouping list is refused after a bounded read (64 and 16 MiB),
/// naming the file, where it was read until memory ran out (here, under a 1 GB limit so the
/// machine stays safe: "out of memory").
#[test]
fn endless_robot_files_are_refused() {
    let rx90 = robot("rx90.toml");
    for (args, file) in [
        (vec!["info", "/dev/zero"], "/dev/zero"),
        (
            vec![
                "generate",
                &rx90,
                "--params",
                "base",
                "--base-file",
                "/dev/zero",
            ],
            "/dev/zero",
        ),
    ] {
        let r = robodyn_in_shell("ulimit -v 1000000", &args, LIMIT);
        refused(&r, &format!("{file}: longer than"));
    }
    let r = robodyn_in_shell("ulimit -v 1000000; exec < /dev/zero", &["info", "-"], LIMIT);
    refused(&r, "<stdin>: longer than");
}

/// `regressor --input` of 150,000 states under a 400 MB address-space limit: it streams (24 MB;
/// the rows of Phi of every state in memory at once needed about 570 MB, and the allocation
/// failure aborted). Its rows equal those of the same states one at a time.
#[test]
fn regressor_streams_a_long_table() {
    let scara = robot("scara.toml");
    let d = dir();
    let input = d.join("long.csv");
    let states = 150_000;
    {
        let mut f = std::io::BufWriter::new(std::fs::File::create(&input).unwrap());
        writeln!(f, "q1,q2,q3,q4,qd1,qd2,qd3,qd4").unwrap();
        for k in 0..states {
            let x = k as f64 * 1e-5;
            writeln!(f, "{x},{},0.1,{},1,-1,0.5,{x}", -x, 2.0 * x).unwrap();
        }
    }
    let output = d.join("phi.csv");
    let (i, o) = (input.to_str().unwrap(), output.to_str().unwrap());
    let r = robodyn_in_shell(
        "ulimit -v 400000",
        &["regressor", &scara, "--input", i, "--output", o],
        LIMIT,
    );
    r.assert_no_crash("regressor");
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    // 4 joints per state, a header
    let text = std::fs::read_to_string(&output).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 1 + 4 * states);
    // the first and the last state alone
    for k in [0, states - 1] {
        let x = k as f64 * 1e-5;
        let one = d.join("one.csv");
        std::fs::write(
            &one,
            format!(
                "q1,q2,q3,q4,qd1,qd2,qd3,qd4\n{x},{},0.1,{},1,-1,0.5,{x}\n",
                -x,
                2.0 * x
            ),
        )
        .unwrap();
        let alone = robodyn_within(
            &["regressor", &scara, "--input", one.to_str().unwrap()],
            LIMIT,
        );
        for (j, line) in alone.stdout.lines().skip(1).enumerate() {
            // the state number differs: 1 alone, k + 1 in the long table
            let (want, got) = (line.split_once(',').unwrap().1, lines[1 + 4 * k + j]);
            assert_eq!(got.split_once(',').unwrap().1, want, "state {}", k + 1);
            assert_eq!(got.split_once(',').unwrap().0, (k + 1).to_string());
        }
    }
    std::fs::remove_file(&input).unwrap();
    std::fs::remove_file(&output).unwrap();
}
