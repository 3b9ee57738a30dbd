//! `robodyn generate` end to end on a closed chain whose G depends on q (the bundled five-bar):
//! the generated Python W and Gamma_cl, run on the closed state that `robodyn closure` returns,
//! agree with the CLI's own `closure --jacobian` and closed-chain `idm` (Python with NumPy
//! needed; CI installs it with Pinocchio). Bad requests give one clear error.

mod common;

use common::{octave_available, octave_eval, robot, run, tmp};
use std::process::Command;

/// Run a generated Python function `name` with the given argument vectors; its outputs.
fn run_python(file: &std::path::Path, name: &str, args: &[Vec<f64>]) -> Vec<f64> {
    let list: Vec<String> = args
        .iter()
        .map(|a| {
            let v: Vec<String> = a.iter().map(|x| format!("{x:e}")).collect();
            format!("np.array([{}])", v.join(", "))
        })
        .collect();
    let script = format!(
        "exec(open({:?}).read())\nprint(' '.join(repr(float(x)) for x in {name}({})))",
        file.display().to_string(),
        list.join(", ")
    );
    let out = Command::new("python3")
        .args(["-c", &script])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "python: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

#[test]
fn generated_closed_models_agree_with_the_cli() {
    let fivebar = robot("fivebar.toml");
    let (qa, qdda) = ([0.1, 0.2], [1.0, -2.0]);
    let closure: serde_json::Value = serde_json::from_str(&run(&[
        "closure",
        &fivebar,
        "--qa",
        "0.1,0.2",
        "--jacobian",
        "--format",
        "json",
    ]))
    .unwrap();
    let get = |group: &str, j: usize| closure[group][format!("q{j}")].as_f64();
    // actuated joints 1 and 3, passive 2 and 4 (tree joints 1..4)
    let q: Vec<f64> = (1..=4)
        .map(|j| get("q_a", j).or_else(|| get("q_p", j)).unwrap())
        .collect();
    assert_eq!((q[0], q[2]), (qa[0], qa[1]));
    let w: Vec<Vec<f64>> = closure["W"]["values"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            r.as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_f64().unwrap())
                .collect()
        })
        .collect();
    if !crate::harness::numpy("generated Python not executed") {
        return;
    }
    let out = tmp("generate", "fivebar.py");
    let out_s = out.to_str().unwrap();
    run(&[
        "generate",
        &fivebar,
        "--model",
        "w",
        "--lang",
        "python",
        "--numeric",
        "--name",
        "w5",
        "--output",
        out_s,
    ]);
    let wg = run_python(&out, "w5", std::slice::from_ref(&q));
    // W2_1 W2_3 W4_1 W4_3: passive rows, actuated columns, as `closure` prints W
    let flat: Vec<f64> = w.iter().flatten().copied().collect();
    for (a, b) in wg.iter().zip(&flat) {
        assert!(
            (a - b).abs() < 1e-9 * (1.0 + b.abs()),
            "W {wg:?} vs {flat:?}"
        );
    }
    assert_eq!(wg.len(), 4);
    // Gamma_cl at qd = 0 (then qdd_p = W qdd_a, eq 10.42 without Psi)
    let qdd = vec![
        qdda[0],
        w[0][0] * qdda[0] + w[0][1] * qdda[1],
        qdda[1],
        w[1][0] * qdda[0] + w[1][1] * qdda[1],
    ];
    run(&[
        "generate",
        &fivebar,
        "--model",
        "closed",
        "--lang",
        "python",
        "--numeric",
        "--name",
        "gcl5",
        "--output",
        out_s,
    ]);
    let g = run_python(&out, "gcl5", &[q, vec![0.0; 4], qdd]);
    let idm: serde_json::Value = serde_json::from_str(&run(&[
        "idm", &fivebar, "--q", "0.1,0.2", "--qd", "0,0", "--qdd", "1,-2", "--format", "json",
    ]))
    .unwrap();
    let expected = [
        idm[0]["tau1"].as_f64().unwrap(),
        idm[0]["tau3"].as_f64().unwrap(),
    ];
    for (a, b) in g.iter().zip(&expected) {
        assert!(
            (a - b).abs() < 1e-9 * (1.0 + b.abs()),
            "Gamma_cl {g:?} vs idm {expected:?}"
        );
    }
    assert_eq!(g.len(), 2);
}

#[test]
fn closed_models_of_a_tree_are_refused() {
    let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["generate", &robot("rx90.toml"), "--model", "w"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("closed loops"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// `--lang matlab --output DIR/NAME.m` writes a function file whose function is NAME (MATLAB
/// calls it by its file name); run by GNU Octave it gives the torques of `robodyn idm`. An output
/// name that is no MATLAB identifier, or a `--name` other than the file's, is one clear error.
#[test]
fn generated_matlab_function_file_agrees_with_idm() {
    let rx90 = robot("rx90.toml");
    let file = tmp("generate_m", "rx90_cli.m");
    let file_s = file.to_str().unwrap();
    run(&[
        "generate",
        &rx90,
        "--lang",
        "matlab",
        "--numeric",
        "--output",
        file_s,
    ]);
    let code = std::fs::read_to_string(&file).unwrap();
    assert!(
        code.contains("function out = rx90_cli(q, qd, qdd)"),
        "{code}"
    );
    for (args, why) in [
        (vec!["--output", "9lives.m"], "MATLAB identifier"),
        (vec!["--output", file_s, "--name", "other"], "file name"),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
            .args(["generate", &rx90, "--lang", "matlab"])
            .args(&args)
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(why) && !err.contains("panicked"), "{err}");
    }
    if !octave_available() {
        return;
    }
    let (q, qd, qdd) = (
        "0.1,0.2,0.3,0.4,0.5,0.6",
        "1,-1,0.5,0.3,-0.2,0.7",
        "0.3,0.1,-0.4,1,2,-1",
    );
    let call = format!("printf('%.17g ', rx90_cli([{q}], [{qd}], [{qdd}]))");
    let got: Vec<f64> = octave_eval(file.parent().unwrap(), &call)
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    let idm: serde_json::Value = serde_json::from_str(&run(&[
        "idm", &rx90, "--q", q, "--qd", qd, "--qdd", qdd, "--format", "json",
    ]))
    .unwrap();
    assert_eq!(got.len(), 6, "{got:?}");
    for (j, g) in got.iter().enumerate() {
        let e = idm[0][format!("tau{}", j + 1)].as_f64().unwrap();
        assert!(
            (g - e).abs() < 1e-9 * (1.0 + e.abs()),
            "tau{}: {g} vs {e}",
            j + 1
        );
    }
}
