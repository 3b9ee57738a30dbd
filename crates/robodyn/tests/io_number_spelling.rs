//! Numbers written as the user wrote them (issue 15, item 8): a `.par` or TOML writer gives a
//! value read as a decimal back as that decimal (`0.705`, never `141/200`), an integer as an
//! integer, and an exact rational or constant (`1/3`, `pi/2`) in its exact form. Every bundled
//! robot and every external SYMORO file (read in place) reads back to the same description, and
//! a file without `a/b` numbers is written without them.

use robodyn::io::{par, toml_format};
use robodyn::model::RobotDescription;
use std::path::{Path, PathBuf};

/// True when `text` holds a number fraction `a/b` (digits on both sides, not a name's digits:
/// `M3/4` is a division of a symbol, `141/200` a fraction).
fn has_fraction(text: &str) -> bool {
    let b = text.as_bytes();
    (1..b.len().saturating_sub(1)).any(|i| {
        if b[i] != b'/' || !b[i + 1].is_ascii_digit() || !b[i - 1].is_ascii_digit() {
            return false;
        }
        // the digits before `/` start a number (not the tail of a name such as M3)
        let mut k = i - 1;
        while k > 0 && b[k - 1].is_ascii_digit() {
            k -= 1;
        }
        k == 0 || !(b[k - 1].is_ascii_alphanumeric() || b[k - 1] == b'_' || b[k - 1] == b'.')
    })
}

/// Write as `.par` and TOML, read back: the same description, and no fraction in the text
/// unless the source had one. Returns the written texts.
fn round_trip(label: &str, d: &RobotDescription, source_has_fraction: bool) -> (String, String) {
    let p = par::write_description(d);
    let (mut back, _) = par::parse_description(&p, Some("back.par"))
        .unwrap_or_else(|e| panic!("{label}: {e}\n{p}"));
    // a .par has no transmission (tx40.toml's motor-joint coupling): compared without it
    back.transmission.clone_from(&d.transmission);
    // nor named frames ([[tool]], the body frames of URDF links)
    back.tools.clone_from(&d.tools);
    assert_eq!(&back, d, "{label}: .par round trip\n{p}");
    let t = toml_format::write_description(d);
    let (back, _) = toml_format::parse_description(&t, Some("back.toml"))
        .unwrap_or_else(|e| panic!("{label}: {e}\n{t}"));
    assert_eq!(&back, d, "{label}: TOML round trip\n{t}");
    if !source_has_fraction {
        assert!(
            !has_fraction(&p),
            "{label}: a fraction in the .par written\n{p}"
        );
        assert!(
            !has_fraction(&t),
            "{label}: a fraction in the TOML written\n{t}"
        );
    }
    // a second round trip writes the same text (the spelling is stable)
    assert_eq!(par::write_description(&back), p, "{label}");
    (p, t)
}

fn files(dir: &Path, ext: &[&str], out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, ext, out);
        } else if p.extension().is_some_and(|x| ext.iter().any(|e| x == *e)) {
            out.push(p);
        }
    }
}

#[test]
fn the_fraction_detector_tells_fractions_from_divided_names() {
    assert!(has_fraction("XX = {141/200,0}"));
    assert!(has_fraction("G = {0,0,-981/100}"));
    assert!(!has_fraction("alpha = {0,pi/2,-pi/2}"));
    assert!(!has_fraction("XX = {M3/4, d_2/10}"));
    assert!(!has_fraction("XX = {0.705,9.81}"));
}

#[test]
fn bundled_robots_keep_their_numbers() {
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots"));
    let mut all = Vec::new();
    files(dir, &["toml", "par", "urdf"], &mut all);
    all.sort();
    assert!(all.len() >= 12, "{all:?}");
    for f in &all {
        let src = std::fs::read_to_string(f).unwrap();
        let (d, _) = robodyn::io::load_description_mapped(f).unwrap();
        let label = f.file_name().unwrap().to_string_lossy().to_string();
        let (p, _) = round_trip(&label, &d, has_fraction(&src));
        // the decimals a TOML robot gives are written as those decimals in .par
        if label == "tx40.toml" {
            assert!(p.contains("M = {10.5,3.6,4.07,3.62,1.02,0.2}"), "{p}");
            assert!(p.contains("G = {0,0,-9.81}"), "{p}");
        }
    }
}

#[test]
fn external_symoro_files_keep_their_numbers() {
    let Some(dir) = common_shared() else { return };
    let mut all = Vec::new();
    files(&dir, &["par"], &mut all);
    all.sort();
    let mut checked = 0;
    for f in &all {
        // the files refused (floating base, inconsistent counts) are io_external's concern
        let Ok((d, _)) = robodyn::io::load_description_mapped(f) else {
            continue;
        };
        let src = String::from_utf8_lossy(&std::fs::read(f).unwrap()).into_owned();
        round_trip(&f.display().to_string(), &d, has_fraction(&src));
        checked += 1;
    }
    assert!(checked >= 30, "{checked} external files");
}

fn common_shared() -> Option<PathBuf> {
    crate::harness::shared(
        "cases/external",
        "number spelling of the external .par files",
    )
}

/// Each spelling class written back as it was read: decimals, integers, exact fractions,
/// multiples of pi, a float with more digits than a short decimal.
#[test]
fn each_spelling_class_is_kept() {
    let par_text = "(* Robotname = 'spelling' *)\nNL = 2\nNJ = 2\nNF = 2\nType = 0\n\
        ant = {0,1}\nsigma = {0,0}\nmu = {1,1}\ngamma = {0,0}\nb = {0,0}\n\
        alpha = {0,pi/2}\nd = {0,0.705}\ntheta = {th1,th2 + 2*pi/3}\nr = {1/3,0}\n\
        XX = {0.25,1/4}\nXY = {0,0}\nXZ = {0,0}\nYY = {0,0}\nYZ = {0,0}\nZZ = {3,1.2345678912345}\n\
        MX = {0,0}\nMY = {0,0}\nMZ = {0,0}\nM = {2.5,1e-3}\nIA = {0,0}\nFV = {0,0}\nFS = {0,0}\n\
        G = {0,0,-9.81}\n";
    let (d, _) = par::parse_description(par_text, Some("spelling.par")).unwrap();
    let (p, t) = round_trip("spelling.par", &d, true);
    for (key, want) in [
        ("alpha", "{0,pi/2}"),
        ("d", "{0,0.705}"),
        ("theta", "{th1,2*pi/3 + th2}"),
        ("r", "{1/3,0}"),
        // 1/4 is the same exact number as 0.25: written as the decimal
        ("XX", "{0.25,0.25}"),
        ("ZZ", "{3,1.2345678912345}"),
        ("M", "{2.5,0.001}"),
        ("G", "{0,0,-9.81}"),
    ] {
        assert!(p.contains(&format!("\n{key} = {want}\n")), "{key}: {p}");
    }
    for line in [
        "alpha = \"pi/2\"",
        "d = 0.705",
        "r = \"1/3\"",
        "XX = 0.25",
        "ZZ = 1.2345678912345",
        "gravity = [0, 0, -9.81]",
    ] {
        assert!(t.contains(line), "{line}: {t}");
    }
}
