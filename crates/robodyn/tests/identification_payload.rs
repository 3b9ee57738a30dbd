//! Payload identification (`identification::payload`): the robot simulated with point masses
//! added to a link (the payload's 10 standard parameters from their definitions,
//! sum m (|r|^2 1 - r r^T), sum m r, sum m), its logs identified against the robot file (robot
//! known) or together with logs without the payload (before/after). Noise-free, every
//! identifiable payload parameter comes back to 1e-8; the rank test finds what theory says is
//! identifiable (all 10 on the RX-90's last link; on its first link, a vertical axis, ZZ
//! alone: Khalil & Dombre's grouping leaves only ZZ1 of link 1); with noise, the errors lie
//! within the reported standard deviations.

use rand::Rng;
use robodyn::identification::payload::{
    identify_payload, rigid_body, PayloadLogs, PAYLOAD_PARAMETERS,
};
use robodyn::identification::{Estimator, Options};
use robodyn_testing::rng;

use crate::identification_gains::{access, log, ols, point_masses, with_payload, PAYLOAD};

fn check_payload(got: &[robodyn::identification::payload::Estimate], truth: &[f64; 10]) {
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    for (e, t) in got.iter().zip(truth) {
        let v = e
            .value
            .unwrap_or_else(|| panic!("{} not identified", e.name));
        let err = (v - t).abs() / t.abs().max(1e-3 * scale);
        assert!(err < 1e-8, "{}: {v} vs {t} ({err:e})", e.name);
    }
}

/// The rigid-body constructor (Huygens–Steiner) against the point masses' definitions: four
/// masses as one body, its centre of mass and inertia about it computed from them.
#[test]
fn rigid_body_equals_its_point_masses() {
    let total: f64 = PAYLOAD.iter().map(|p| p.0).sum();
    let c: [f64; 3] =
        std::array::from_fn(|a| PAYLOAD.iter().map(|(m, r)| m * r[a]).sum::<f64>() / total);
    let about_c: Vec<(f64, [f64; 3])> = PAYLOAD
        .iter()
        .map(|(m, r)| (*m, std::array::from_fn(|a| r[a] - c[a])))
        .collect();
    let k = point_masses(&about_c);
    let i_c = [[k[0], k[1], k[2]], [k[1], k[3], k[4]], [k[2], k[4], k[5]]];
    let body = rigid_body(total, c, i_c);
    let direct = point_masses(&PAYLOAD);
    for i in 0..10 {
        assert!(
            (body[i] - direct[i]).abs() < 1e-14,
            "{i}: {} vs {}",
            body[i],
            direct[i]
        );
    }
}

/// Robot known (the robot file), the RX-90 loaded on link 6: all 10 payload parameters are
/// identifiable (structural rank 10) and come back to 1e-8.
#[test]
fn payload_on_the_last_link_with_the_robot_known() {
    let mut acc = access("rx90.toml");
    let phi = point_masses(&PAYLOAD);
    let loaded = with_payload(&acc, 6, &phi);
    let after = log(&loaded, 11);
    let id = identify_payload(&mut acc, 6, &PayloadLogs::Known(vec![&after]), &ols()).unwrap();
    assert_eq!(id.structural_rank, 10, "{:?}", id.structural_null);
    assert_eq!(id.rank, 10, "{:?}", id.undetermined);
    check_payload(&id.payload, &phi);
    assert_eq!(id.payload[9].name, PAYLOAD_PARAMETERS[9]);
}

/// Before/after: logs without and with the payload identified together with the robot's base
/// parameters: the payload to 1e-8 and the robot's parameters to 1e-8 (the file's, mapped).
#[test]
fn payload_before_and_after() {
    let mut acc = access("rx90.toml");
    let phi = point_masses(&PAYLOAD);
    let loaded = with_payload(&acc, 6, &phi);
    let before = log(&acc, 12);
    let after = log(&loaded, 13);
    let logs = PayloadLogs::BeforeAfter {
        before: vec![&before],
        after: vec![&after],
    };
    let id = identify_payload(&mut acc, 6, &logs, &ols()).unwrap();
    check_payload(&id.payload, &phi);
    let model =
        robodyn::identification::parameters::ParameterModel::build(&mut acc, &ols().parameters)
            .unwrap();
    let truth = model.values(&acc.standard_parameters());
    let scale = truth.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    assert_eq!(id.others.len(), truth.len());
    for (e, t) in id.others.iter().zip(&truth) {
        let v = e.value.unwrap();
        assert!(
            (v - t).abs() < 1e-8 * t.abs().max(1e-3 * scale),
            "{}: {v} vs {t}",
            e.name
        );
    }
}

