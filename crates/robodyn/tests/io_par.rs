//! SYMORO `.par` files: the bundled robots give the same torques from .par, .toml and URDF;
//! random trees round-trip through the writer and the reader; the dialect's details (comments,
//! capitalised keys, joint variables with offsets) and its errors (file, line, reason).

use rand::Rng;
use robodyn::algorithms::inverse_dynamics::inverse_dynamics;
use robodyn::io::{par, toml_format};
use robodyn::model::param;
use robodyn::{Error, Expr, Robot, RobotDescription};
use robodyn_testing::{self as testing, TreeOptions};
use std::path::Path;

fn robots() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots"))
}

fn load(name: &str) -> Robot {
    robodyn::io::load(robots().join(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Largest torque difference over random states, relative to the largest torque.
fn torque_difference(a: &Robot, b: &Robot, seed: u64) -> f64 {
    assert_eq!(a.nl(), b.nl());
    let mut rng = testing::rng(seed);
    let mut worst: f64 = 0.0;
    for _ in 0..20 {
        let [q, qd, qdd] = testing::random_state(&mut rng, a.dof());
        let ta = inverse_dynamics(a, &q, &qd, &qdd).unwrap();
        let tb = inverse_dynamics(b, &q, &qd, &qdd).unwrap();
        let scale = ta.amax();
        assert!(
            scale > 1e-3,
            "torques vanish: the comparison would be vacuous"
        );
        worst = worst.max((ta - tb).amax() / scale);
    }
    worst
}

#[test]
fn sr400_par_and_toml_give_the_same_torques() {
    let (p, t) = (load("sr400.par"), load("sr400.toml"));
    assert_eq!(p.name(), "SR400");
    assert_eq!((p.nl(), p.nj(), p.nf()), (8, 9, 10));
    assert_eq!(p.description().gravity[2].to_string(), "G3");
    assert_eq!(p.description().symbols["G3"], -9.81);
    let e = torque_difference(&p, &t, 1);
    assert!(e < 1e-14, "{e:e}");
}

#[test]
fn rx90_toml_par_and_urdf_give_the_same_torques() {
    let (t, p, u) = (load("rx90.toml"), load("rx90.par"), load("rx90.urdf"));
    let e = torque_difference(&t, &p, 2);
    assert!(e < 1e-14, "toml vs par: {e:e}");
    // URDF has no rotor inertias: compare with the TOML robot without them
    let mut d = t.description().clone();
    for l in &mut d.links {
        l.params[param::IA] = Expr::zero();
    }
    let t0 = Robot::new(d).unwrap();
    let e = torque_difference(&t0, &u, 3);
    assert!(e < 1e-10, "toml vs urdf: {e:e}");
    // the URDF frames reproduce the modified DH table
    for j in 1..=6 {
        for (k, (a, b)) in t
            .frame(j)
            .geometric()
            .iter()
            .zip(u.frame(j).geometric())
            .enumerate()
        {
            let value = |r: &Robot, e: &Expr| {
                e.eval(&|s| r.description().symbols.get(s).copied())
                    .unwrap()
            };
            let (a, b) = (value(&t, a), value(&u, b));
            assert!(
                (a - b).abs() < 1e-15,
                "frame {j}, parameter {k}: {a} vs {b}"
            );
        }
        assert_eq!(t.frame(j).name, u.frame(j).name);
    }
}

#[test]
fn bundled_robots_convert_to_par_and_back() {
    for name in [
        "sr400.toml",
        "rx90.toml",
        "torso2arms.toml",
        "scara.toml",
        "rx90.urdf",
    ] {
        let r = load(name);
        let text = par::write_description(r.description());
        let (d, _) = par::parse_description(&text, Some("converted.par")).unwrap();
        let back = Robot::new(d).unwrap();
        let e = torque_difference(&r, &back, 4);
        assert!(e == 0.0, "{name}: {e:e}");
        // TOML -> .par -> TOML is the identity on the description, but for the named frames
        // ([[tool]], the URDF root link's), which a .par has no place for
        let mut without_tools = r.description().clone();
        without_tools.tools.clear();
        assert_eq!(
            toml_format::write_description(back.description()),
            toml_format::write_description(&without_tools),
            "{name}"
        );
    }
}

#[test]
fn random_trees_round_trip_through_par() {
    let opt = TreeOptions {
        p_prismatic: 0.3,
        p_fixed: 0.15,
        general_frames: true,
        friction: true,
        wrenches: true,
        ..TreeOptions::default()
    };
    for seed in 0..30 {
        let mut rng = testing::rng(seed);
        let n = rng.random_range(2..=30);
        let mut d = testing::random_tree_description(&mut rng, n, &opt);
        // symbols with values, as in a real file
        d.symbols.insert("L1".into(), rng.random_range(0.1..1.0));
        d.frames[0].d = Expr::symbol("L1");
        d.notes.push("random tree".into());
        let text = par::write_description(&d);
        let (back, _) = par::parse_description(&text, None).unwrap();
        assert_desc_eq(&d, &back, seed);
        let e = torque_difference(&Robot::new(d).unwrap(), &Robot::new(back).unwrap(), seed);
        assert!(e == 0.0, "seed {seed}: {e:e}");
    }
}

fn assert_desc_eq(a: &RobotDescription, b: &RobotDescription, seed: u64) {
    assert_eq!(
        (a.nl, a.nj, &a.name, &a.notes),
        (b.nl, b.nj, &b.name, &b.notes),
        "seed {seed}"
    );
    assert_eq!(a.symbols, b.symbols, "seed {seed}");
    for (j, (fa, fb)) in a.frames.iter().zip(&b.frames).enumerate() {
        assert_eq!(fa, fb, "seed {seed}, frame {}", j + 1);
    }
    for (j, (la, lb)) in a.links.iter().zip(&b.links).enumerate() {
        assert_eq!(la, lb, "seed {seed}, link {}", j + 1);
    }
    assert_eq!(a.gravity, b.gravity);
}

const HEAD: &str = "NL = 3\nNJ = 3\nNF = 3\nType = 0\n";

fn parse(body: &str) -> Result<RobotDescription, Error> {
    par::parse_description(body, Some("test.par")).map(|(d, _)| d)
}

#[test]
fn joint_variables_offsets_and_comments() {
    let text = format!(
        "(* a comment\n   spanning (* nested *) lines *)\n{HEAD}Ant = {{0,1,2}}\nSigma = {{0,1,0}}\n\
         Theta = {{th1 + Pi/2, -pi/2, t3 - 0.25}}\nR = {{0.1, r2 + d0, 0}}\n\
         (* robodyn values: d0 = 0.5 *)\n"
    );
    let d = parse(&text).unwrap();
    let v = |e: &Expr| e.eval(&|s| d.symbols.get(s).copied()).unwrap();
    assert!((v(&d.frames[0].theta) - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    assert!((v(&d.frames[1].theta) + std::f64::consts::FRAC_PI_2).abs() < 1e-15); // prismatic: constant
    assert_eq!(v(&d.frames[2].theta), -0.25);
    assert_eq!(v(&d.frames[0].r), 0.1);
    assert_eq!(d.frames[1].r.to_string(), "d0"); // r2 is the variable, d0 the offset
    assert_eq!(v(&d.frames[1].r), 0.5);
    // q<j> also names a variable
    let d = parse(&format!("{HEAD}theta = {{q1, q2, q3}}\n")).unwrap();
    assert!(d.frames.iter().all(|f| f.theta.is_zero()));
}

fn err(text: &str) -> String {
    let e = parse(text).expect_err("must fail");
    assert!(
        matches!(e, Error::Parse { .. } | Error::Invalid { .. }),
        "{e:?}"
    );
    e.to_string()
}

#[test]
fn joint_variable_must_have_coefficient_one() {
    let m = err(&format!("{HEAD}theta = {{th1, 2*th2, th3}}\n"));
    assert!(m.starts_with("test.par:5:"), "{m}");
    assert!(
        m.contains("frame 2") && m.contains("coefficient 1") && m.contains("th2"),
        "{m}"
    );
}

#[test]
fn wrong_list_length_names_key_and_counts() {
    let m = err(&format!("{HEAD}\nd = {{0, 0.1}}\n"));
    assert!(m.starts_with("test.par:6:"), "{m}");
    assert!(m.contains("d has 2 entries, NF = 3 expected"), "{m}");
    let m = err(&format!("{HEAD}XX = {{1,2,3,4}}\n"));
    assert!(m.contains("XX has 4 entries, NL = 3 expected"), "{m}");
    let m = err(&format!("{HEAD}G = {{0,-9.81}}\n"));
    assert!(m.contains("G has 2 entries, 3 expected"), "{m}");
    let m = err(&format!("{HEAD}Z = {{1,0,0,1}}\n"));
    assert!(m.contains("Z has 4 entries, 16 expected"), "{m}");
}

#[test]
fn unknown_key_bad_expression_and_counts() {
    let m = err(&format!("{HEAD}foo = {{1,2,3}}\n"));
    assert!(
        m.starts_with("test.par:5:") && m.contains("unknown key `foo`"),
        "{m}"
    );
    let m = err(&format!("{HEAD}d = {{0, 0.1 +* 2, 0}}\n"));
    // column of the `*` on line 5: `d = {0, 0.1 +* 2` -> column 14
    assert!(m.starts_with("test.par:5:14:"), "{m}");
    assert!(m.contains("bad expression"), "{m}");
    let m = err("NL = 3\nNJ = 3\nNF = 4\n");
    assert!(
        m.starts_with("test.par:3:") && m.contains("2 NJ - NL = 3"),
        "{m}"
    );
    let m = err(&format!("(* never closed\n{HEAD}"));
    assert!(
        m.starts_with("test.par:1:") && m.contains("never closed"),
        "{m}"
    );
    let m = err(&format!("{HEAD}ant = {{0,2,1}}\n"));
    assert!(m.contains("test.par:5") && m.contains("a(2) = 2"), "{m}");
}

#[test]
fn values_missing_are_reported_by_symbol_and_line() {
    let text = format!("{HEAD}d = {{0, L2, 0}}\nM = {{1, 1, 1}}\n");
    let (d, map) = par::parse_description(&text, Some("test.par")).unwrap();
    let e = map.locate(Robot::new(d).unwrap_err()).to_string();
    // XX1.. are symbolic (no values) too; the first reported is frame 2's d
    assert!(e.starts_with("test.par:5:") && e.contains("`L2`"), "{e}");
}

#[test]
fn documented_example_is_the_bundled_sr400() {
    let doc = std::fs::read_to_string(robots().join("../docs/robot-format.md")).unwrap();
    // the complete example: the toml block that starts with the SR400's comment
    let start = doc
        .find("```toml\n# Acma SR400")
        .expect("the SR400 toml block")
        + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let r = toml_format::parse_robot(&doc[start..end], Some("robot-format.md")).unwrap();
    let e = torque_difference(&r, &load("sr400.toml"), 9);
    assert!(e == 0.0, "{e:e}");
}

#[test]
fn opensymoro_mobile_base_flexibility_and_floating() {
    // OpenSYMORO lists link 0 first when the base is mobile, and writes eta/k (NJ entries)
    let text = "NL = 2\nNJ = 2\nNF = 2\nType = 0\nis_floating = 0\nis_mobile = 1\n\
                M = {M0, 1, 2}\nMX = {0, 0.1, 0.2}\neta = {0, 0}\nk = {0, 0}\n\
                VP0 = {0, 0, 1}\n";
    let d = parse(text).unwrap();
    assert!(d.mobile_base);
    let m: Vec<String> = d
        .links
        .iter()
        .map(|l| l.params[param::M].to_string())
        .collect();
    assert_eq!(m, ["1", "2"]);
    assert!(
        d.notes.iter().any(|n| n.contains("link 0")),
        "{:?}",
        d.notes
    );
    // written back with the link-0 entry, read again identically
    let back = parse(&par::write_description(&d)).unwrap();
    assert_eq!(back.links, d.links);
    assert!(back.mobile_base);
    // the NL-entry form is accepted too
    let d2 = parse("NL = 2\nNJ = 2\nNF = 2\nis_mobile = 1\nM = {1, 2}\n").unwrap();
    assert_eq!(d2.links[1].params[param::M].to_string(), "2");
    // flexible joints are noted; a floating base reads link 0's parameters
    let d3 = parse("NL = 2\nNJ = 2\nNF = 2\neta = {1, 0}\nk = {k1, 0}\n").unwrap();
    assert!(
        d3.notes.iter().any(|n| n.contains("flexib")),
        "{:?}",
        d3.notes
    );
    let d4 = parse("NL = 2\nNJ = 2\nNF = 2\nis_floating = 1\nM = {M0, 1, 2}\n").unwrap();
    let base = d4.floating_base.as_ref().expect("a floating base");
    assert_eq!(base.params[param::M].to_string(), "M0");
    assert_eq!(d4.links[0].params[param::M].to_string(), "1");
    let back = parse(&par::write_description(&d4)).unwrap();
    assert_eq!(back, d4);
}

#[test]
fn latin1_symoro_files_load() {
    // SYMORO+ headers carry Latin-1 text ("Noë"); the loader falls back to Latin-1
    let dir = std::env::temp_dir().join(format!("robodyn_io_par_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("latin1.par");
    let mut bytes = b"(* 1 rue de la No".to_vec();
    bytes.push(0xeb);
    bytes.extend_from_slice(b" *)\nNL = 1\nNJ = 1\nNF = 1\nM = {2}\nZZ = {1}\n");
    for k in [
        "XX", "XY", "XZ", "YY", "YZ", "MX", "MY", "MZ", "IA", "FV", "FS",
    ] {
        bytes.extend_from_slice(format!("{k} = {{0}}\n").as_bytes());
    }
    std::fs::write(&p, bytes).unwrap();
    let r = robodyn::io::load(&p).unwrap();
    // a single revolute joint about the vertical: tau = ZZ qdd
    let tau = inverse_dynamics(&r, &[0.3], &[0.0], &[2.0]).unwrap();
    assert_eq!(tau[0], 2.0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn joint_variables_are_read_as_symoro_reads_them() {
    // SYMORO's theta entry of a revolute joint IS the joint variable: a number there is the
    // variable's value (the configuration the file describes), not an offset; a bare symbol
    // without a value is the variable whatever its name
    let text = format!("{HEAD}theta = {{0.3, th2 + a2, x3}}\n");
    let (d, map) = par::parse_description(&text, Some("test.par")).unwrap();
    assert!(d.frames[0].theta.is_zero(), "{}", d.frames[0].theta);
    assert_eq!(d.frames[1].theta.to_string(), "a2");
    assert!(d.frames[2].theta.is_zero());
    let w: Vec<String> = map.warnings.iter().map(|w| w.to_string()).collect();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("test.par:5: frame 1, theta:")
            && w[0].contains("q1 = 3/10")
            && w[0].contains("th1 + 3/10"),
        "{w:?}"
    );
    // a zero is the same under both readings: no warning
    let (_, map) = par::parse_description(&format!("{HEAD}theta = {{0, 0, 0}}\n"), None).unwrap();
    assert!(map.warnings.is_empty());
    // two symbols without values, neither named like a variable: which one moves is ambiguous
    let m = err(&format!("{HEAD}theta = {{a + b, 0, 0}}\n"));
    assert!(
        m.contains("several candidates") && m.contains("a, b"),
        "{m}"
    );
    // OpenSYMORO's Python booleans
    for (v, mobile) in [
        ("True", true),
        ("true", true),
        ("False", false),
        ("false", false),
        ("1", true),
        ("0", false),
    ] {
        let d = parse(&format!("{HEAD}is_mobile = {v}\nis_floating = False\n")).unwrap();
        assert_eq!(d.mobile_base, mobile, "{v}");
    }
    let m = err(&format!("{HEAD}is_mobile = yes\n"));
    assert!(m.starts_with("test.par:5:") && m.contains("0 or 1"), "{m}");
    let d = parse(&format!("{HEAD}is_floating = True\n")).unwrap();
    assert!(d.floating_base.is_some() && !d.mobile_base);
}

#[test]
fn joint_limits_travel_in_a_comment() {
    let d = parse(&format!(
        "{HEAD}(* robodyn limits q_min: 1 = -pi; 3 = -0.5 *)\n(* robodyn limits q_max: 1 = pi *)\n\
         (* robodyn limits qdd: 2 = 20 *)\n(* robodyn limits qd: 2 = 2.5 *)\n(* robodyn limits tau: 3 = 40 *)\n"
    ))
    .unwrap();
    let l1 = &d.limits[&1];
    assert_eq!(
        (l1.q_min, l1.q_max),
        (Some(-std::f64::consts::PI), Some(std::f64::consts::PI))
    );
    assert_eq!((d.limits[&2].qd, d.limits[&2].qdd), (Some(2.5), Some(20.0)));
    assert_eq!(
        (d.limits[&3].q_min, d.limits[&3].tau),
        (Some(-0.5), Some(40.0))
    );
    // written back as the same comments
    let (back, _) = par::parse_description(&par::write_description(&d), None).unwrap();
    assert_eq!(back.limits, d.limits);
    let m = err(&format!("{HEAD}(* robodyn limits qd: 2 = -1 *)\n"));
    assert!(
        m.starts_with("test.par:5:") && m.contains("positive"),
        "{m}"
    );
    let m = err(&format!("{HEAD}(* robodyn limits speed: 2 = 1 *)\n"));
    assert!(m.contains("`speed` is not one of"), "{m}");
    let m = err(&format!("{HEAD}(* robodyn limits tau: 9 = 1 *)\n"));
    assert!(m.contains("frame 9"), "{m}");
    let m = err(&format!(
        "{HEAD}(* robodyn limits q_min: 1 = 1 *)\n(* robodyn limits q_max: 1 = -1 *)\n"
    ));
    assert!(m.contains("not an interval"), "{m}");
}
