//! Issue 12.2: `robodyn info` says what a closed robot's loop closure starts from: the file's
//! assembly, or, without one, q = 0 when the loops close there with Wp regular (the four-bar,
//! closed at q = 0 by construction: q_p = [0, 0], as its file states), or that q = 0 is
//! singular and how to give an assembly (OpenSYMORO's SR400 `.par`: q = 0 flattens the
//! parallelogram). A tree prints nothing about it.

mod common;

use common::{robot, run};

fn start_line(out: &str) -> &str {
    out.lines()
        .find(|l| l.starts_with("assembly"))
        .unwrap_or_else(|| panic!("no assembly line in\n{out}"))
}

#[test]
fn info_says_what_loop_closure_starts_from() {
    // the file's assembly
    let out = run(&["info", &robot("sr400.toml")]);
    let line = start_line(&out);
    assert!(
        line.starts_with("assembly (start of loop closure): q = ["),
        "{line}"
    );

    // none, and q = 0 closes regularly: the passive values printed are the file's q_p = [0, 0]
    let out = run(&["info", &robot("fourbar.toml")]);
    let line = start_line(&out);
    assert!(
        line.starts_with("assembly: none; the start is q_a = 0, where the loops close"),
        "{line}"
    );
    let qp = line.split("q_p = [").nth(1).unwrap();
    let qp: Vec<f64> = qp[..qp.find(']').unwrap()]
        .split(", ")
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(qp.len(), 2, "{line}");
    assert!(qp.iter().all(|x| x.abs() < 1e-6), "{line}");

    // a tree: no such line
    let out = run(&["info", &robot("rx90.toml")]);
    assert!(!out.lines().any(|l| l.starts_with("assembly")), "{out}");

    // JSON carries the same note
    let v: serde_json::Value =
        serde_json::from_str(&run(&["info", &robot("fourbar.toml"), "--format", "json"])).unwrap();
    assert!(v["assembly"].is_null());
    assert!(v["start"]
        .as_str()
        .is_some_and(|s| s.starts_with("assembly: none; the start is q_a = 0")));
}

#[test]
fn info_on_a_par_without_values_says_why_q0_cannot_start_and_how_to_give_an_assembly() {
    let Some(dir) = crate::harness::shared("cases/external", "info on SYMORO's SR400.par") else {
        return;
    };
    let file = dir.join("opensymoro-symoro/SR400.par");
    let out = run(&["info", file.to_str().unwrap()]);
    let line = start_line(&out);
    // OpenSYMORO's file has no numeric values: q = 0 cannot even be evaluated, and info says so
    assert!(
        line.starts_with("assembly: none, and q = 0 cannot serve as the start"),
        "{line}"
    );
    assert!(line.contains("has no numeric value"), "{line}");
    assert!(
        line.contains("robodyn assembly"),
        "says how to give one: {line}"
    );
}
