//! Numeric IGM and IKM: converged solutions checked by the direct geometric model
//! (`geometry::frame_transforms`, not the kinematics the solver iterates on), the RX-90's numeric
//! solution among the closed-form ones, the IKM against the frame Jacobian (J qd = twist) and
//! against finite differences of the direct geometric model.

mod common;

use nalgebra::{DMatrix, Matrix4};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robodyn::algorithms::inverse_geometry::{
    inverse_kinematics, numeric_igm_batch, ClosedFormIgm, IkmOptions, NumericIgm, NumericOptions,
};
use robodyn::geometry::frame_transforms;
use robodyn::{frame_jacobian, FrameId, Reference, Robot};
use std::f64::consts::{PI, TAU};

fn panda() -> Option<Robot> {
    let dir = common::example_robot_data("the numeric IGM of the Panda not checked")?;
    let f = common::find_file(&dir, "panda.urdf").expect("panda.urdf in example-robot-data");
    Some(robodyn::io::load(&f).unwrap())
}

/// q uniform within the limits (one turn when a joint has none).
fn random_q<R: Rng>(r: &Robot, rng: &mut R) -> Vec<f64> {
    r.coordinates()
        .frames()
        .iter()
        .map(|j| {
            let l = r.description().limits.get(j);
            let lo = l.and_then(|l| l.q_min).unwrap_or(-PI);
            let hi = l.and_then(|l| l.q_max).unwrap_or(PI);
            rng.random_range(lo..=hi)
        })
        .collect()
}

/// The placement of `f` by the direct geometric model.
fn dgm(r: &Robot, f: &FrameId, q: &[f64]) -> Matrix4<f64> {
    let t = frame_transforms(r, q).unwrap()[f.parent() - 1];
    t.compose(f.offset()).matrix()
}

