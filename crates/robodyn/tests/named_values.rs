//! Values given by name (`robodyn::io::set_values`, the rule of the CLI's `--set` and of the
//! Python package): symbols, and standard parameters a file writes as numbers (a URDF's mass of
//! link 3 is `M3`); unknown names refused with the known ones, nothing changed then. And the
//! URDF reader's warning for a legged robot loaded with a fixed base.

use robodyn::algorithms::base_parameters::ParameterNames;
use robodyn::io::{load_description, set_values};
use robodyn::{Error, Robot};
use std::collections::BTreeMap;
use std::path::PathBuf;

fn file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name)
}

fn values(v: &[(&str, f64)]) -> BTreeMap<String, f64> {
    v.iter().map(|(k, x)| (k.to_string(), *x)).collect()
}

#[test]
fn urdf_standard_parameters_are_set_by_name() {
    let mut d = load_description(file("rx90.urdf")).unwrap();
    let before = Robot::new(d.clone()).unwrap().standard_parameters();
    let names = ParameterNames::of(&d);
    set_values(&mut d, &values(&[("M3", 100.0), ("FS2", 0.7)])).unwrap();
    assert!(d.symbols.is_empty(), "no symbol added: {:?}", d.symbols);
    assert_eq!(ParameterNames::of(&d), names, "no parameter renamed (M3_)");
    let after = Robot::new(d).unwrap().standard_parameters();
    let changed: Vec<(&str, f64)> = (0..before.len())
        .filter(|&k| before[k] != after[k])
        .map(|k| (names.name(k), after[k]))
        .collect();
    assert_eq!(changed, vec![("FS2", 0.7), ("M3", 100.0)]);
}

#[test]
fn symbols_are_set_and_unknown_names_refused() {
    let mut d = load_description(file("rx90.toml")).unwrap();
    set_values(&mut d, &values(&[("D3", 0.5)])).unwrap();
    assert_eq!(d.symbols["D3"], 0.5);
    let kept = d.clone();
    let e = set_values(&mut d, &values(&[("RL4", 0.3), ("d3", 0.5)])).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, Error::Input(_)), "{e:?}");
    assert!(
        msg.contains("no symbol `d3`")
            && msg.contains("did you mean `D3`")
            && msg.contains("D3, G3, RL4")
            && msg.contains("M<j>"),
        "{msg}"
    );
    assert_eq!(d, kept, "nothing changes when a name is unknown");
    let e = set_values(&mut d, &values(&[("D3", f64::NAN)])).unwrap_err();
    assert!(e.to_string().contains("not a finite number"), "{e}");
    // the loaders apply the same rule
    let e = robodyn::io::load_with(file("rx90.urdf"), &values(&[("FOO", 1.0)])).unwrap_err();
    assert!(e.to_string().contains("no symbol `FOO`"), "{e}");
    let r = robodyn::io::load_with(file("rx90.urdf"), &values(&[("M3", 7.0)])).unwrap();
    assert_eq!(r.standard_parameters()[13 * 2 + 9], 7.0);
}

const LEG: &str = r#"<robot name="legs"><link name="{base}"><inertial><mass value="2"/>
  <inertia ixx="0.1" iyy="0.1" izz="0.1"/></inertial></link>
  <link name="{a}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/></inertial></link>
  <link name="{b}"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/></inertial></link>
  <joint name="ja" type="revolute"><parent link="{base}"/><child link="{a}"/><axis xyz="0 1 0"/></joint>
  <joint name="jb" type="revolute"><parent link="{base}"/><child link="{b}"/><axis xyz="0 1 0"/></joint>
</robot>"#;

fn warnings_of(base: &str, a: &str, b: &str) -> Vec<String> {
    let text = LEG
        .replace("{base}", base)
        .replace("{a}", a)
        .replace("{b}", b);
    let (_, map) = robodyn::io::urdf::parse_description(&text, Some("legs.urdf")).unwrap();
    map.warnings.iter().map(|w| w.to_string()).collect()
}

#[test]
fn a_legged_urdf_says_its_base_is_held_fixed() {
    let w = warnings_of("trunk", "lf_foot", "RF_FOOT");
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(
        w[0].starts_with("legs.urdf:1: robot: links `lf_foot`, `RF_FOOT` look like the feet")
            && w[0].contains("root link `trunk` as a fixed base"),
        "{}",
        w[0]
    );
    assert_eq!(warnings_of("base", "left_sole_link", "ankle2_1").len(), 1);
    // one foot-like name, or `footprint`, `TorsoLeft` (not words foot, sole): no warning
    assert!(warnings_of("base_footprint", "lf_foot", "arm").is_empty());
    assert!(warnings_of("base", "TorsoLeftLink", "footprint_2").is_empty());
}
