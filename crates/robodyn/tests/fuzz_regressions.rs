//! Every input the fuzzers (`fuzz/`) found crashing, replayed through the same checks
//! (`robodyn::io::fuzz_checks`): each file of `fuzz/regressions/<target>/` must now pass.

use robodyn::io::{fuzz_checks, Format};
use std::path::Path;

fn replay(target: &str, check: impl Fn(&[u8]) + std::panic::RefUnwindSafe) {
    let dir = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fuzz/regressions"
    ))
    .join(target);
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
        let path = entry.unwrap().path();
        let data = std::fs::read(&path).unwrap();
        let name = path.display().to_string();
        // a failing check panics: name the input
        if let Err(e) = std::panic::catch_unwind(|| check(&data)) {
            let msg = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            panic!("{name}: {msg}");
        }
        n += 1;
    }
    assert!(n > 0, "no regression input in {}", dir.display());
}

#[test]
fn expressions() {
    replay("expr", fuzz_checks::check_expression);
}

#[test]
fn toml_files() {
    replay("toml", |d| fuzz_checks::check_robot_file(Format::Toml, d));
}

#[test]
fn par_files() {
    replay("par", |d| fuzz_checks::check_robot_file(Format::Par, d));
}

#[test]
fn urdf_files() {
    replay("urdf", |d| fuzz_checks::check_robot_file(Format::Urdf, d));
}

#[test]
fn state_tables() {
    replay("csv", fuzz_checks::check_table);
}