#[test]
fn panda_numeric_igm_converges() {
    let Some(r) = panda() else { return };
    let f = r.frame_id("panda_hand_tcp_joint").unwrap();
    let igm = NumericIgm::new(&r, f, NumericOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let n = 1000;
    let (mut converged, mut worst, mut iterations, mut starts) = (0, 0.0f64, 0, 0);
    let limits = |k: usize| {
        let l = r.description().limits.get(&r.coordinates().frame(k));
        (
            l.and_then(|l| l.q_min).unwrap_or(f64::NEG_INFINITY),
            l.and_then(|l| l.q_max).unwrap_or(f64::INFINITY),
        )
    };
    for _ in 0..n {
        let q = random_q(&r, &mut rng);
        let target = dgm(&r, &f, &q);
        let start = random_q(&r, &mut rng);
        let s = igm.solve(&r, &target, &start).unwrap();
        iterations += s.iterations;
        starts += s.starts;
        for (k, x) in s.q.iter().enumerate() {
            let (lo, hi) = limits(k);
            assert!(lo <= *x && *x <= hi, "joint {k}: {x} outside [{lo}, {hi}]");
        }
        if s.converged {
            converged += 1;
            let err = (dgm(&r, &f, &s.q) - target).amax();
            worst = worst.max(err);
            assert!(err <= 1e-9, "converged but off by {err:e}");
        }
    }
    eprintln!(
        "Panda: {converged} of {n} targets converged, largest pose error {worst:.1e}, \
         {:.1} steps and {:.2} starts per target",
        iterations as f64 / n as f64,
        starts as f64 / n as f64
    );
    assert!(converged * 100 >= 99 * n, "{converged} of {n}");
}

#[test]
fn rx90_numeric_solution_is_a_closed_form_one() {
    let r = common::robot("rx90.toml");
    let f = r.frame_id_of(6).unwrap();
    let igm = NumericIgm::new(&r, f, NumericOptions::default()).unwrap();
    let cf = ClosedFormIgm::new(&r).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    for _ in 0..100 {
        let q: Vec<f64> = (0..6).map(|_| rng.random_range(-PI..PI)).collect();
        let target = dgm(&r, &f, &q);
        let start: Vec<f64> = (0..6).map(|_| rng.random_range(-PI..PI)).collect();
        let s = igm.solve(&r, &target, &start).unwrap();
        assert!(s.converged, "{s:?}");
        let gap = cf
            .solve(&target)
            .unwrap()
            .as_slice()
            .iter()
            .map(|c| {
                c.q.iter()
                    .zip(&s.q)
                    .map(|(a, b)| {
                        let d = (a - b).rem_euclid(TAU);
                        d.min(TAU - d)
                    })
                    .fold(0.0, f64::max)
            })
            .fold(f64::INFINITY, f64::min);
        // a pose error of 1e-10 is a joint error of 1e-10 times the conditioning: 1e-6 rad
        // leaves room for poses near the elbow singularity (q3 near pi/2)
        assert!(
            gap <= 1e-6,
            "numeric {:?} is {gap:e} from every closed-form solution",
            s.q
        );
    }
}

#[test]
fn batch_equals_one_by_one_and_reports_unreachable() {
    let r = common::robot("rx90.toml");
    let f = r.frame_id_of(6).unwrap();
    let igm = NumericIgm::new(&r, f, NumericOptions::default()).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    let mut targets: Vec<Matrix4<f64>> = (0..20)
        .map(|_| {
            dgm(
                &r,
                &f,
                &(0..6)
                    .map(|_| rng.random_range(-PI..PI))
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    targets[3][(0, 3)] = 5.0; // out of reach
    let starts = vec![0.1; 20 * 6];
    let batch = numeric_igm_batch(&r, &igm, &targets, &starts).unwrap();
    for (i, b) in batch.iter().enumerate() {
        let one = NumericIgm::new(
            &r,
            f,
            NumericOptions {
                seed: igm.options().seed + i as u64,
                ..NumericOptions::default()
            },
        )
        .unwrap()
        .solve(&r, &targets[i], &starts[i * 6..(i + 1) * 6])
        .unwrap();
        assert_eq!(b, &one, "target {i}");
        assert_eq!(b.converged, i != 3, "target {i}: {b:?}");
    }
    assert!(batch[3].position_error > 4.0, "{:?}", batch[3]);
    let e = numeric_igm_batch(&r, &igm, &targets, &starts[1..]).unwrap_err();
    assert!(e.to_string().contains("starts"), "{e}");
    let mut bad = targets.clone();
    bad[7][(2, 1)] = f64::NAN;
    let e = numeric_igm_batch(&r, &igm, &bad, &starts)
        .unwrap_err()
        .to_string();
    assert!(e.contains("row 8") && e.contains("target[2, 1]"), "{e}");
}

#[test]
fn numeric_options_are_checked() {
    let r = common::robot("rx90.toml");
    let f = r.frame_id_of(6).unwrap();
    for o in [
        NumericOptions {
            position_tolerance: 0.0,
            ..Default::default()
        },
        NumericOptions {
            starts: 0,
            ..Default::default()
        },
        NumericOptions {
            damping: f64::NAN,
            ..Default::default()
        },
    ] {
        assert!(matches!(
            NumericIgm::new(&r, f, o),
            Err(robodyn::Error::Setting { .. })
        ));
    }
}

/// J qd = twist where J is well conditioned; the least-norm solution for the redundant Panda;
/// finite differences of the direct geometric model along qd give the twist.
fn check_ikm(r: &Robot, f: &FrameId, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let o = IkmOptions::default();
    let mut checked = 0;
    for _ in 0..200 {
        let q = random_q(r, &mut rng);
        let twist: Vec<f64> = (0..6).map(|_| rng.random_range(-1.0..1.0)).collect();
        let s = inverse_kinematics(r, &q, f, Reference::LocalWorldAligned, &twist, &o).unwrap();
        if s.sigma_min < o.threshold {
            assert!(s.damping > 0.0);
            continue;
        }
        checked += 1;
        assert_eq!(s.damping, 0.0);
        let j = frame_jacobian(r, &q, f, Reference::LocalWorldAligned).unwrap();
        let res = (&j * &s.qd - DMatrix::from_column_slice(6, 1, &twist)).amax();
        assert!(res <= 1e-10, "J qd - twist = {res:e}");
        // least norm: qd = J^+ twist
        let pinv = j.clone().pseudo_inverse(1e-12).unwrap();
        let ln = (&pinv * DMatrix::from_column_slice(6, 1, &twist) - &s.qd).amax();
        assert!(ln <= 1e-8, "{ln:e}");
        // central differences of the DGM: d/dt p = v, (dR/dt) R^T = [w]
        let h = 1e-6;
        let step = |sgn: f64| {
            let qh: Vec<f64> = q
                .iter()
                .zip(s.qd.iter())
                .map(|(a, b)| a + sgn * h * b)
                .collect();
            dgm(r, f, &qh)
        };
        let (tp, tm, t0) = (step(1.0), step(-1.0), dgm(r, f, &q));
        let d = (tp - tm) / (2.0 * h);
        let w = d.fixed_view::<3, 3>(0, 0) * t0.fixed_view::<3, 3>(0, 0).transpose();
        let fd = [
            d[(0, 3)],
            d[(1, 3)],
            d[(2, 3)],
            w[(2, 1)],
            w[(0, 2)],
            w[(1, 0)],
        ];
        let scale = 1.0 + s.qd.amax();
        for k in 0..6 {
            assert!(
                (fd[k] - twist[k]).abs() <= 1e-6 * scale,
                "{k}: {fd:?} vs {twist:?}"
            );
        }
    }
    assert!(checked > 100, "only {checked} well-conditioned states");
}

#[test]
fn ikm_against_the_jacobian_and_finite_differences() {
    let r = common::robot("rx90.toml");
    check_ikm(&r, &r.frame_id_of(6).unwrap(), 31);
    if let Some(p) = panda() {
        check_ikm(&p, &p.frame_id("panda_hand_tcp_joint").unwrap(), 32);
    }
}

#[test]
fn ikm_at_a_singularity_is_damped() {
    let r = common::robot("rx90.toml");
    let f = r.frame_id_of(6).unwrap();
    let q = [0.3, -0.4, 0.8, 0.5, 0.0, -0.2]; // wrist singular
    let twist = [0.1, 0.0, 0.0, 0.0, 0.5, 0.5];
    let o = IkmOptions::default();
    let s = inverse_kinematics(&r, &q, &f, Reference::LocalWorldAligned, &twist, &o).unwrap();
    assert!(s.sigma_min < 1e-12 && s.condition > 1e12, "{s:?}");
    assert!((s.damping - o.max_damping).abs() < 1e-9, "{s:?}");
    assert!(
        s.qd.iter().all(|x| x.is_finite()) && s.qd.amax() < 1e3,
        "{s:?}"
    );
    let e = inverse_kinematics(&r, &q, &f, Reference::LocalWorldAligned, &[f64::NAN; 6], &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("twist[0]"), "{e}");
    let e = inverse_kinematics(&r, &q, &f, Reference::LocalWorldAligned, &[0.0; 5], &o)
        .unwrap_err()
        .to_string();
    assert!(e.contains("twist"), "{e}");
}
