//! Hostile inputs (issue 13): every reader and the expression parser refuse them with a clear
//! error naming the file, the line and the key, in bounded memory and without recursion on the
//! depth the file controls; no writer changes a name.

use robodyn::io::{par, toml_format, urdf, Format};
use robodyn::{Error, Expr, RobotDescription};

fn toml(text: &str) -> Result<RobotDescription, Error> {
    toml_format::parse_description(text, Some("t.toml")).map(|(d, _)| d)
}

fn par(text: &str) -> Result<RobotDescription, Error> {
    par::parse_description(text, Some("t.par")).map(|(d, _)| d)
}

fn urdf(text: &str) -> Result<RobotDescription, Error> {
    urdf::parse_description(text, Some("t.urdf")).map(|(d, _)| d)
}

fn message(r: Result<RobotDescription, Error>) -> String {
    r.expect_err("must be refused").to_string()
}

const ONE_LINK: &str = "[[frame]]\nant = 0\n[[link]]\nM = 1\n";

#[test]
fn huge_joint_counts_are_refused_before_allocating() {
    // NF = 2 nj - nl frames would be allocated from these numbers
    for nj in [
        "10000000",
        "1000000000",
        "9223372036854775807",
        "18446744073709551615",
    ] {
        let m = message(toml(&format!("nl = 1\nnj = {nj}\n{ONE_LINK}")));
        assert!(m.starts_with("t.toml:"), "{m}");
        assert!(m.contains("nj"), "{m}");
    }
    let m = message(toml(&format!("nl = 1\nnj = 1e9\n{ONE_LINK}")));
    assert!(m.starts_with("t.toml:2:") && m.contains("key `nj`"), "{m}");
    for nj in ["10000000", "1000000000", "9223372036854775807"] {
        let m = message(par(&format!("NL = 1\nNJ = {nj}\nant = {{0}}\n")));
        assert!(m.starts_with("t.par:2:") && m.contains("NJ"), "{m}");
    }
    let m = message(par("NL = 1000000000\nNJ = 1000000000\n"));
    assert!(m.contains("at most 1000 frames"), "{m}");
    let m = message(par("NL = 1\nNJ = 1e9\n"));
    assert!(m.contains("not a whole number"), "{m}");
}

#[test]
fn deep_expressions_are_refused_with_a_depth_error() {
    let deep = [
        format!("{}1{}", "(".repeat(50_000), ")".repeat(50_000)),
        format!("{}1", "-".repeat(100_000)),
        format!("{}1{}", "sin(".repeat(50_000), ")".repeat(50_000)),
        format!("{}1", "2^".repeat(50_000)),
    ];
    for e in &deep {
        let err = Expr::parse(e).expect_err("too deep");
        assert!(err.message.contains("nested more than"), "{}", err.message);
        let m = message(toml(&format!(
            "nl = 1\n[[frame]]\nant = 0\nd = \"{e}\"\n[[link]]\n"
        )));
        assert!(
            m.starts_with("t.toml:4:") && m.contains("frame 1, d"),
            "{}",
            &m[..200.min(m.len())]
        );
        let m = message(par(&format!("NL = 1\nd = {{{e}}}\n")));
        assert!(
            m.starts_with("t.par:2:") && m.contains("nested"),
            "{}",
            &m[..200.min(m.len())]
        );
    }
    // within the limit, nesting is fine
    let ok = format!("{}x{}", "(".repeat(150), ")".repeat(150));
    assert_eq!(Expr::parse(&ok).unwrap().to_string(), "x");
}

#[test]
fn deep_trees_built_in_code_drop_print_and_evaluate() {
    // 200,000 nested sines: no recursion in drop, printing, evaluation or comparison
    let mut e = Expr::symbol("x");
    for _ in 0..200_000 {
        e = Expr::func(robodyn_symbolic::Func::Sin, e);
    }
    assert_eq!(e.depth(), 200_001);
    let v = e.eval(&|_| Some(0.5)).unwrap();
    assert!(v > 0.0 && v < 0.5);
    assert_eq!(e.to_string().len(), 200_000 * 5 + 1);
    let same = e.clone();
    assert_eq!(e, same);
    drop(e);
}

#[test]
fn toml_type_errors_and_duplicates_name_the_key() {
    let m = message(toml("nl = 1\n[[frame]]\nant = \"x\"\n[[link]]\n"));
    assert!(
        m.starts_with("t.toml:3:") && m.contains("[[frame]] number 1, key `ant`"),
        "{m}"
    );
    let m = message(toml("nl = 1\nnl = 2\n[[frame]]\nant = 0\n[[link]]\n"));
    assert!(
        m.starts_with("t.toml:2:") && m.contains("key `nl`") && m.contains("duplicate"),
        "{m}"
    );
    let m = message(toml("nl = 1\n[[frame]]\nant = 0\nd = 1\nd = 2\n[[link]]\n"));
    assert!(m.starts_with("t.toml:5:") && m.contains("key `d`"), "{m}");
    let m = message(toml("nl = 1\n[[frame]]\nant = 0\n[[link]]\nM = true\n"));
    assert!(
        m.starts_with("t.toml:5:") && m.contains("[[link]] number 1, key `M`"),
        "{m}"
    );
    assert!(m.contains("a number or a string"), "{m}");
    let m = message(toml(
        "nl = 1\n[symbols]\n\"a b\" = 1\n[[frame]]\nant = 0\n[[link]]\n",
    ));
    assert!(
        m.starts_with("t.toml:3:") && m.contains("`a b` is not a symbol name"),
        "{m}"
    );
}

