//! A seeded random harness over the command line (issue 24, "Done means"): the commands run on
//! bundled robots with random combinations of options and values, hostile numbers among them
//! (nan, inf, 1e308, -0, empty, 1e-320, huge counts, lists of the wrong length, a trailing comma).
//! Every run must end within a time bound, without a panic (exit code 101, "panicked") or an abort
//! (134, a signal), and exit 0 only with finite numbers in what it wrote. The seed and the failing
//! command line are in the message; `ROBODYN_HARNESS_SEED` and `ROBODYN_HARNESS_RUNS` change them.

mod common;

use common::process::robodyn_within;
use common::robot;
use std::path::{Path, PathBuf};

/// A run may take this long (the slowest legitimate runs here take well under a second).
const LIMIT: f64 = 20.0;

/// SplitMix64: a small seeded generator (the test needs no more).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
    fn pick<'a>(&mut self, v: &[&'a str]) -> &'a str {
        v[self.below(v.len())]
    }
    fn chance(&mut self, percent: u64) -> bool {
        self.next() % 100 < percent
    }
}

/// Numbers a user (or an attacker) may type.
const HOSTILE: [&str; 24] = [
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "pi/3",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e300",
    "1e-320",
    "1e309",
    "",
    "abc",
    "1e6",
    "-7.5e5",
    "1e17",
    "2*pi",
    "1/0",
    "0x10",
    "99999999999",
];

/// Counts and positive options.
const COUNTS: [&str; 10] = [
    "0",
    "1",
    "3",
    "-1",
    "1e3",
    "",
    "nan",
    "18446744073709551615",
    "18446744073709551616",
    "2.5",
];

/// (robot file, joints of its state vectors, closed)
const ROBOTS: [(&str, usize, bool); 8] = [
    ("rx90.toml", 6, false),
    ("rx90.par", 6, false),
    ("rx90.urdf", 6, false),
    ("scara.toml", 4, false),
    ("torso2arms.toml", 0, false),
    ("sr400.toml", 6, true),
    ("fourbar.toml", 1, true),
    ("fivebar.toml", 2, true),
];

/// A list of about `n` values: usually plausible, sometimes hostile, sometimes the wrong length.
fn list(rng: &mut Rng, n: usize) -> String {
    let len = match rng.below(10) {
        0 => n + 1,
        1 => n.saturating_sub(1),
        _ => n,
    };
    let mut v: Vec<String> = (0..len)
        .map(|k| {
            if rng.chance(8) {
                rng.pick(&HOSTILE).to_string()
            } else {
                format!(
                    "{}",
                    0.1 * (k as f64 + 1.0) * if rng.chance(50) { 1.0 } else { -1.0 }
                )
            }
        })
        .collect();
    if rng.chance(5) {
        v.push(String::new()); // a trailing comma
    }
    v.join(",")
}

/// A state table of `n` joints with a few rows, sometimes hostile (a value, a column).
fn state_table(rng: &mut Rng, dir: &Path, n: usize, third: &str, k: usize) -> PathBuf {
    let p = dir.join(format!("states{k}.csv"));
    let mut head: Vec<String> = Vec::new();
    for prefix in ["q", "qd", third] {
        head.extend((1..=n).map(|j| format!("{prefix}{j}")));
    }
    if rng.chance(20) {
        head.push(rng.pick(&["t", "label", "qdd_1", "tau1", "Q1"]).to_string());
    }
    let mut text = head.join(",") + "\n";
    for r in 0..1 + rng.below(4) {
        let row: Vec<String> = (0..head.len())
            .map(|c| {
                if rng.chance(5) {
                    rng.pick(&HOSTILE).to_string()
                } else {
                    format!("{}", 0.01 * (r * 7 + c) as f64)
                }
            })
            .collect();
        text += &(row.join(",") + "\n");
    }
    std::fs::write(&p, text).unwrap();
    p
}

