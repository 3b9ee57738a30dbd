//! What a person sees (issue 30.4, 30.9, 30.10): warnings of the loader printed with the link
//! and the inequality; numbers written once by one rule (no `5000.000000`, `1.68993e0`,
//! `-0.000000`); grouping equations in one style per line; units in the identification table;
//! a warning said once; `info`'s title first; every option and value with a help text; plots
//! whose panels carry their own units, the tracked reference and its error.

mod common;
use common::{robot, run, tmp};
use std::process::{Command, Output};

fn robodyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(args)
        .output()
        .unwrap()
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// Whether an SVG of plotters has a text element `s` (its content is a line of its own).
fn has_text(svg: &str, s: &str) -> bool {
    svg.lines().any(|l| l.trim() == s)
}

/// Number spellings issue 30 found: fixed decimals that print noise or a negative zero, an
/// exponent on a number that needs none.
fn bad_number(s: &str) -> Option<&str> {
    s.split(|c: char| c.is_whitespace() || matches!(c, ',' | '(' | ')' | '[' | ']' | '='))
        .find(|t| {
            t.ends_with("e0")
                || t.contains("e+")
                || t.starts_with("-0.000000")
                || t.contains(".000000")
        })
}

/// The SCARA with link 4's inertia about its centre of mass diag(IXX4, 0.2, 0.5) (IXX4 a
/// symbol of the file, 0.1 there: positive definite, but 0.1 + 0.2 < 0.5).
fn triangle_robot() -> String {
    let text = std::fs::read_to_string(robot("scara.toml")).unwrap();
    let cut = text.rfind("[[link]]").unwrap();
    let file = format!(
        "{}[[link]]\nj = 4\nXX = \"IXX4 + 0.005\"\nXY = 0\nXZ = 0.01\nYY = 0.225\nYZ = 0\n\
         ZZ = 0.52\nMX = 0.2\nMY = 0\nMZ = -0.1\nM = 2\n",
        &text[..cut]
    )
    .replace("[symbols]\n", "[symbols]\nIXX4 = 0.1\n");
    let path = tmp("presentation", "triangle.toml");
    std::fs::write(&path, file).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn inconsistent_inertia_is_reported_at_load() {
    let file = triangle_robot();
    for args in [
        vec!["idm", &file, "--q", "0,0,0,0"],
        vec!["info", &file],
        vec!["inertia", &file],
    ] {
        let out = robodyn(&args);
        assert!(out.status.success(), "{args:?}: {}", text(&out.stderr));
        let err = text(&out.stderr);
        assert!(
            err.contains("robodyn: warning: ")
                && err
                    .contains(": link 4: Ixx + Iyy < Izz at the centre of mass (0.1 + 0.2 < 0.5)"),
            "{args:?}: {err}"
        );
    }
    // the value --set gives is the one checked: 0.35 makes a body
    let out = robodyn(&["idm", &file, "--q", "0,0,0,0", "--set", "IXX4=0.35"]);
    assert!(out.status.success());
    assert!(
        !text(&out.stderr).contains("warning"),
        "{}",
        text(&out.stderr)
    );
    // bundled robots load without a warning
    let out = robodyn(&["idm", &robot("scara.toml"), "--q", "0,0,0,0"]);
    assert_eq!(text(&out.stderr), "");
}

#[test]
fn info_starts_with_the_robot() {
    let out = run(&["info", &robot("fivebar.toml")]);
    assert!(
        out.starts_with("planar five-bar: closed chain structure"),
        "{out}"
    );
    let loops = out.find("loops:").unwrap();
    let assembly = out.find("assembly: none").unwrap();
    assert!(assembly > loops, "{out}");
    assert!(out.contains("(q_p = [0, 0])"), "{out}");
    assert!(bad_number(&out).is_none(), "{:?}", bad_number(&out));
}

/// Every option of every command has a help text, and every value of an option that takes
/// one of a list is documented (`--help`), `robodyn --help` shows a first command and where
/// the documentation is.
#[test]
fn every_option_and_value_has_a_help_text() {
    let commands = [
        "info",
        "idm",
        "closure",
        "base-params",
        "regressor",
        "convert",
        "inertia",
        "ddm",
        "simulate",
        "generate",
        "identify",
        "excite",
    ];
    for c in commands {
        let help = run(&[c, "--help"]);
        assert!(
            !help.contains("[possible values:"),
            "{c}: values without help text:\n{help}"
        );
        let lines: Vec<&str> = help.lines().collect();
        for (i, l) in lines.iter().enumerate() {
            let t = l.trim_start();
            if !(t.starts_with("--") || t.starts_with("-h, ") || t.starts_with("-V, ")) {
                continue;
            }
            // the short layout puts the text on the option's line, the long one below it
            let doc = match t.split_once("  ") {
                Some((_, rest)) => rest.trim(),
                None => lines.get(i + 1).map_or("", |n| n.trim()),
            };
            assert!(
                !doc.is_empty() && !doc.starts_with('[') && doc != "Possible values:",
                "{c}: `{t}` has no help text"
            );
        }
    }
    let top = run(&["--help"]);
    assert!(top.contains("robodyn info robots/"), "{top}");
    assert!(
        top.contains("docs/cli.md") && top.contains("README.md"),
        "{top}"
    );
}

/// Grouping equations of the numerical method: one style per line (the TX40's geometry is
/// decimal: 0.225, not 9/40 next to 0.007875).
#[test]
fn grouping_equations_have_one_number_style_per_line() {
    let out = run(&["base-params", &robot("tx40.toml"), "--method", "numeric"]);
    assert!(
        out.contains("XZR2 = XZ2 - 0.225*MZ3 - 0.007875*M3"),
        "{out}"
    );
    let equations = out
        .split("Grouping equations:")
        .nth(1)
        .unwrap()
        .split("\n\n")
        .next()
        .unwrap();
    for line in equations.lines() {
        let fraction = line.contains('/');
        let decimal = line
            .split(|c: char| !(c.is_ascii_digit() || c == '.'))
            .any(|t| t.contains('.') && t.len() > 1);
        assert!(!(fraction && decimal), "mixed styles: {line}");
    }
}

/// The identification of the real TX40 log: numbers for people, units per parameter and per
/// joint, the poorly-identified warning once, the plot's units per joint.
#[test]
fn identification_report_reads_well() {
    let Some(data) = crate::harness::shared("data/tx40/tx40_joint.csv", "the TX40 report") else {
        return;
    };
    let data = data.to_str().unwrap().to_string();
    let plot = tmp("presentation", "tx40_fit.svg");
    let args = [
        "identify",
        &robot("tx40.toml"),
        "--data",
        &data,
        "--offsets",
        "--validation",
        "0.6:0.8",
        "--plot",
        plot.to_str().unwrap(),
    ];
    let out = robodyn(&args);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (report, err) = (text(&out.stdout), text(&out.stderr));
    assert!(report.contains("samples at 5000 Hz ("), "{report}");
    assert!(bad_number(&report).is_none(), "{:?}", bad_number(&report));
    let header = report.lines().find(|l| l.starts_with("parameter")).unwrap();
    assert!(
        header.contains(" unit ") && header.contains("value"),
        "{header}"
    );
    let zzr1 = report.lines().find(|l| l.starts_with("ZZR1 ")).unwrap();
    assert!(zzr1.contains(" kg m^2 "), "{zzr1}");
    let fv1 = report.lines().find(|l| l.starts_with("FV1 ")).unwrap();
    assert!(fv1.contains(" N m s/rad "), "{fv1}");
    let joint1 = report.lines().find(|l| l.starts_with("  1  ")).unwrap();
    assert!(joint1.contains(" N m "), "{joint1}");
    let said = |s: &str| s.matches("poorly identified").count();
    assert_eq!(said(&report) + said(&err), 1, "{report}\n{err}");
    // with the report in a file, standard error says it (once)
    let file = tmp("presentation", "tx40.txt");
    let mut to_file = args[..7].to_vec();
    to_file.extend(["--output", file.to_str().unwrap()]);
    let out = robodyn(&to_file);
    assert_eq!(said(&text(&out.stderr)), 1, "{}", text(&out.stderr));
    assert_eq!(said(&std::fs::read_to_string(&file).unwrap()), 1);
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(has_text(&svg, "tau1 [N m]") && has_text(&svg, "tau6 [N m]"));
    assert!(!svg.contains("force [N]"));
}

#[test]
fn excitation_plot_has_a_unit_per_panel() {
    let plot = tmp("presentation", "excite_scara.svg");
    run(&[
        "excite",
        &robot("scara.toml"),
        "--period",
        "5",
        "--harmonics",
        "3",
        "--iterations",
        "40",
        "--qd-max",
        "1",
        "--qdd-max",
        "3",
        "--output",
        tmp("presentation", "excite_scara.csv").to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(&plot).unwrap();
    for label in [
        "q [rad]",
        "q [m]",
        "qd [rad/s]",
        "qd [m/s]",
        "qdd [rad/s^2]",
        "qdd [m/s^2]",
    ] {
        assert!(has_text(&svg, label), "{label}");
    }
    assert!(!svg.contains("rad, rad/s, rad/s^2"));
}

/// `simulate --track --plot` of the SR400 (a closed chain): the reference dashed beside the
/// positions, a tracking-error panel, the passive joints marked, the energy panel says it is the
/// work of the torques (not a drift).
#[test]
fn tracking_plot_shows_the_reference_and_the_error() {
    let reference = tmp("presentation", "hold.csv");
    std::fs::write(
        &reference,
        "t,q1,q2,q4,q5,q6,q7\n0,0,0,0,0,0,1.5708\n0.5,0.2,0.1,0.1,0.1,0.1,1.6\n",
    )
    .unwrap();
    let plot = tmp("presentation", "tracked.svg");
    run(&[
        "simulate",
        &robot("sr400.toml"),
        "--duration",
        "0.5",
        "--track",
        reference.to_str().unwrap(),
        "--kp",
        "3000",
        "--kd",
        "300",
        "--output",
        tmp("presentation", "tracked.csv").to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(&plot).unwrap();
    for s in [
        "tracking error q_ref - q, revolute joints",
        "q_ref - q [rad]",
        "reference",
        "q3 (passive)",
        "q8 (passive)",
    ] {
        assert!(has_text(&svg, s), "{s}");
    }
    assert!(svg.contains("the work of the joint torques"));
    assert!(!svg.contains("drift"));
}