#[test]
fn mimic_with_a_nan_multiplier_is_an_error_of_an_unknown_joint_a_warning() {
    let robot = |mimic: &str| {
        format!(
            "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"/>\n<link name=\"c\"/>\n\
             <joint name=\"j1\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint>\n\
             <joint name=\"j2\" type=\"revolute\"><parent link=\"b\"/><child link=\"c\"/>\n{mimic}\n</joint>\n</robot>\n"
        )
    };
    let m = message(urdf(&robot(
        "<mimic joint=\"does_not_exist\" multiplier=\"nan\"/>",
    )));
    assert!(
        m.starts_with("t.urdf:7:") && m.contains("multiplier"),
        "{m}"
    );
    let m = message(urdf(&robot("<mimic joint=\"j1\" offset=\"inf\"/>")));
    assert!(m.starts_with("t.urdf:7:") && m.contains("offset"), "{m}");
    // a dangling reference does not change the model (mimic joints are imported as independent
    // joints; example-robot-data's alex_psyonic_hands.urdf has some): a warning with its line
    let (_, map) =
        urdf::parse_description(&robot("<mimic joint=\"does_not_exist\"/>"), Some("t.urdf"))
            .unwrap();
    let w: Vec<String> = map.warnings.iter().map(|w| w.to_string()).collect();
    assert!(
        w.len() == 1
            && w[0].starts_with("t.urdf:7: frame 2: joint `j2`")
            && w[0].contains("does_not_exist"),
        "{w:?}"
    );
    let d = urdf(&robot(
        "<mimic joint=\"j1\" multiplier=\"-2\" offset=\"0.5\"/>",
    ))
    .unwrap();
    assert!(
        d.notes
            .iter()
            .any(|n| n.contains("j2 mimics j1 (q = -2.0 * q_j1 + 0.5)")),
        "{:?}",
        d.notes
    );
}

/// Names that break a `.par` comment or list, or TOML's basic strings.
const NASTY: [&str; 8] = [
    "a;b",
    "x *) y",
    "(* z",
    "two\nlines",
    "quote\"d",
    " padded ",
    "back\\slash",
    "ctrl\u{1b}char",
];

#[test]
fn convert_keeps_every_name() {
    let mut d = toml(&format!("name = \"r\"\nnl = 1\n{ONE_LINK}")).unwrap();
    for (k, n) in NASTY.iter().enumerate() {
        d.name = n.to_string();
        d.frames[0].name = format!("f{k}{n}");
        d.links[0].name = format!("l{k}{n}");
        d.notes = vec![format!("note {n}")];
        for format in [Format::Toml, Format::Par] {
            let text = match format {
                Format::Toml => toml_format::write_description(&d),
                _ => par::write_description(&d),
            };
            let back = match format {
                Format::Toml => toml(&text),
                _ => par(&text),
            }
            .unwrap_or_else(|e| panic!("{n:?} ({format:?}): {e}\n{text}"));
            assert_eq!(back.name, d.name, "{format:?}\n{text}");
            assert_eq!(back.frames[0].name, d.frames[0].name, "{format:?}\n{text}");
            assert_eq!(back.links[0].name, d.links[0].name, "{format:?}\n{text}");
            assert_eq!(back.notes, d.notes, "{format:?}\n{text}");
        }
    }
}

#[test]
fn large_files_load_in_bounded_time_per_line() {
    // a 2000-link chain: the line of every value comes from a line index (this test would take
    // minutes with a quadratic search; its time is not asserted, the cost is measured in
    // `examples/scaling.rs`)
    let mut s = String::from("nl = 2000\n");
    for j in 1..=2000 {
        s.push_str(&format!(
            "[[frame]]\nant = {}\nd = 0.1\nalpha = \"pi/2\"\n",
            j - 1
        ));
    }
    for _ in 1..=2000 {
        s.push_str("[[link]]\nM = 1\nXX = 0.1\nYY = 0.1\nZZ = 0.1\n");
    }
    let (d, map) = toml_format::parse_description(&s, Some("big.toml")).unwrap();
    assert_eq!(d.nl, 2000);
    assert_eq!(
        map.line_of(&robodyn::error::Item::Link(2000, Some("ZZ".into()))),
        Some(1 + 4 * 2000 + 5 * 1999 + 5)
    );
}
