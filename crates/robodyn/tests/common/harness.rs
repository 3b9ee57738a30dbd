//! What every crate's `tests/all.rs` shares: the optional checks' visible skips, the shared
//! directory, and the guard that no `tests/*.rs` file is left out of the test binary.
//!
//! Optional checks need something building robodyn does not (the README's test section):
//!
//! | key         | needs                                        | checks                          |
//! |-------------|----------------------------------------------|---------------------------------|
//! | `octave`    | GNU Octave (`octave-cli`)                    | generated MATLAB runs, agrees   |
//! | `latex`     | `pdflatex`                                   | generated LaTeX typesets        |
//! | `numpy`     | `python3` with NumPy                         | generated Python runs, agrees   |
//! | `pinocchio` | Python `pin` and `example-robot-data`        | dynamics of real URDFs vs rnea  |
//! | `shared`    | the project's `shared/` directory (above the | external SYMORO `.par` files,   |
//! |             | repository)                                  | the real TX40 log               |
//! | `browser`   | node.js, Chromium, `npm ci` in               | the page of `robodyn view` in a |
//! |             | `crates/robodyn-cli/tests/browser`           | browser                         |
//!
//! Where one is missing the check is SKIPPED, visibly in cargo's default output: a `SKIPPED`
//! line when it happens and a summary after the binary's `test result:` line. (libtest hides
//! the output of passing tests and cannot mark a test ignored at run time, so both are written
//! to the process's standard error directly, past libtest's capture.) With
//! `ROBODYN_REQUIRE=all`, or a comma-separated list of keys, a missing one FAILS instead: CI
//! sets `ROBODYN_REQUIRE=all`.
#![allow(dead_code)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::{Mutex, Once};

/// The optional checks' keys (the table above).
pub const KEYS: &[&str] = &["octave", "latex", "numpy", "pinocchio", "shared", "browser"];

/// The skips so far: (test, reason).
static SKIPPED: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());
static SUMMARY: Once = Once::new();

/// The environment variables of the earlier schemes, each replaced by `ROBODYN_REQUIRE` (or by
/// the default, which skips visibly): a skip while one is set fails, naming the replacement, so
/// that a CI configuration that still sets it does not silently stop requiring the check.
pub const LEGACY: &[(&str, &str)] = &[
    ("ROBODYN_REQUIRE_OCTAVE", "ROBODYN_REQUIRE=octave"),
    ("ROBODYN_REQUIRE_LATEX", "ROBODYN_REQUIRE=latex"),
    ("ROBODYN_REQUIRE_PINOCCHIO", "ROBODYN_REQUIRE=pinocchio"),
    ("ROBODYN_REQUIRE_NUMPY", "ROBODYN_REQUIRE=numpy"),
    (
        "ROBODYN_ALLOW_MISSING_SHARED",
        "nothing (a missing shared/ is skipped visibly unless ROBODYN_REQUIRE names `shared`)",
    ),
    (
        "ROBODYN_SKIP_EXTERNAL",
        "nothing (a missing shared/ is skipped visibly unless ROBODYN_REQUIRE names `shared`)",
    ),
];

/// Whether `ROBODYN_REQUIRE` requires the optional check `key` (asked when it would be skipped).
/// An unknown key there, or a variable of [`LEGACY`], fails.
pub fn required(key: &str) -> bool {
    assert!(KEYS.contains(&key), "unknown optional check {key:?}");
    for (old, new) in LEGACY {
        assert!(
            std::env::var_os(old).is_none(),
            "{old} is no longer read: use {new} (ROBODYN_REQUIRE=all requires every optional \
             check; the README's test section)"
        );
    }
    let Ok(list) = std::env::var("ROBODYN_REQUIRE") else {
        return false;
    };
    list.split(',').map(str::trim).any(|k| {
        assert!(
            k == "all" || KEYS.contains(&k),
            "ROBODYN_REQUIRE={list}: unknown key {k:?} (all or a list of {KEYS:?})"
        );
        k == "all" || k == key
    })
}

