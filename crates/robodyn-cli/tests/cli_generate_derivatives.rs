//! `robodyn generate --model idm-derivatives`: the generated Python of the RX-90 (numeric) run
//! with NumPy equals `robodyn idm --derivatives` (the numeric analytical derivatives) at one
//! state, block by block in the documented layout (three N x N blocks, column-major); the
//! operation counts are printed like the other models'.

use std::process::Command;

mod common;
use common::{robot, run, tmp};

#[test]
fn generated_python_derivatives_equal_idm_derivatives() {
    let file = robot("rx90.toml");
    let (q, qd, qdd) = (
        [0.3, -0.8, 1.1, 0.4, -0.6, 0.9],
        [0.7, -0.2, 0.4, -0.9, 0.3, 0.5],
        [-1.0, 2.0, 0.5, 1.5, -3.0, 0.2],
    );
    let out = tmp("generate_derivatives", "rx90_d.py");
    let output = Command::new(env!("CARGO_BIN_EXE_robodyn"))
        .args(["generate", &file, "--model", "idm-derivatives", "--numeric"])
        .args(["--lang", "python", "--name", "rx90_d", "--output"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("rx90_d: ") && stderr.contains(" multiplications, "),
        "{stderr}"
    );
    let code = std::fs::read_to_string(&out).unwrap();
    assert!(
        code.contains("Operations: "),
        "operation counts in the header"
    );
    if !crate::harness::numpy("generated Python derivatives not executed") {
        return;
    }
    let arr = |v: &[f64]| {
        let s: Vec<String> = v.iter().map(|x| format!("{x:e}")).collect();
        format!("np.array([{}])", s.join(", "))
    };
    let script = format!(
        "exec(open({:?}).read())\nprint(' '.join(repr(float(x)) for x in rx90_d({}, {}, {})))",
        out.display().to_string(),
        arr(&q),
        arr(&qd),
        arr(&qdd)
    );
    let py = Command::new("python3")
        .args(["-c", &script])
        .output()
        .unwrap();
    assert!(
        py.status.success(),
        "{}",
        String::from_utf8_lossy(&py.stderr)
    );
    let got: Vec<f64> = String::from_utf8(py.stdout)
        .unwrap()
        .split_whitespace()
        .map(|t| t.parse().unwrap())
        .collect();
    assert_eq!(got.len(), 3 * 36);
    let l = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(",")
    };
    let json: serde_json::Value = serde_json::from_str(&run(&[
        "idm",
        &file,
        "--derivatives",
        "--q",
        &l(&q),
        "--qd",
        &l(&qd),
        "--qdd",
        &l(&qdd),
        "--format",
        "json",
    ]))
    .unwrap();
    for (b, key) in ["dtau_dq", "dtau_dqd", "A"].iter().enumerate() {
        let rows: Vec<Vec<f64>> = serde_json::from_value(json[key].clone()).unwrap();
        let scale = rows.iter().flatten().fold(1.0f64, |m, x| m.max(x.abs()));
        for (i, row) in rows.iter().enumerate() {
            for (k, x) in row.iter().enumerate() {
                let g = got[b * 36 + k * 6 + i];
                assert!(
                    (g - x).abs() < 1e-9 * scale,
                    "{key}[{i}][{k}]: generated {g} vs idm --derivatives {x}"
                );
            }
        }
    }
}
