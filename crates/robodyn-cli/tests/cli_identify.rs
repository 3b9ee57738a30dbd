//! `robodyn excite`, `robodyn simulate --track` and `robodyn identify` end to end: the
//! identified base parameters of a simulated log equal those `robodyn base-params --method
//! numeric` computes from the robot file; the robot written by identify simulates; bad input
//! is refused with a reason.

mod common;
use common::{assert_identified_base_params, fails, robot, run, tmp};

#[test]
fn excite_simulate_identify_round_trip() {
    let rx90 = robot("rx90.toml");
    let reference = tmp("identify", "excite.csv");
    let plot = tmp("identify", "excite.svg");
    let text = run(&[
        "excite",
        &rx90,
        "--period",
        "4",
        "--harmonics",
        "4",
        "--qd-max",
        "1.5",
        "--qdd-max",
        "6",
        "--iterations",
        "60",
        "--rate",
        "200",
        "--periods",
        "2",
        "--output",
        reference.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert!(text.contains("condition number"), "{text}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(svg.contains("<svg") && svg.contains("qd1"));
    // simulate the robot tracking the reference (PD), logging q, qd, qdd, tau
    let traj = tmp("identify", "traj.csv");
    run(&[
        "simulate",
        &rx90,
        "--duration",
        "8",
        "--dt",
        "0.001",
        "--output-step",
        "0.004",
        "--track",
        reference.to_str().unwrap(),
        "--kp",
        "400",
        "--kd",
        "40",
        "--coulomb-smoothing",
        "0",
        "--output",
        traj.to_str().unwrap(),
    ]);
    let json = run(&[
        "identify",
        &rx90,
        "--data",
        traj.to_str().unwrap(),
        "--estimator",
        "ols",
        "--validation",
        "0.7:1",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    for key in [
        "parameters",
        "condition_number",
        "relative_error",
        "per_joint",
    ] {
        assert!(v.get(key).is_some(), "JSON key {key}");
    }
    assert_eq!(v["per_joint"].as_array().unwrap().len(), 6);
    assert!(
        v["per_joint"][0].get("rms").is_some() && v["per_joint"][0].get("relative_error").is_some()
    );
    assert!(v["relative_error"].as_f64().unwrap() < 1e-9);
    // the same base parameters from the robot file, by base-params
    assert_identified_base_params(&rx90, &v);
    for p in v["parameters"].as_array().unwrap() {
        assert!(p.get("relative_std").is_some());
    }
    // CSV table and the consistent robot file, which simulates
    let csv = run(&[
        "identify",
        &rx90,
        "--data",
        traj.to_str().unwrap(),
        "--estimator",
        "ols",
        "--format",
        "csv",
    ]);
    assert!(csv.starts_with("name,value,std,relative_std,equation"));
    let written = tmp("identify", "identified.toml");
    let fit = tmp("identify", "fit.svg");
    run(&[
        "identify",
        &rx90,
        "--data",
        traj.to_str().unwrap(),
        "--estimator",
        "ols",
        "--write-robot",
        written.to_str().unwrap(),
        "--plot",
        fit.to_str().unwrap(),
    ]);
    assert!(std::fs::read_to_string(&fit).unwrap().contains("predicted"));
    let out = tmp("identify", "resim.csv");
    run(&[
        "simulate",
        written.to_str().unwrap(),
        "--duration",
        "0.2",
        "--dt",
        "0.001",
        "--output",
        out.to_str().unwrap(),
    ]);
}

#[test]
fn identify_refuses_bad_input_with_a_reason() {
    let rx90 = robot("rx90.toml");
    let log = tmp("identify_bad", "log.csv");
    // a robot at rest: nothing is excited
    let mut s = String::from("t,q1,q2,q3,q4,q5,q6,tau1,tau2,tau3,tau4,tau5,tau6\n");
    for k in 0..3000 {
        s.push_str(&format!("{},0,0,0,0,0,0,0,1,1,0,0,0\n", k as f64 * 0.001));
    }
    std::fs::write(&log, &s).unwrap();
    // the velocities differentiated from the positions: the default minimum speed leaves out
    // every row, said so
    let e = fails(&["identify", &rx90, "--data", log.to_str().unwrap()]);
    assert!(
        e.contains("0 equations") && e.contains("slower than the minimum speed 0.005"),
        "{e}"
    );
    // every row kept: what they cannot determine
    let e = fails(&[
        "identify",
        &rx90,
        "--data",
        log.to_str().unwrap(),
        "--min-speed",
        "0",
    ]);
    assert!(
        e.contains("no effect") || e.contains("rank-deficient"),
        "{e}"
    );
    // cut-off above Nyquist
    let e = fails(&[
        "identify",
        &rx90,
        "--data",
        log.to_str().unwrap(),
        "--cutoff",
        "600",
    ]);
    assert!(e.contains("Nyquist"), "{e}");
    // missing column
    std::fs::write(&log, "t,q1,tau1\n0,0,0\n0.001,0,0\n").unwrap();
    let e = fails(&["identify", &rx90, "--data", log.to_str().unwrap()]);
    assert!(e.contains("q2"), "{e}");
    // time not uniform
    let mut s = String::from("t,q1,q2,q3,q4,q5,q6,tau1,tau2,tau3,tau4,tau5,tau6\n");
    for k in 0..10 {
        let t = if k < 5 {
            k as f64 * 0.001
        } else {
            k as f64 * 0.002
        };
        s.push_str(&format!("{t},0,0,0,0,0,0,0,0,0,0,0,0\n"));
    }
    std::fs::write(&log, &s).unwrap();
    let e = fails(&["identify", &rx90, "--data", log.to_str().unwrap()]);
    assert!(e.contains("uniformly") && e.contains("log.csv:"), "{e}");
    // currents without gains
    std::fs::write(&log, "t,q1,q2,q3,q4,q5,q6,i1,i2,i3,i4,i5,i6\n0,0,0,0,0,0,0,0,0,0,0,0,0\n0.001,0,0,0,0,0,0,0,0,0,0,0,0\n").unwrap();
    let e = fails(&["identify", &rx90, "--data", log.to_str().unwrap()]);
    assert!(e.contains("--gains"), "{e}");
    // excite needs limits
    let e = fails(&[
        "excite",
        &rx90,
        "--period",
        "4",
        "--harmonics",
        "3",
        "--output",
        log.to_str().unwrap(),
    ]);
    assert!(e.contains("velocity limit"), "{e}");
}

/// The bundled TX40 (motor-joint transmission) works everywhere, and the transmission survives a
/// TOML round trip (idm, ddm, simulate with motors' drive parameters: `cli_transmission.rs`).
#[test]
fn transmission_survives_a_toml_round_trip() {
    run(&["idm", &robot("tx40.toml"), "--q", "0,0,0,0,0,0"]);
    // and the transmission survives a TOML round trip
    let out = tmp("identify_tr", "tx40_copy.toml");
    run(&["convert", &robot("tx40.toml"), out.to_str().unwrap()]);
    let copy = std::fs::read_to_string(&out).unwrap();
    assert!(
        copy.contains("[transmission]") && copy.contains("[0.0, 0.0, 0.0, 0.0, 32.0, 32.0]"),
        "{copy}"
    );
}
