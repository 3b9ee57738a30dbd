//! The properties the fuzz targets (`fuzz/`) check on every input, shared with the test that
//! replays the inputs they found (`tests/fuzz_regressions.rs`). Each function panics when the
//! property fails, which is what a fuzzer reports.

use crate::io::{par, physical_consistency, table::Table, toml_format, urdf, Format};
use crate::model::RobotDescription;
use robodyn_symbolic::Expr;

/// A robot file of any content: the reader accepts it or returns an error (never panics); an
/// accepted description goes through [`check_description`].
pub fn check_robot_file(format: Format, data: &[u8]) {
    let text = crate::io::decode_text(data.to_vec());
    let parsed = match format {
        Format::Toml => toml_format::parse_description(&text, Some("fuzz.toml")),
        Format::Par => par::parse_description(&text, Some("fuzz.par")),
        Format::Urdf => urdf::parse_description(&text, Some("fuzz.urdf")),
    };
    if let Ok((desc, _)) = parsed {
        check_description(&desc);
    }
}

/// An accepted description validates or is refused with an error, the physical-consistency
/// check runs, and both writers produce files the readers accept and read back to the same
/// text.
pub fn check_description(desc: &RobotDescription) {
    let _ = physical_consistency(desc);
    let _ = crate::Robot::new(desc.clone());
    let t = toml_format::write_description(desc);
    match toml_format::parse_description(&t, Some("rewritten.toml")) {
        Ok((back, _)) => assert_eq!(
            toml_format::write_description(&back),
            t,
            "TOML -> TOML is not stable"
        ),
        Err(e) => panic!("the TOML writer's output does not read back: {e}\n{t}"),
    }
    let p = par::write_description(desc);
    match par::parse_description(&p, Some("rewritten.par")) {
        Ok((back, _)) => assert_eq!(
            toml_format::write_description(&back),
            t,
            ".par -> TOML differs from the TOML writer's"
        ),
        Err(e) => panic!("the .par writer's output does not read back: {e}\n{p}"),
    }
}

/// An expression: an accepted one prints to text that parses back to the same printed form,
/// evaluates (to a number or an error), expands and counts its operations.
pub fn check_expression(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(e) = Expr::parse(text) else {
        return;
    };
    let printed = e.to_string();
    let again = match Expr::parse(&printed) {
        Ok(a) => a,
        Err(err) => panic!("`{text}` prints as `{printed}`, which does not parse: {err}"),
    };
    assert_eq!(
        again.to_string(),
        printed,
        "printing is not stable for `{text}`"
    );
    let _ = e.eval(&|s| Some(s.len() as f64 * 0.37 - 1.0));
    // expansion multiplies out: bounded inputs only (a fuzzer's `(a+b+c)^64` is 10^5 terms)
    if text.len() < 64 {
        let _ = e.expand();
    }
    let _ = robodyn_symbolic::count_ops(&e);
}

/// A state table: accepted rows have one finite number per column.
pub fn check_table(data: &[u8]) {
    if let Ok(t) = Table::parse(data, "fuzz.csv") {
        assert!(t.rows.iter().all(|r| r.len() == t.headers.len()));
        assert!(t.rows.iter().flatten().all(|x| x.is_finite()));
    }
}
