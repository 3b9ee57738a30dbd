//! Malformed input ends with a message naming the file, the line (or frame/link) and the reason,
//! and exit code 1: never a panic (exit code 101) or a NaN result. One test per case.

use std::path::PathBuf;
use std::process::Command;

fn tmp(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("robodyn_cli_bad_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// Run robodyn, expect failure with exit code 1; return stderr.
fn fails(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(1), "stderr: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(err.starts_with("robodyn: error: "), "{err}");
    err
}

fn path(p: &std::path::Path) -> &str {
    p.to_str().unwrap()
}

const FRAMES: &str = "nl = 2\nnj = 2\n\n[[frame]]\nant = 0\n\n[[frame]]\nant = 1\nd = 0.3\n";
const LINKS: &str = "\n[[link]]\nM = 1\n\n[[link]]\nM = 2\nMX = 0.2\n";

#[test]
fn unknown_key_in_toml() {
    let f = tmp("unknown_key.toml", &format!("{FRAMES}colour = 3\n{LINKS}"));
    // `colour` lands in frame 2's table (line 10)
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:10", path(&f))), "{e}");
    assert!(e.contains("unknown field `colour`"), "{e}");
}

#[test]
fn unknown_key_in_par() {
    let f = tmp("unknown_key.par", "NL = 2\nNJ = 2\nNF = 2\nantt = {0,1}\n");
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:4:", path(&f))), "{e}");
    assert!(e.contains("unknown key `antt`"), "{e}");
}

#[test]
fn list_of_the_wrong_length() {
    let f = tmp(
        "short.par",
        "NL = 3\nNJ = 3\nNF = 3\n(* lengths *)\nd = {0, 0.2}\n",
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:5:", path(&f))), "{e}");
    assert!(e.contains("d has 2 entries, NF = 3 expected"), "{e}");
}

#[test]
fn antecedent_not_smaller_than_j() {
    let f = tmp(
        "ant.toml",
        &format!("{}{LINKS}", FRAMES.replace("ant = 1", "ant = 2")),
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:8", path(&f))), "{e}");
    assert!(e.contains("frame 2, ant"), "{e}");
    assert!(e.contains("a(2) = 2 must be smaller than 2"), "{e}");
}

const URDF_LINKS: &str = r#"<robot name="t">
  <link name="base"/>
  <link name="a"/>
  <link name="b"/>
"#;

#[test]
fn urdf_cycle() {
    let f = tmp(
        "cycle.urdf",
        &format!(
            "{URDF_LINKS}  <joint name=\"ab\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint>\n  \
             <joint name=\"ba\" type=\"revolute\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>\n"
        ),
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:5", path(&f))), "{e}");
    assert!(
        e.contains("cycle") && e.contains("`ab`") && e.contains("`ba`"),
        "{e}"
    );
}

#[test]
fn urdf_link_with_two_parents() {
    let f = tmp(
        "two_parents.urdf",
        &format!(
            "{URDF_LINKS}  <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"a\"/></joint>\n  \
             <joint name=\"j2\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint>\n  \
             <joint name=\"j3\" type=\"fixed\"><parent link=\"base\"/><child link=\"b\"/></joint>\n</robot>\n"
        ),
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:7:", path(&f))), "{e}");
    assert!(e.contains("link `b` has two parents"), "{e}");
    assert!(e.contains("`j2`") && e.contains("`j3`"), "{e}");
}

#[test]
fn urdf_unknown_link_and_floating_joint() {
    let f = tmp(
        "unknown_link.urdf",
        &format!("{URDF_LINKS}  <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"c\"/></joint>\n</robot>\n"),
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:5:", path(&f))), "{e}");
    assert!(
        e.contains("joint `j1`: child link `c` is not defined"),
        "{e}"
    );
    let f = tmp(
        "floating.urdf",
        &format!("{URDF_LINKS}  <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"a\"/></joint>\n  \
                  <joint name=\"free\" type=\"floating\"><parent link=\"a\"/><child link=\"b\"/></joint>\n</robot>\n"),
    );
    // a floating joint is the root joint of a floating base, nowhere else
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:6:", path(&f))), "{e}");
    assert!(
        e.contains("joint `free`: type `floating` is accepted as the root joint only"),
        "{e}"
    );
}

#[test]
fn unknown_symbol() {
    let f = tmp(
        "symbol.toml",
        &format!("{}{LINKS}", FRAMES.replace("d = 0.3", "d = \"L9\"")),
    );
    let e = fails(&["idm", path(&f), "--q", "0,0"]);
    assert!(e.contains(&format!("{}:9", path(&f))), "{e}");
    assert!(e.contains("frame 2, d") && e.contains("symbol `L9`"), "{e}");
    assert!(e.contains("no numeric value"), "{e}");
}

#[test]
fn nan_value() {
    let f = tmp(
        "nan.toml",
        &format!("{}{LINKS}", FRAMES.replace("d = 0.3", "d = nan")),
    );
    let e = fails(&["idm", path(&f), "--q", "0,0"]);
    assert!(e.contains(&format!("{}:9", path(&f))), "{e}");
    assert!(e.contains("NaN is not a finite number"), "{e}");
}

#[test]
fn infinite_values() {
    let f = tmp(
        "inf.toml",
        &format!("{FRAMES}{}", LINKS.replace("MX = 0.2", "MX = -inf")),
    );
    let e = fails(&["idm", path(&f), "--q", "0,0"]);
    assert!(e.contains(&format!("{}:16", path(&f))), "{e}");
    assert!(e.contains("-inf is not a finite number"), "{e}");
    // in a .par file, a number overflowing to infinity, found when evaluating
    let f = tmp(
        "inf.par",
        "NL = 2\nNJ = 2\nNF = 2\nd = {0, 1e999}\nM = {1, 1}\n",
    );
    let e = fails(&["idm", path(&f), "--q", "0,0"]);
    assert!(e.contains(&format!("{}:4", path(&f))), "{e}");
    assert!(e.contains("frame 2, d") && e.contains("finite"), "{e}");
    // in a URDF
    let f = tmp(
        "inf.urdf",
        "<robot name=\"r\">\n<link name=\"b\"/>\n<link name=\"a\"><inertial><mass value=\"inf\"/><inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial></link>\n\
         <joint name=\"j\" type=\"revolute\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>\n",
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:3:", path(&f))), "{e}");
    assert!(
        e.contains("mass") && e.contains("not a finite number"),
        "{e}"
    );
}

#[test]
fn negative_mass() {
    let f = tmp(
        "mass.toml",
        &format!("{FRAMES}{}", LINKS.replace("M = 2", "M = -2")),
    );
    let e = fails(&["idm", path(&f), "--q", "0,0"]);
    assert!(e.contains(&format!("{}:15", path(&f))), "{e}");
    assert!(e.contains("link 2, M") && e.contains("negative"), "{e}");
    // in a URDF: the line of the <mass> element
    let f = tmp(
        "mass.urdf",
        "<robot name=\"r\">\n<link name=\"b\"/>\n<link name=\"a\"><inertial>\n<mass value=\"-3\"/>\n\
         <inertia ixx=\"1\" iyy=\"1\" izz=\"1\"/></inertial></link>\n\
         <joint name=\"j\" type=\"revolute\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>\n",
    );
    let e = fails(&["idm", path(&f), "--q", "0"]);
    assert!(e.contains(&format!("{}:4", path(&f))), "{e}");
    assert!(e.contains("link 1, M") && e.contains("negative"), "{e}");
}

fn robot() -> String {
    concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml").to_string()
}

#[test]
fn csv_missing_column() {
    let f = tmp(
        "missing.csv",
        "q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6,qdd1,qdd2,qdd3,qdd4,qdd5\n0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n",
    );
    let e = fails(&["idm", &robot(), "--input", path(&f)]);
    assert!(e.contains(path(&f)), "{e}");
    assert!(e.contains("missing column `qdd6`"), "{e}");
}

#[test]
fn csv_not_a_number() {
    let head = "q1,q2,q3,q4,q5,q6,qd1,qd2,qd3,qd4,qd5,qd6,qdd1,qdd2,qdd3,qdd4,qdd5,qdd6\n";
    let f = tmp(
        "nan.csv",
        &format!(
            "{head}0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n0,0,x1,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0\n"
        ),
    );
    let e = fails(&["idm", &robot(), "--input", path(&f)]);
    assert!(e.contains(&format!("{}:3", path(&f))), "{e}");
    assert!(
        e.contains("column `q3`") && e.contains("`x1` is not a number"),
        "{e}"
    );
}

#[test]
fn urdf_cycle_without_root() {
    let f = tmp(
        "cycle_no_root.urdf",
        "<robot name=\"t\">\n  <link name=\"a\"/>\n  <link name=\"b\"/>\n  \
         <joint name=\"ab\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint>\n  \
         <joint name=\"ba\" type=\"revolute\"><parent link=\"b\"/><child link=\"a\"/></joint>\n</robot>\n",
    );
    let e = fails(&["info", path(&f)]);
    assert!(e.contains(&format!("{}:1:", path(&f))), "{e}");
    assert!(
        e.contains("cycle") && e.contains("`ab` (line 4)") && e.contains("`ba` (line 5)"),
        "{e}"
    );
}