/// A payload on link 1 (a vertical first axis): only ZZ reaches the torques (structural rank
/// 1, 9 combinations named as never changing them); ZZ comes back to 1e-8, the others are
/// reported without a value.
#[test]
fn payload_on_the_first_link_gives_zz_alone() {
    let mut acc = access("rx90.toml");
    let phi = point_masses(&PAYLOAD);
    let loaded = with_payload(&acc, 1, &phi);
    let after = log(&loaded, 14);
    let id = identify_payload(&mut acc, 1, &PayloadLogs::Known(vec![&after]), &ols()).unwrap();
    assert_eq!(id.structural_rank, 1);
    assert_eq!(id.structural_null.len(), 9);
    assert_eq!(id.rank, 1);
    for (k, e) in id.payload.iter().enumerate() {
        if e.name == "ZZ" {
            let v = e.value.unwrap();
            assert!(
                (v - phi[k]).abs() < 1e-8 * phi[k].abs(),
                "ZZ {v} vs {}",
                phi[k]
            );
            assert!(e.std.is_some());
        } else {
            assert!(
                e.value.is_none() && e.std.is_none(),
                "{} has a value",
                e.name
            );
        }
    }
}

/// Torque noise (1 % of each joint's RMS), 20 draws, WLS, robot known: each payload parameter
/// within 4 reported standard deviations, within 2 in at least 85 % of the 200 cases.
#[test]
fn noisy_payload_lies_within_its_standard_deviations() {
    let mut acc = access("rx90.toml");
    let phi = point_masses(&PAYLOAD);
    let loaded = with_payload(&acc, 6, &phi);
    let clean = log(&loaded, 15);
    let sd: Vec<f64> = (0..6)
        .map(|j| {
            let s: f64 = clean.samples.iter().map(|s| s.y[j] * s.y[j]).sum();
            0.01 * (s / clean.samples.len() as f64).sqrt()
        })
        .collect();
    let opt = Options {
        validation: None,
        ..Options::default()
    };
    let (mut inside2, mut cases) = (0, 0);
    for draw in 0..20 {
        let mut l = clean.clone();
        let mut r = rng(300 + draw);
        for s in &mut l.samples {
            for (y, sd) in s.y.iter_mut().zip(&sd) {
                let (u, v): (f64, f64) =
                    (r.random_range(f64::EPSILON..1.0), r.random_range(0.0..1.0));
                *y += sd * (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos();
            }
        }
        let id = identify_payload(&mut acc, 6, &PayloadLogs::Known(vec![&l]), &opt).unwrap();
        for (k, e) in id.payload.iter().enumerate() {
            let (v, s) = (e.value.unwrap(), e.std.unwrap());
            let z = (v - phi[k]).abs() / s;
            assert!(
                z < 4.0,
                "draw {draw} {}: {v} vs {} (std {s})",
                e.name,
                phi[k]
            );
            inside2 += usize::from(z < 2.0);
            cases += 1;
        }
    }
    assert!(
        inside2 * 100 >= 85 * cases,
        "{inside2} of {cases} within 2 std"
    );
}

/// A link that does not exist, and IDIM-IV, are refused.
#[test]
fn payload_refusals() {
    let mut acc = access("rx90.toml");
    let l = log(&acc, 16);
    let e = identify_payload(&mut acc, 7, &PayloadLogs::Known(vec![&l]), &ols()).unwrap_err();
    assert!(e.to_string().contains("no link 7"), "{e}");
    let iv = Options {
        estimator: Estimator::Iv,
        ..ols()
    };
    let e = identify_payload(&mut acc, 6, &PayloadLogs::Known(vec![&l]), &iv).unwrap_err();
    assert!(e.to_string().contains("IDIM-IV"), "{e}");
}
