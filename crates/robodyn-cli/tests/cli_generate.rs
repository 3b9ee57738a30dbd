//! `robodyn generate` end to end on a closed chain whose G depends on q (the bundled five-bar):
//! the generated Python W and Gamma_cl, run on the closed state that `robodyn closure` returns,
//! agree with the CLI's own `closure --jacobian` and closed-chain `idm` (Python with NumPy
//! needed; CI installs it with Pinocchio). Bad requests give one clear error.

mod common;

use common::{octave_available, octave_eval, robot, run, tmp};
use std::process::Command;

/// Run a generated Python function `name` with the given argument vectors; its outputs.
pub(crate) fn run_python(file: &std::path::Path, name: &str, args: &[Vec<f64>]) -> Vec<f64> {
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

/// `--model dgm` and `--model jacobian` with `--frame` and `--reference`, run as generated
/// Python (numeric RX-90): 0T3 3T6 = 0T6, and the local Jacobian 6J6 equals central differences
/// of the generated 0T6 (d0P6/dq and d0A6/dq 0A6^T, rotated into frame 6).
#[test]
fn generated_dgm_and_jacobian_fit_together() {
    if !crate::harness::numpy("generated DGM and Jacobian not executed") {
        return;
    }
    let rx90 = robot("rx90.toml");
    let gen = |tag: &str, extra: &[&str]| {
        let file = tmp("generate_kin", &format!("{tag}.py"));
        let mut args = vec![
            "generate",
            &rx90,
            "--numeric",
            "--lang",
            "python",
            "--name",
            tag,
            "--output",
            file.to_str().unwrap(),
        ];
        args.extend(extra);
        run(&args);
        file
    };
    let t06 = gen("t06", &["--model", "dgm"]);
    let t03 = gen("t03", &["--model", "dgm", "--frame", "3"]);
    let t36 = gen(
        "t36",
        &["--model", "dgm", "--reference", "3", "--frame", "6"],
    );
    let j66 = gen("j66", &["--model", "jacobian", "--reference", "local"]);
    // [s n a P] column by column -> (rotation, position)
    let split = |v: Vec<f64>| {
        (
            nalgebra::Matrix3::from_column_slice(&v[..9]),
            nalgebra::Vector3::from_column_slice(&v[9..]),
        )
    };
    let q = vec![0.3, -0.7, 1.1, 0.4, -1.3, 2.0];
    let dgm = |file: &std::path::Path, name: &str, q: &[f64]| {
        split(run_python(file, name, &[q.to_vec()]))
    };
    let (a06, p06) = dgm(&t06, "t06", &q);
    let (a03, p03) = dgm(&t03, "t03", &q);
    let (a36, p36) = dgm(&t36, "t36", &q);
    assert!((a03 * a36 - a06).amax() < 1e-12 && (p03 + a03 * p36 - p06).amax() < 1e-12);
    let jac = run_python(&j66, "j66", std::slice::from_ref(&q));
    let h = 1e-6;
    for c in 0..6 {
        let at = |d: f64| {
            let mut x = q.clone();
            x[c] += d;
            dgm(&t06, "t06", &x)
        };
        let ((ap, pp), (am, pm)) = (at(h), at(-h));
        let v = a06.transpose() * (pp - pm) / (2.0 * h);
        // skew(6w) = 6A0 (d0A6/dq 0A6^T) 0A6 = 0A6^T d0A6/dq
        let ws = a06.transpose() * ((ap - am) / (2.0 * h));
        let w_local = nalgebra::Vector3::new(ws[(2, 1)], ws[(0, 2)], ws[(1, 0)]);
        for r in 0..3 {
            assert!((jac[r * 6 + c] - v[r]).abs() < 1e-7, "linear {r} {c}");
            assert!(
                (jac[(r + 3) * 6 + c] - w_local[r]).abs() < 1e-7,
                "angular {r} {c}"
            );
        }
    }
}

/// Frame choices the model cannot take are one clear error each.
#[test]
fn frame_flags_are_checked() {
    let err = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_robodyn"))
            .args(args)
            .output()
            .unwrap();
        assert_ne!(out.status.code(), Some(0), "{args:?}");
        let e = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(!e.contains("panicked"), "{e}");
        e
    };
    let rx90 = robot("rx90.toml");
    let torso = robot("torso2arms.toml");
    let e = err(&["generate", &rx90, "--model", "idm", "--frame", "3"]);
    assert!(e.contains("--model dgm and jacobian"), "{e}");
    let e = err(&["generate", &torso, "--model", "dgm"]);
    assert!(
        e.contains("2 terminal links (4 `l_elbow`, 7 `r_elbow`)") && e.contains("--frame J"),
        "{e}"
    );
    let e = err(&["generate", &rx90, "--model", "jacobian", "--frame", "9"]);
    assert!(e.contains("not a frame"), "{e}");
    let e = err(&[
        "generate",
        &rx90,
        "--model",
        "jacobian",
        "--reference",
        "world",
    ]);
    assert!(e.contains("`local`"), "{e}");
}

/// `--frame` by name: a URDF joint or link names the frame of that number (the same generated
/// text); an unknown name and a tool are clear errors.
#[test]
fn generate_frame_by_name_is_the_frame_number() {
    let rx90 = robot("rx90.urdf");
    let gen = |f: &str| {
        Command::new(env!("CARGO_BIN_EXE_robodyn"))
            .args([
                "generate",
                &rx90,
                "--numeric",
                "--model",
                "dgm",
                "--frame",
                f,
            ])
            .output()
            .unwrap()
    };
    let text = |f: &str| {
        let out = gen(f);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let three = text("3");
    assert!(!three.is_empty());
    assert_eq!(text("elbow"), three, "joint name");
    assert_eq!(text("link3"), three, "link name");
    assert_ne!(text("link4"), three);
    let out = gen("elbw");
    assert_eq!(out.status.code(), Some(1));
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(e.contains("elbw") && e.contains("link3"), "{e}");
}
