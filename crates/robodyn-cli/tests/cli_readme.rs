//! The README's commands, as written there (issue 30, item 8: "the README passes as written").
//! Every indented command line of README.md that runs the CLI (`cargo run --release -p
//! robodyn-cli -- ...`, continuation lines joined), and the `mkdir`/`printf` lines that prepare
//! their inputs, run in order in a scratch directory laid out like the repository (`robots/`
//! linked, `../shared` linked when the project's shared data is found), with the built binary in
//! place of `cargo run`. Each must succeed, except the SR400's fall, which the README says stops
//! with an error at the singularity (exit 1) after writing its trajectory.

use crate::harness;
use std::path::{Path, PathBuf};
use std::process::Command;

const CARGO_RUN: &str = "cargo run --release -p robodyn-cli -- ";

/// The README's shell lines that concern the CLI, continuation lines joined.
fn readme_commands(readme: &str) -> Vec<String> {
    let mut lines = Vec::new();
    let mut current = String::new();
    for raw in readme.lines() {
        let Some(line) = raw.strip_prefix("    ") else {
            continue;
        };
        let line = line.trim_end();
        if let Some(head) = line.strip_suffix('\\') {
            current.push_str(head.trim_start());
            continue;
        }
        current.push_str(line.trim_start());
        let cmd = std::mem::take(&mut current);
        if cmd.starts_with(CARGO_RUN) || cmd.starts_with("mkdir ") || cmd.starts_with("printf ") {
            lines.push(cmd);
        }
    }
    lines
}

fn scratch() -> PathBuf {
    let root = std::env::temp_dir().join(format!("robodyn_cli_readme_{}", std::process::id()));
    let repo = root.join("repo");
    std::fs::create_dir_all(&repo).unwrap();
    let robots = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    let link = repo.join("robots");
    if !link.exists() {
        std::os::unix::fs::symlink(robots.canonicalize().unwrap(), &link).unwrap();
    }
    repo
}

#[test]
fn readme_commands_run_as_written() {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../README.md")).unwrap();
    let commands = readme_commands(&readme);
    let cli = commands.iter().filter(|c| c.starts_with(CARGO_RUN)).count();
    assert!(cli >= 8, "only {cli} CLI commands found in the README");
    let repo = scratch();
    let shared = harness::find_shared("data/tx40");
    if let Some(dir) = &shared {
        let link = repo.parent().unwrap().join("shared");
        if !link.exists() {
            let top = dir.parent().unwrap().parent().unwrap();
            std::os::unix::fs::symlink(top.canonicalize().unwrap(), &link).unwrap();
        }
    }
    let bin = env!("CARGO_BIN_EXE_robodyn");
    for cmd in &commands {
        if cmd.contains("../shared") && shared.is_none() {
            harness::skip("shared", &format!("README command needs ../shared: {cmd}"));
            continue;
        }
        let line = cmd.replacen(CARGO_RUN, &format!("{bin} "), 1);
        let out = Command::new("sh")
            .arg("-c")
            .arg(&line)
            .current_dir(&repo)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let falls = cmd.contains("simulate") && cmd.contains("out/fall.csv");
        if falls {
            assert_eq!(out.status.code(), Some(1), "{cmd}: {err}");
            assert!(err.contains("singular"), "{cmd}: {err}");
            let csv = std::fs::read_to_string(repo.join("out/fall.csv")).unwrap();
            assert!(
                csv.lines().count() > 10,
                "{cmd}: the trajectory up to the stop"
            );
        } else {
            assert!(out.status.success(), "{cmd}: {err}");
        }
    }
    // the files the README's examples promise
    for f in ["out/sr400_run.svg", "out/fall.svg", "out/fall.html"] {
        let len = std::fs::metadata(repo.join(f))
            .map(|m| m.len())
            .unwrap_or(0);
        assert!(len > 1000, "{f}: {len} bytes");
    }
}
