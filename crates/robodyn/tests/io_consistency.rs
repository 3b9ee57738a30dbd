//! Physical consistency at load (issue 30.4): one definition, the pseudo-inertia (density
//! realizability), shared by the loader's warnings and identification; a link whose inertia about
//! its centre of mass is positive definite but violates a triangle inequality is reported with
//! its file, line, link and the inequality with its numbers; `--set`-style values are checked.

use robodyn::model::inertial::{body_inconsistency, pseudo_inertia};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// The SCARA file with link 4 replaced: M = 2, centre of mass c = (0.1, 0, -0.05), inertia
/// about it diag(`ixx`, 0.2, 0.5) in R_4, written as standard parameters about O_4.
fn scara_with_link4(ixx: &str) -> String {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/scara.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let cut = text.rfind("[[link]]").unwrap();
    // J = J_G + M (c'c I - c c'): c'c = 0.0125; XX = ixx + 2 (0.0125 - 0.01), YY = 0.2 + 0.025,
    // ZZ = 0.5 + 2 (0.0125 - 0.0025), XZ = -2 (0.1)(-0.05) = 0.01
    format!(
        "{}[[link]]\nj = 4\nXX = \"{ixx} + 0.005\"\nXY = 0\nXZ = 0.01\nYY = 0.225\nYZ = 0\n\
         ZZ = 0.52\nMX = 0.2\nMY = 0\nMZ = -0.1\nM = 2\n",
        &text[..cut]
    )
}

fn write(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("robodyn-consistency-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn a_positive_definite_inertia_violating_a_triangle_inequality_is_reported_at_load() {
    let path = write("triangle.toml", &scara_with_link4("IXX4"));
    let text = std::fs::read_to_string(&path).unwrap();
    let path = write(
        "triangle.toml",
        &text.replace("[symbols]\n", "[symbols]\nIXX4 = 0.1\n"),
    );
    let (desc, map) = robodyn::io::load_description_mapped(&path).unwrap();
    // the inertia about the centre of mass is positive definite (0.1, 0.2, 0.5)...
    let w: Vec<String> = map.warnings.iter().map(|w| w.to_string()).collect();
    // the line of the link's `[[link]]` header
    let line = 1 + std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .collect::<Vec<_>>()
        .iter()
        .rposition(|l| *l == "[[link]]")
        .unwrap();
    let expected = format!(
        "{}:{}: link 4: Ixx + Iyy < Izz at the centre of mass (0.1 + 0.2 < 0.5)",
        path.display(),
        line
    );
    assert!(
        w.iter().any(|w| w.starts_with(&expected)),
        "expected `{expected}` in {w:#?}"
    );
    assert_eq!(w.len(), 1, "{w:#?}");
    // ... the pseudo-inertia of link 4 is not PSD (the one definition), and the robot still
    // loads (a warning: base-parameter files are not bodies on purpose)
    let env = |s: &str| desc.symbols.get(s).copied();
    let p: Vec<f64> = desc.links[3].params[..10]
        .iter()
        .map(|e| e.eval(&env).unwrap())
        .collect();
    assert!(pseudo_inertia(&p).symmetric_eigenvalues().min() < -1e-3);
    assert!(body_inconsistency(&p).is_some());
    assert!(robodyn::Robot::new(desc).is_ok());
}

/// A value given at load (the CLI's `--set`) is checked: the file's 0.35 is a body, 0.1 is
/// not; and the other way round, a fixed value clears the warning.
#[test]
fn values_given_at_load_are_checked() {
    let text = scara_with_link4("IXX4").replace("[symbols]\n", "[symbols]\nIXX4 = 0.35\n");
    let path = write("given.toml", &text);
    let (_, map) = robodyn::io::load_description_mapped(&path).unwrap();
    assert!(map.warnings.is_empty(), "{:?}", map.warnings);
    let set = BTreeMap::from([("IXX4".to_string(), 0.1)]);
    let (_, map) = robodyn::io::load_description_with(&path, &set).unwrap();
    assert_eq!(map.warnings.len(), 1, "{:?}", map.warnings);
    assert!(map.warnings[0].to_string().contains("Ixx + Iyy < Izz"));
    let (_, warnings) = robodyn::io::load_with_warnings(&path, &set).unwrap();
    assert_eq!(warnings.len(), 1);
    // a bad file value fixed at load leaves no warning
    let bad = write(
        "bad.toml",
        &scara_with_link4("IXX4").replace("[symbols]\n", "[symbols]\nIXX4 = 0.1\n"),
    );
    let fixed = BTreeMap::from([("IXX4".to_string(), 0.35)]);
    let (_, map) = robodyn::io::load_description_with(&bad, &fixed).unwrap();
    assert!(map.warnings.is_empty(), "{:?}", map.warnings);
}

/// Every bundled robot is a set of bodies (the check does not cry wolf).
#[test]
fn bundled_robots_are_consistent() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots");
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        let (_, map) = robodyn::io::load_description_mapped(&p).unwrap();
        let physical: Vec<_> = map
            .warnings
            .iter()
            .filter(|w| w.message.contains("centre of mass") || w.message.contains("negative"))
            .collect();
        assert!(physical.is_empty(), "{}: {physical:?}", p.display());
    }
}