/// The actuated joints of a closed robot for its state vectors (frame numbers in its files).
fn frames(file: &str, n: usize) -> Vec<usize> {
    match file {
        "sr400.toml" => vec![1, 2, 4, 5, 6, 7],
        "fivebar.toml" => vec![1, 3],
        _ => (1..=n).collect(),
    }
}

/// One random command line; `out` is its output file.
fn command(rng: &mut Rng, dir: &Path, k: usize, out: &Path) -> Vec<String> {
    let (file, n, closed) = ROBOTS[rng.below(ROBOTS.len())];
    let n = if n == 0 { 14 } else { n }; // torso2arms: 14 movable joints... or a wrong count
    let r = robot(file);
    let o = out.to_str().unwrap().to_string();
    let mut a: Vec<String> = Vec::new();
    let mut push = |v: &[&str]| a.extend(v.iter().map(|s| s.to_string()));
    match rng.below(9) {
        0 | 1 => {
            let cmd = rng.pick(&["idm", "ddm"]);
            push(&[cmd, &r]);
            if rng.chance(50) {
                let third = if cmd == "idm" { "qdd" } else { "tau" };
                let t = state_table(rng, dir, n, third, k);
                push(&["--input", t.to_str().unwrap()]);
            } else {
                push(&[
                    &format!("--q={}", list(rng, n)),
                    &format!("--qd={}", list(rng, n)),
                ]);
            }
            if rng.chance(30) {
                push(&["--format", rng.pick(&["csv", "json", "xml"])]);
            }
        }
        2 => {
            let t = state_table(rng, dir, n, "qdd", k);
            push(&["regressor", &r, "--input", t.to_str().unwrap()]);
            if rng.chance(40) {
                push(&["--base"]);
            }
            if rng.chance(20) {
                push(&["--seed", rng.pick(&COUNTS)]);
            }
        }
        3 => {
            let qa = if closed {
                list(rng, frames(file, n).len())
            } else {
                list(rng, 1)
            };
            push(&["closure", &r, &format!("--qa={qa}")]);
            if rng.chance(30) {
                push(&["--guess", &list(rng, 3)]);
            }
            if rng.chance(50) {
                push(&["--jacobian", "--format", "json"]);
            }
        }
        4 | 5 => {
            // the work asked for stays bounded: a long or finely stepped run gets few steps
            let duration = if rng.chance(70) {
                rng.pick(&["0.02", "0.05", "0.2"])
            } else {
                rng.pick(&["0", "-1", "nan", "inf", "1e-9", "1e308", ""])
            };
            push(&["simulate", &r, "--duration", duration, "--output", &o]);
            let dt = rng
                .chance(50)
                .then(|| rng.pick(&["1e-300", "0.001", "0.01", "nan", "-0", "1e308"]));
            if let Some(dt) = dt {
                push(&["--dt", dt]);
            } else if rng.chance(30) {
                push(&["--rtol", rng.pick(&HOSTILE), "--atol", rng.pick(&HOSTILE)]);
            }
            let output_step = rng
                .chance(30)
                .then(|| rng.pick(&["1e-300", "1e-9", "0.01", "0", "nan", "1e308"]));
            if let Some(step) = output_step {
                push(&["--output-step", step]);
            }
            // every output row takes at least one step: few steps, or a short coarse run
            let short = matches!(duration, "1e-9" | "0.02" | "0.05" | "0.2")
                && matches!(dt, Some("0.001") | Some("0.01"))
                && !matches!(output_step, Some("1e-300") | Some("1e-9"));
            let steps = if short {
                rng.pick(&COUNTS)
            } else {
                rng.pick(&["0", "1", "100", "2000", "-1", ""])
            };
            push(&["--max-steps", steps]);
            if rng.chance(40) {
                push(&[&format!("--q0={}", list(rng, n))]);
            }
            if rng.chance(30) {
                push(&[&format!("--torque={}", list(rng, n))]);
            }
            if rng.chance(20) {
                push(&["--coulomb-smoothing", rng.pick(&HOSTILE)]);
            }
            if rng.chance(10) {
                push(&["--kp", "100"]);
            }
            if rng.chance(20) {
                push(&["--plot", &format!("{o}.svg")]);
            }
        }
        6 => {
            push(&["inertia", &r, &format!("--q={}", list(rng, n))]);
            if rng.chance(30) {
                push(&["--format", "json"]);
            }
        }
        7 => {
            let model = if closed {
                rng.pick(&["closed", "w", "idm"])
            } else {
                rng.pick(&["idm", "inertia", "h", "w"])
            };
            let lang = rng.pick(&["text", "latex", "rust", "c", "python", "julia", "matlab"]);
            push(&["generate", &r, "--model", model, "--lang", lang]);
            if rng.chance(50) {
                push(&["--numeric"]);
            }
            if rng.chance(30) {
                push(&[
                    "--name",
                    rng.pick(&["f", "my func", "1x", "end", "lambda", "", "ok_name"]),
                ]);
            }
            if rng.chance(30) {
                push(&["--output", &o]);
            }
        }
        _ => {
            let cmd = rng.pick(&["info", "base-params"]);
            push(&[cmd, &r]);
            if rng.chance(30) {
                push(&["--format", "json"]);
            }
        }
    }
    if rng.chance(15) {
        a.push("--set".into());
        a.push(format!(
            "{}={}",
            rng.pick(&["G3", "D3", "M2", "XX"]),
            rng.pick(&HOSTILE)
        ));
    }
    a
}

