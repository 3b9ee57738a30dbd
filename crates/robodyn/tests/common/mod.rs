//! Bundled closed robots and the slider-crank fixture, shared by the closed-chain tests; the
//! check for the external programs some tests run (`crate::harness`).
#![allow(dead_code)]

use robodyn::Robot;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::PathBuf;

/// A bundled robot by file name.
pub fn robot(name: &str) -> Robot {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name);
    robodyn::io::load(&p).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Bundled closed robots: file, reference (q_a, q_p) where the loops close (the files'
/// `assembly`, zeros where a file gives none), random range of q_a around it.
pub const ROBOTS: &[(&str, &[f64], &[f64], f64)] = &[
    (
        "sr400.toml",
        &[0.0, 0.0, 0.0, 0.0, 0.0, FRAC_PI_2],
        &[PI, -FRAC_PI_2],
        0.5,
    ),
    ("fourbar.toml", &[0.0], &[0.0, 0.0], 1.0),
    ("fivebar.toml", &[0.0, 0.0], &[0.0, 0.0], 0.3),
    ("spatial_loop.toml", &[0.0], &[0.0; 5], 0.3),
    ("twoloops.toml", &[0.0], &[0.0; 4], 1.0),
];

/// Slider-crank with a PRISMATIC cut joint: crank 1 (0.1 m, actuated) and rod 2 (0.3 m) in the
/// plane z0 = 0, slider link 3 pinned to the rod; cut joint 4 is the slider's prismatic joint along
/// x0, its twin frame 5 fixed on the base. Assembled at q = 0 (crank along y0, sin beta = -1/3).
pub fn slider_crank() -> Robot {
    robodyn::io::toml_format::parse_robot(include_str!("../data/slider_crank.toml"), None).unwrap()
}

/// The bundled robots and the slider-crank: (label, robot, q_a0, q_p0, range).
pub type Loaded = (&'static str, Robot, &'static [f64], &'static [f64], f64);

pub fn cases() -> Vec<Loaded> {
    let mut v: Vec<_> = ROBOTS
        .iter()
        .map(|c| (c.0, robot(c.0), c.1, c.2, c.3))
        .collect();
    v.push(("slider-crank", slider_crank(), &[0.0], &[0.0, 0.0], 1.0));
    v
}

/// Whether an external program the tests run (GNU Octave, pdflatex) works here: `program args`
/// exits with success. Without it the optional check `key` (of `crate::harness::KEYS`) is
/// skipped visibly, or fails where `ROBODYN_REQUIRE` requires it (CI).
pub fn tool_available(program: &str, args: &[&str], key: &str, what: &str) -> bool {
    crate::harness::tool(key, program, args, what)
}
