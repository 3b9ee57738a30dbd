//! Bundled closed robots and the slider-crank fixture, shared by the closed-chain tests; the
//! check for the external programs some tests run (`crate::harness`).
#![allow(dead_code)]

use robodyn::Robot;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::PathBuf;

pub mod pinocchio;

/// Largest gap between each cut frame and its twin (rotation and position) at a solution, from
/// the geometric model 0T_j (frames 1..NJ with the cut-joint variables).
pub fn closure_gap(
    r: &Robot,
    cc: &robodyn::ClosedChain,
    s: &robodyn::algorithms::closed_chain::ClosureSolution,
) -> f64 {
    let t = robodyn::geometry::frame_transforms_with_cuts(r, s.q_tree.as_slice(), s.q_c.as_slice())
        .expect("a solution's state");
    cc.loops()
        .iter()
        .map(|l| {
            let (k, tw) = (l.topology.cut, l.topology.twin);
            (t[k - 1].rot - t[tw - 1].rot)
                .amax()
                .max((t[k - 1].pos - t[tw - 1].pos).amax())
        })
        .fold(0.0, f64::max)
}

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

/// The Python interpreter of the optional checks (`ROBODYN_PYTHON`, default `python3`).
pub fn python() -> String {
    std::env::var("ROBODYN_PYTHON").unwrap_or_else(|_| "python3".into())
}

/// The example-robot-data `robots` folder (installed with Pinocchio), or None after a visible
/// skip of the optional check `pinocchio` saying `what` is not checked.
pub fn example_robot_data(what: &str) -> Option<PathBuf> {
    let out = std::process::Command::new(python())
        .args([
            "-c",
            "import pinocchio, cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(\
             cmeel.__file__)), 'cmeel.prefix', 'share', 'example-robot-data', 'robots'))",
        ])
        .output();
    let found = match out {
        Ok(o) if o.status.success() => {
            let p = PathBuf::from(String::from_utf8_lossy(&o.stdout).trim());
            p.is_dir().then_some(p)
        }
        _ => None,
    };
    if found.is_none() {
        crate::harness::skip(
            "pinocchio",
            &format!(
                "pinocchio / example-robot-data not found (pip install pin example-robot-data): \
                 {what}"
            ),
        );
    }
    found
}

/// A file by name anywhere under `dir`.
pub fn find_file(dir: &std::path::Path, name: &str) -> Option<PathBuf> {
    for e in std::fs::read_dir(dir).ok()?.flatten() {
        let p = e.path();
        if p.is_dir() {
            if let Some(f) = find_file(&p, name) {
                return Some(f);
            }
        } else if p.file_name().is_some_and(|f| f == name) {
            return Some(p);
        }
    }
    None
}