/// The words of a text that are not finite numbers (`NaN`, `inf`, ...).
fn non_finite_words(text: &str) -> Vec<String> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+'))
        .filter(|w| {
            let w = w.trim_start_matches(['-', '+']).to_ascii_lowercase();
            w == "nan" || w == "inf" || w == "infinity"
        })
        .map(str::to_string)
        .collect()
}

#[test]
fn random_command_lines_never_crash_hang_or_print_non_finite_numbers() {
    let seed: u64 = std::env::var("ROBODYN_HARNESS_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(0x5EED_2024);
    let runs: usize = std::env::var("ROBODYN_HARNESS_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1200);
    let dir = std::env::temp_dir().join(format!("robodyn_harness_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = Rng(seed);
    let mut exits = [0usize; 3];
    for k in 0..runs {
        let out = dir.join(format!("out{k}.csv"));
        let args = command(&mut rng, &dir, k, &out);
        let a: Vec<&str> = args.iter().map(String::as_str).collect();
        let what = format!("seed {seed:#x}, run {k}: robodyn {}", shell_words(&a));
        let r = robodyn_within(&a, LIMIT);
        if std::env::var("ROBODYN_HARNESS_VERBOSE").is_ok() {
            eprintln!(
                "{what}\n  -> {:?} {:.3} s {}",
                r.code,
                r.seconds,
                r.stderr.lines().next().unwrap_or("")
            );
        }
        r.assert_no_crash(&what);
        exits[r.code.unwrap() as usize] += 1;
        if r.code == Some(0) {
            let mut written = r.stdout.clone();
            for f in [out.clone(), out.with_extension("csv.svg")] {
                if let Ok(t) = std::fs::read_to_string(&f) {
                    written += &t;
                }
            }
            let bad = non_finite_words(&written);
            assert!(bad.is_empty(), "{what}: exit 0 with {bad:?} in its output");
        } else {
            assert!(
                r.stderr.contains("error"),
                "{what}: failed without saying why: {}",
                r.stderr
            );
        }
    }
    eprintln!("random command lines: {runs} runs, exit codes 0/1/2: {exits:?}");
    // the harness reaches both outcomes
    assert!(
        exits[0] > runs / 10 && exits[1] > runs / 10,
        "exit codes 0/1/2: {exits:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A command line as one would type it (for the failure message).
fn shell_words(a: &[&str]) -> String {
    a.iter()
        .map(|w| {
            if !w.is_empty()
                && w.chars()
                    .all(|c| c.is_ascii_alphanumeric() || "-_./=,:+".contains(c))
            {
                w.to_string()
            } else {
                format!("'{}'", w.replace('\'', "'\\''"))
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}
