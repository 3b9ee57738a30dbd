//! `robodyn base-params` and `robodyn regressor` on closed chains: the numerical method through
//! the loop-closure sampler, the arbiter block when the methods differ, and the closed-chain
//! base regressor G^T Phi_b times the base values against `robodyn idm` (Gamma_cl by
//! Newton–Euler, an independent route).

use serde_json::Value;
use std::path::PathBuf;
mod common;

use common::{csv, robot, run};

fn tmp_(name: &str) -> PathBuf {
    common::tmp("bpc", name)
}

#[test]
fn sr400_numeric_method_through_loop_closure_has_42_parameters() {
    let out = run(&[
        "base-params",
        &robot("sr400.toml"),
        "--method",
        "numeric",
        "--no-friction",
        "--format",
        "json",
    ]);
    let j: Value = serde_json::from_str(&out).unwrap();
    assert_eq!(j["count"], 42);
    let names: Vec<&str> = j["base"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["name"].as_str().unwrap())
        .collect();
    assert_eq!(names[0], "ZZR1");
    assert_eq!(names[names.len() - 1], "MY8");
    // both: same set, no arbiter block
    let text = run(&["base-params", &robot("sr400.toml"), "--no-friction"]);
    assert!(
        text.contains("the same set as the symbolic rules"),
        "{text}"
    );
    assert!(!text.contains("ARBITER"), "{text}");
}

#[test]
fn fourbar_report_names_the_arbiter_and_the_differing_parameters() {
    let text = run(&["base-params", &robot("fourbar.toml"), "--method", "both"]);
    let head: Vec<&str> = text.lines().take(4).collect();
    let head = head.join("\n");
    assert!(
        head.contains("THE NUMERICAL METHOD IS THE ARBITER"),
        "{head}"
    );
    // crank-rocker: the numerical method groups MX3 (a cut-joint relation the rules do not use)
    assert!(head.contains("base by the rules only: MX3"), "{head}");
    let j: Value = serde_json::from_str(&run(&[
        "base-params",
        &robot("fourbar.toml"),
        "--format",
        "json",
    ]))
    .unwrap();
    assert_eq!(j["comparison"]["arbiter"], "numeric");
    assert_eq!(j["comparison"]["symbolic_only"][0], "MX3");
    assert!(j["comparison"]["numeric_count"].as_u64() < j["comparison"]["symbolic_count"].as_u64());
}

#[test]
fn closed_base_regressor_times_base_values_gives_idm_torques() {
    let cases: [(&str, Vec<&str>); 4] = [
        (
            "fourbar.toml",
            vec!["0.3,1.0,2.0", "-0.5,-0.7,1.5", "1.2,0.4,-3.0"],
        ),
        ("twoloops.toml", vec!["0.3,1.0,2.0", "-0.4,-0.7,1.5"]),
        ("spatial_loop.toml", vec!["0.3,1.0,2.0", "-0.5,-0.7,1.5"]),
        (
            "sr400.toml",
            vec![
                "0.1,0.2,0.3,0.2,-0.3,0.5,0.3,0.1,-1,0.4,0.5,0.6,-0.2,0.3,0.1,0.5,0.4,-0.2",
                "-0.4,1.2,0.3,-0.6,0.3,-2.5,1.3,0.1,1,0.4,-0.5,0.6,0.9,0.3,0.1,-0.3,0.8,1.2",
            ],
        ),
    ];
    for (file, states) in cases {
        let r = robot(file);
        let actuated: Vec<usize> = if file == "sr400.toml" {
            vec![1, 2, 4, 5, 6, 7]
        } else {
            vec![1]
        };
        let header: Vec<String> = actuated
            .iter()
            .flat_map(|j| [format!("q{j}"), format!("qd{j}"), format!("qdd{j}")])
            .collect();
        let input = tmp_(&format!("{file}.csv"));
        std::fs::write(
            &input,
            format!("{}\n{}\n", header.join(","), states.join("\n")),
        )
        .unwrap();
        let bp: Value = serde_json::from_str(&run(&[
            "base-params",
            &r,
            "--method",
            "numeric",
            "--format",
            "json",
        ]))
        .unwrap();
        let reg = run(&[
            "regressor",
            &r,
            "--input",
            input.to_str().unwrap(),
            "--base",
        ]);
        let (head, rows) = csv(&reg);
        let values: Vec<(usize, f64)> = bp["base"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| {
                let name = b["name"].as_str().unwrap();
                let col = head
                    .iter()
                    .position(|h| h == name)
                    .unwrap_or_else(|| panic!("{file}: no column {name} in {head:?}"));
                (col, b["value"].as_f64().unwrap())
            })
            .collect();
        assert_eq!(values.len() + 3, head.len(), "{file}: {head:?}");
        for (s, state) in states.iter().enumerate() {
            // idm one state at a time: each solved from the assembly like the regressor
            let one = tmp_(&format!("{file}-{s}.csv"));
            std::fs::write(&one, format!("{}\n{state}\n", header.join(","))).unwrap();
            let (ih, irows) = csv(&run(&["idm", &r, "--input", one.to_str().unwrap()]));
            for row in rows.iter().filter(|x| x[0] as usize == s + 1) {
                let j = row[1] as usize;
                let base: f64 = row[2] + values.iter().map(|&(c, v)| row[c] * v).sum::<f64>();
                let k = ih.iter().position(|h| *h == format!("tau{j}")).unwrap();
                let tau = irows[0][k];
                let scale = irows[0].iter().fold(1e-9f64, |a, x| a.max(x.abs()));
                assert!(
                    (base - tau).abs() <= 1e-9 * scale,
                    "{file} state {} joint {j}: base model {base} vs idm {tau}",
                    s + 1
                );
            }
        }
    }
}
