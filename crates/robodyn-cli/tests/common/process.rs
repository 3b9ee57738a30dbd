//! Running the binary under limits: a time bound (a hang is a failure, not a stuck test), and a
//! shell's resource limits (`ulimit`) for the memory and file-size cases.

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

/// What a run of `robodyn` gave.
pub struct Run {
    /// Exit code (`None`: killed by a signal).
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
}

impl Run {
    /// Neither a panic (exit code 101, "panicked") nor an abort (134, or a signal).
    pub fn assert_no_crash(&self, what: &str) {
        assert!(
            matches!(self.code, Some(0) | Some(1) | Some(2)),
            "{what}: exit code {:?} (a crash)\n{}",
            self.code,
            self.stderr
        );
        assert!(!self.stderr.contains("panicked"), "{what}: {}", self.stderr);
    }
}

fn collect(out: Output, start: Instant) -> Run {
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// Run `cmd` (standard input closed unless set), killing it after `limit` seconds: a run that
/// needs the kill fails the test, naming `what`.
pub fn run_within(mut cmd: Command, limit: f64, what: &str) -> Run {
    let start = Instant::now();
    let mut child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // the pipes are drained by threads so a large output cannot block the child
    let mut out = child.stdout.take().unwrap();
    let mut err = child.stderr.take().unwrap();
    let t_out = std::thread::spawn(move || {
        let mut b = Vec::new();
        std::io::Read::read_to_end(&mut out, &mut b).ok();
        b
    });
    let t_err = std::thread::spawn(move || {
        let mut b = Vec::new();
        std::io::Read::read_to_end(&mut err, &mut b).ok();
        b
    });
    let deadline = start + Duration::from_secs_f64(limit);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            child.kill().ok();
            child.wait().ok();
            panic!("{what}: still running after {limit} s (killed)");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    collect(
        Output {
            status,
            stdout: t_out.join().unwrap(),
            stderr: t_err.join().unwrap(),
        },
        start,
    )
}

/// `robodyn ARGS` within `limit` seconds, standard input empty.
pub fn robodyn_within(args: &[&str], limit: f64) -> Run {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_robodyn"));
    cmd.args(args).stdin(Stdio::null());
    run_within(cmd, limit, &format!("robodyn {args:?}"))
}

/// `robodyn ARGS` run by `sh` after the shell commands `setup` (`ulimit -v ...`, `trap ...`),
/// within `limit` seconds.
pub fn robodyn_in_shell(setup: &str, args: &[&str], limit: f64) -> Run {
    let quoted: Vec<String> = args
        .iter()
        .map(|a| format!("'{}'", a.replace('\'', "'\\''")))
        .collect();
    let script = format!(
        "{setup}; exec '{}' {}",
        env!("CARGO_BIN_EXE_robodyn"),
        quoted.join(" ")
    );
    let mut cmd = Command::new("sh");
    cmd.args(["-c", &script]).stdin(Stdio::null());
    run_within(cmd, limit, &script)
}
