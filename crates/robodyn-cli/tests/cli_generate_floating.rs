//! `robodyn generate` on floating-base robots (issue 27): the inverse dynamic model of OpenSYMORO's
//! `rx90float.par` (`is_floating = 1`), of the bundled `rx90float.toml` (`base = "floating"`) and
//! of a URDF with `--floating` (the library's test URDF with fixed frames), written as Python by the CLI and run
//! on random floating states, against the library's numeric `inverse_dynamics` of the same
//! robot (base wrench then joint torques, 1e-10 relative); the text form names the base's
//! quantities; the other models refuse a floating robot by name.

mod common;

use common::{fails, robot, run, tmp};
use robodyn::nalgebra::{UnitQuaternion, Vector3};
use std::collections::BTreeMap;

/// Deterministic floating states: q (nq) with a unit quaternion, qd and qdd (nv).
fn state(k: usize, nq: usize) -> [Vec<f64>; 3] {
    let f = |i: usize, s: f64| ((i * 7 + k * 13) as f64 * 0.37 + s).sin();
    let mut q: Vec<f64> = (0..nq).map(|i| f(i, 0.1)).collect();
    let quat = UnitQuaternion::from_scaled_axis(Vector3::new(f(1, 0.5), f(2, 0.9), f(3, 1.3)));
    q[3..7].copy_from_slice(&[quat.i, quat.j, quat.k, quat.w]);
    let v = (0..nq - 1).map(|i| 2.0 * f(i, 0.7)).collect();
    let a = (0..nq - 1).map(|i| 3.0 * f(i, 1.9)).collect();
    [q, v, a]
}

/// Generate `args` as numeric Python (function `name`), run it on three states and compare with
/// the library's inverse dynamics of `robot`.
fn check_generated(args: &[&str], name: &str, robot: &robodyn::Robot) {
    let file = tmp("generate_floating", &format!("{name}.py"));
    let mut all = vec!["generate"];
    all.extend_from_slice(args);
    all.extend([
        "--numeric",
        "--lang",
        "python",
        "--name",
        name,
        "--output",
        file.to_str().unwrap(),
    ]);
    run(&all);
    if !crate::harness::numpy("generated floating Python not executed") {
        return;
    }
    for k in 0..3 {
        let [q, v, a] = state(k, robot.nq());
        let got = crate::cli_generate::run_python(&file, name, &[q.clone(), v.clone(), a.clone()]);
        let want = robodyn::inverse_dynamics(robot, &q, &v, &a).unwrap();
        assert_eq!(got.len(), robot.nv(), "{name}: nv outputs");
        let scale = want.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        for (g, w) in got.iter().zip(want.iter()) {
            assert!((g - w).abs() <= 1e-10 * scale, "{name}: {g} vs {w}");
        }
    }
}

#[test]
fn generated_floating_idm_agrees_with_the_library() {
    let toml = robot("rx90float.toml");
    let values: BTreeMap<String, f64> = [("G3".to_string(), -9.81)].into_iter().collect();
    let rx = robodyn::io::load_with(&toml, &values).unwrap();
    check_generated(&[&toml, "--set", "G3=-9.81"], "rxf", &rx);
    if let Some(dir) = crate::harness::find_shared("cases/external/symoro-robots") {
        // OpenSYMORO's file with its symbols given on the command line
        let par = dir.join("rx90float.par");
        let d = robodyn::io::load_description(&par).unwrap();
        let values: BTreeMap<String, f64> = d
            .used_symbols()
            .into_iter()
            .enumerate()
            .map(|(k, s)| {
                let x = match s.as_str() {
                    "GX" => 1.0,
                    "GY" => -2.0,
                    "GZ" => -9.0,
                    _ => 0.2 + 0.01 * k as f64,
                };
                (s, x)
            })
            .collect();
        let sets: Vec<String> = values.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let mut args = vec![par.to_str().unwrap()];
        for s in &sets {
            args.extend(["--set", s.as_str()]);
        }
        let r = robodyn::io::load_with(&par, &values).unwrap();
        check_generated(&args, "rxfpar", &r);
    }
    // a URDF made floating on the command line: its root link is the base body, its fixed
    // frames folded into the base and the links
    let urdf = format!(
        "{}/../robodyn/tests/data/fixed_frames.urdf",
        env!("CARGO_MANIFEST_DIR")
    );
    let r = robodyn::io::load_with_options(
        &urdf,
        &BTreeMap::new(),
        &robodyn::io::LoadOptions::floating(),
    )
    .unwrap();
    assert!(r.is_floating());
    check_generated(&[&urdf, "--floating"], "urdff", &r);
}

/// The text form of the OpenSYMORO file: the base's inputs and outputs by name, link 0's
/// parameters as symbols; the other models are refused, naming the one that is generated.
#[test]
fn floating_text_model_and_refusals() {
    let toml = robot("rx90float.toml");
    let text = run(&["generate", &toml]);
    for name in [
        "QW0", "V10", "W30", "DV10", "WP30", "E10", "N30", "GAM6", "M0", "MZ0",
    ] {
        assert!(text.contains(name), "{name} missing:\n{text}");
    }
    assert!(text.contains("multiplications"), "{text}");
    for model in ["inertia", "h", "ddm", "idm-derivatives"] {
        let err = fails(&["generate", &toml, "--model", model]);
        assert!(
            err.contains("floating base") && err.contains("`idm`") && !err.contains("panicked"),
            "{model}: {err}"
        );
    }
    let err = fails(&["generate", &toml, "--params", "base"]);
    assert!(
        err.contains("floating") && !err.contains("panicked"),
        "{err}"
    );
}