/// Skip the calling test's optional check `key` because of `reason`: a visible SKIPPED line and
/// an entry in the summary, or a failure where `ROBODYN_REQUIRE` requires `key`. The caller
/// returns without checking.
pub fn skip(key: &str, reason: &str) {
    assert!(
        !required(key),
        "{reason} (ROBODYN_REQUIRE requires the optional check {key:?})"
    );
    let test = std::thread::current()
        .name()
        .unwrap_or("<unnamed>")
        .to_string();
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED {test}: {reason} (optional check `{key}`)"
    );
    SKIPPED
        .lock()
        .unwrap()
        .push((test, format!("{reason} [{key}]")));
    SUMMARY.call_once(|| {
        extern "C" {
            fn atexit(f: extern "C" fn()) -> std::ffi::c_int;
        }
        // SAFETY: registers a plain function without arguments, run once at process exit.
        unsafe { atexit(summary) };
    });
}

/// At exit, after libtest's `test result:` line: the skipped checks.
extern "C" fn summary() {
    let Ok(list) = SKIPPED.lock() else { return };
    let mut err = std::io::stderr().lock();
    let _ = writeln!(
        err,
        "SKIPPED {} optional check(s) above (passed without checking; the README's test section \
         says what they need; ROBODYN_REQUIRE=all makes a missing one fail):",
        list.len()
    );
    for (test, reason) in list.iter() {
        let _ = writeln!(err, "    {test}: {reason}");
    }
}

/// Whether `program args` runs here and exits with success.
pub fn runs(program: &str, args: &[&str]) -> bool {
    Command::new(program)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Whether the optional check `key` can run `program args`; if not, skips it (see [`skip`]) with
/// "PROGRAM not found: WHAT not checked".
pub fn tool(key: &str, program: &str, args: &[&str], what: &str) -> bool {
    let ok = runs(program, args);
    if !ok {
        skip(key, &format!("{program} not found: {what} not checked"));
    }
    ok
}

/// Whether `python3` can import NumPy; if not, skips the optional check `numpy` (generated
/// Python `what` not run), saying which is missing: python3 itself, or NumPy.
pub fn numpy(what: &str) -> bool {
    let ok = runs("python3", &["-c", "import numpy"]);
    if !ok {
        skip(
            "numpy",
            &numpy_missing(runs("python3", &["--version"]), what),
        );
    }
    ok
}

/// The skip reason of [`numpy`]: `python3` not found, or found without NumPy.
pub fn numpy_missing(python_runs: bool, what: &str) -> String {
    if python_runs {
        format!("python3 cannot import NumPy (pip install numpy): {what} not checked")
    } else {
        format!("python3 not found: {what} not checked")
    }
}

/// `shared/SUB` in the first ancestor of the crate that has it, if any (the project's shared
/// directory, read in place).
pub fn find_shared(sub: &str) -> Option<PathBuf> {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .ancestors()
        .map(|d| d.join("shared").join(sub))
        .find(|p| p.exists())
}

/// [`find_shared`], or a skip of the optional check `shared` (`what` not checked).
pub fn shared(sub: &str, what: &str) -> Option<PathBuf> {
    let found = find_shared(sub);
    if found.is_none() {
        skip(
            "shared",
            &format!(
                "shared/{sub} not found above {}: {what} not checked",
                env!("CARGO_MANIFEST_DIR")
            ),
        );
    }
    found
}

/// The guard of `tests/all.rs` (its text `all_rs`): every `tests/*.rs` file of the crate at
/// `manifest_dir` is one of its modules (`#[path = "FILE.rs"]` then `mod FILE;`), so none is
/// silently left out. The failure says which lines to add, and where.
pub fn every_test_file_is_a_module(manifest_dir: &str, all_rs: &str) {
    let dir = Path::new(manifest_dir).join("tests");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".rs") && n != "all.rs")
        .collect();
    names.sort();
    let lines: Vec<&str> = all_rs.lines().map(str::trim).collect();
    let mut missing = String::new();
    for name in &names {
        let stem = &name[..name.len() - 3];
        let path = format!("#[path = \"{name}\"]");
        let module = format!("mod {stem};");
        if !lines.windows(2).any(|w| w[0] == path && w[1] == module) {
            missing += &format!("{path}\n{module}\n");
        }
    }
    assert!(
        missing.is_empty(),
        "test files not compiled (never run): add these lines to {} among the other \
         `#[path]` modules (alphabetical order), before the guard test:\n\n{missing}",
        dir.join("all.rs").display()
    );
}
