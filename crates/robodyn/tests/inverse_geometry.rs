//! Inverse geometric model: the closed form (Paul's method) against the direct geometric model
//! `geometry::frame_transforms` (an independent product of the frames' transforms): every
//! solution reproduces the pose, the joint values the pose came from are among the solutions,
//! 8 solutions for generic poses, singular poses without NaN, bad targets rejected.

mod common;

use nalgebra::Matrix4;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use robodyn::algorithms::inverse_geometry::{ClosedFormIgm, IgmClass, IgmSolution};
use robodyn::geometry::frame_transforms;
use robodyn::{Expr, Robot};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// The UR5 of example-robot-data, or None after a visible skip.
fn ur5() -> Option<Robot> {
    let dir = common::example_robot_data("the closed-form IGM of the UR5 not checked")?;
    let f =
        common::find_file(&dir, "ur5_robot.urdf").expect("ur5_robot.urdf in example-robot-data");
    Some(robodyn::io::load(&f).unwrap())
}

/// 0T_frame at the movable-joint vector q.
fn pose(r: &Robot, frame: usize, q: &[f64]) -> Matrix4<f64> {
    frame_transforms(r, q).unwrap()[frame - 1].matrix()
}

/// The robot's movable-joint vector of a solution.
fn full_q(r: &Robot, ik: &ClosedFormIgm, s: &IgmSolution) -> Vec<f64> {
    let mut q = vec![0.0; r.dof()];
    for (k, &i) in ik.joints().iter().enumerate() {
        q[i] = s.q[k];
    }
    q
}

/// Largest angular distance modulo 2 pi.
fn angle_gap(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let d = (x - y).rem_euclid(TAU);
            d.min(TAU - d)
        })
        .fold(0.0, f64::max)
}

/// Every solution of `n` poses of random q reproduces the pose to 1e-10; 8 solutions; q among
/// them.
fn check_random_poses(label: &str, r: &Robot, class: IgmClass, n: usize, seed: u64, eight: bool) {
    let ik = ClosedFormIgm::new(r).unwrap_or_else(|e| panic!("{label}: {e}"));
    assert_eq!(ik.class(), class, "{label}");
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut worst: f64 = 0.0;
    let mut counts = [0; 9];
    for _ in 0..n {
        let q: Vec<f64> = (0..r.dof()).map(|_| rng.random_range(-PI..PI)).collect();
        let target = pose(r, ik.frame(), &q);
        let sols = ik.solve(&target).unwrap();
        counts[sols.len()] += 1;
        if eight {
            assert_eq!(sols.len(), 8, "{label}: q = {q:?}");
        }
        assert!(
            sols.len().is_multiple_of(2),
            "{label}: {} solutions for q = {q:?}",
            sols.len()
        );
        let mut best = f64::INFINITY;
        for s in sols.as_slice() {
            assert!(
                !s.singular.any(),
                "{label}: generic q = {q:?} marked {:?}",
                s.singular
            );
            let qs = full_q(r, &ik, s);
            let err = (pose(r, ik.frame(), &qs) - target).amax();
            worst = worst.max(err);
            assert!(
                err <= 1e-10,
                "{label}: solution {qs:?} of q = {q:?} off by {err:e}"
            );
            best = best.min(angle_gap(&qs, &q));
        }
        assert!(
            best <= 1e-7,
            "{label}: q = {q:?} not among the solutions ({best:e})"
        );
    }
    eprintln!(
        "{label}: {n} poses, largest pose error of a solution {worst:.1e}, poses by number of \
         solutions (0..=8) {counts:?}"
    );
}

#[test]
fn rx90_random_poses() {
    let r = common::robot("rx90.toml");
    check_random_poses("RX-90", &r, IgmClass::SphericalWrist, 1000, 1, true);
}

#[test]
fn tx40_random_poses() {
    let r = common::robot("tx40.toml");
    check_random_poses("TX40", &r, IgmClass::SphericalWrist, 1000, 2, true);
}

#[test]
fn ur5_random_poses() {
    let Some(r) = ur5() else { return };
    check_random_poses("UR5", &r, IgmClass::OffsetWrist, 1000, 3, false);
}

/// Singular poses: each solution finite and reproducing the pose; `expect` holds on the set
/// (the marker of the case on the solutions of q's branch).
fn check_singular(label: &str, r: &Robot, q: &[f64], expect: fn(&[IgmSolution]) -> bool) {
    let ik = ClosedFormIgm::new(r).unwrap();
    let target = pose(r, ik.frame(), q);
    let sols = ik.solve(&target).unwrap();
    assert!(!sols.is_empty(), "{label}: no solution");
    for s in sols.as_slice() {
        assert!(s.q.iter().all(|x| x.is_finite()), "{label}: {:?}", s.q);
        let qs = full_q(r, &ik, s);
        let err = (pose(r, ik.frame(), &qs) - target).amax();
        assert!(err <= 1e-9, "{label}: {qs:?} off by {err:e}");
    }
    assert!(expect(sols.as_slice()), "{label}: {:?}", sols.as_slice());
    eprintln!("{label}: {} solutions", sols.len());
}

/// Every solution with q5 = 0 (mod pi: axes 4 and 6 aligned) is marked wrist-singular, and
/// there is one.
fn wrist(s: &[IgmSolution]) -> bool {
    let aligned = |x: &IgmSolution| x.q[4].sin().abs() < 1e-9;
    s.iter().any(aligned) && s.iter().filter(|x| aligned(x)).all(|x| x.singular.wrist)
}

#[test]
fn rx90_singular_poses() {
    let r = common::robot("rx90.toml");
    // wrist: q5 = 0 aligns axes 4 and 6
    check_singular("RX-90 wrist", &r, &[0.3, -0.4, 0.8, 0.5, 0.0, -0.2], wrist);
    // shoulder: the wrist centre O4 = D3 x2 + RL4 y2 (q3 = 0) on axis 1: x2 at 45 degrees
    let q2 = [FRAC_PI_4, 3.0 * FRAC_PI_4, -FRAC_PI_4, -3.0 * FRAC_PI_4]
        .into_iter()
        .find(|&q2| {
            let o4 = frame_transforms(&r, &[0.3, q2, 0.0, 0.5, 0.7, -0.2]).unwrap()[3].pos;
            o4.xy().norm() < 1e-12
        })
        .expect("a q2 puts the wrist centre on axis 1");
    check_singular("RX-90 shoulder", &r, &[0.3, q2, 0.0, 0.5, 0.7, -0.2], |s| {
        s.iter().any(|x| x.singular.shoulder)
    });
    // elbow: the arm stretched (q3 = pi/2 puts r4 along d3)
    check_singular(
        "RX-90 elbow",
        &r,
        &[0.3, -0.4, FRAC_PI_2, 0.5, 0.7, -0.2],
        |s| s.iter().any(|x| x.singular.elbow),
    );
    check_singular("RX-90 zero", &r, &[0.0; 6], |s| {
        s.iter().any(|x| x.singular.any())
    });
}

#[test]
fn ur5_singular_poses() {
    let Some(r) = ur5() else { return };
    check_singular("UR5 zero", &r, &[0.0; 6], |s| {
        s.iter().any(|x| x.singular.any())
    });
    // wrist: q5 = 0 makes axis 6 parallel to axes 2, 3, 4
    check_singular("UR5 wrist", &r, &[0.3, -0.4, 0.8, 0.5, 0.0, -0.2], wrist);
    // elbow: q3 = 0 stretches the arm
    check_singular("UR5 elbow", &r, &[0.3, -0.4, 0.0, 0.5, 0.7, -0.2], |s| {
        s.iter().any(|x| x.singular.elbow)
    });
}

#[test]
fn tool_offset_and_unreachable() {
    let r = common::robot("rx90.toml");
    let mut tool = Matrix4::identity();
    tool[(0, 3)] = 0.05;
    tool[(2, 3)] = 0.2;
    let ik = ClosedFormIgm::new(&r).unwrap().with_tool(&tool).unwrap();
    let q = [0.2, -0.3, 0.9, 0.4, -0.8, 1.1];
    let target = pose(&r, 6, &q) * tool;
    let sols = ik.solve(&target).unwrap();
    assert_eq!(sols.len(), 8);
    for s in sols.as_slice() {
        assert!((pose(&r, 6, &s.q) * tool - target).amax() <= 1e-10);
    }
    // out of reach: 10 m away
    let mut far = target;
    far[(0, 3)] = 10.0;
    assert!(ik.solve(&far).unwrap().is_empty());
}

#[test]
fn joint_limits_flag() {
    let mut d = common::robot("rx90.toml").into_description();
    for j in 1..=6 {
        d.limits.insert(
            j,
            robodyn::model::JointLimits {
                q_min: Some(-1.0),
                q_max: Some(1.0),
                ..Default::default()
            },
        );
    }
    let r = Robot::new(d).unwrap();
    let ik = ClosedFormIgm::new(&r).unwrap();
    let q = [0.2, -0.3, 0.9, 0.4, -0.8, 0.6];
    let sols = ik.solve(&pose(&r, 6, &q)).unwrap();
    let inside: Vec<_> = sols.as_slice().iter().filter(|s| s.within_limits).collect();
    assert!(!inside.is_empty() && inside.len() < 8, "{}", inside.len());
    for s in sols.as_slice() {
        assert_eq!(
            s.within_limits,
            s.q.iter().all(|x| x.abs() <= 1.0),
            "{:?}",
            s.q
        );
    }
}

#[test]
fn bad_targets_are_errors() {
    let r = common::robot("rx90.toml");
    let ik = ClosedFormIgm::new(&r).unwrap();
    let mut t = pose(&r, 6, &[0.1; 6]);
    t[(1, 2)] = f64::NAN;
    let e = ik.solve(&t).unwrap_err().to_string();
    assert!(
        e.contains("target[1, 2]") && e.contains("not a finite"),
        "{e}"
    );
    let mut t = pose(&r, 6, &[0.1; 6]);
    t[(0, 0)] *= 1.01;
    let e = ik.solve(&t).unwrap_err().to_string();
    assert!(e.contains("orthonormal"), "{e}");
    let mut t = pose(&r, 6, &[0.1; 6]);
    t.fixed_view_mut::<3, 1>(0, 0).neg_mut(); // a reflection: det = -1
    let e = ik.solve(&t).unwrap_err().to_string();
    assert!(e.contains("determinant"), "{e}");
    let mut t = pose(&r, 6, &[0.1; 6]);
    t[(3, 0)] = 0.5;
    let e = ik.solve(&t).unwrap_err().to_string();
    assert!(e.contains("last row"), "{e}");
}

/// A random 6R chain of `class`: general gamma, b, alpha, d, r, theta offsets, but the
/// parameters the class fixes (parallel axes: alpha = gamma = 0 and b free; concurrent axes:
/// d = 0 and no offset along the previous axis before the wrist centre).
fn random_of_class<R: Rng>(rng: &mut R, class: IgmClass) -> Robot {
    let opts = robodyn_testing::TreeOptions {
        p_prismatic: 0.0,
        p_fixed: 0.0,
        p_serial: 1.0,
        ..Default::default()
    };
    let mut d = robodyn_testing::random_tree_description(rng, 6, &opts);
    let mut x = |lo: f64, hi: f64| Expr::num(rng.random_range(lo..hi));
    for j in 1..=6 {
        let f = &mut d.frames[j - 1];
        f.ant = j - 1;
        f.gamma = x(-3.0, 3.0);
        f.b = x(-0.3, 0.3);
        f.alpha = x(-3.0, 3.0);
        f.d = x(-0.5, 0.5);
        f.theta = x(-3.0, 3.0);
        f.r = x(-0.5, 0.5);
    }
    let parallel = |f: &mut robodyn::model::FrameDesc| {
        f.alpha = Expr::num(0.0);
        f.gamma = Expr::num(0.0);
    };
    let zero = || Expr::num(0.0);
    match class {
        IgmClass::SphericalWrist => {
            parallel(&mut d.frames[2]);
            // axes 4, 5, 6 through O4: r4 carries O4 along axis 4, then no offset
            for j in [5, 6] {
                let f = &mut d.frames[j - 1];
                (f.d, f.b) = (zero(), zero());
            }
            d.frames[4].r = zero();
        }
        IgmClass::OffsetWrist => {
            parallel(&mut d.frames[2]);
            parallel(&mut d.frames[3]);
            d.frames[5].d = zero();
        }
    }
    Robot::new(d).unwrap()
}

#[test]
fn random_chains_of_each_class() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for class in [IgmClass::SphericalWrist, IgmClass::OffsetWrist] {
        for k in 0..20 {
            let r = random_of_class(&mut rng, class);
            check_random_poses(&format!("{} #{k}", class.name()), &r, class, 50, k, false);
        }
    }
}

#[test]
fn robots_of_no_class_name_the_numeric_model() {
    let r = common::robot("scara.toml");
    let e = ClosedFormIgm::new(&r).unwrap_err().to_string();
    assert!(e.contains("numeric"), "{e}");
    // a random 6R chain: no two axes parallel, no three concurrent
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut r = random_of_class(&mut rng, IgmClass::SphericalWrist).into_description();
    r.frames[2].alpha = Expr::num(0.4);
    r.frames[5].d = Expr::num(0.1);
    let e = ClosedFormIgm::new(&Robot::new(r).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no closed-form") && e.contains("numeric"), "{e}");
}

/// Gives a random chain the wrist whose second solution is the mirror (theta4 + pi, -theta5,
/// theta6 + pi) of the first (taken for the spherical wrist): alpha5, alpha6 = ±pi/2, gamma6
/// = 0 or pi, d5 = 0, theta5's offset 0 (the wrist singular at q5 = 0).
fn give_wrist_mirror<R: Rng>(rng: &mut R, d: &mut robodyn::model::RobotDescription) {
    let mut sign = || if rng.random_bool(0.5) { 1.0 } else { -1.0 };
    let (a5, a6, g6) = (
        sign() * FRAC_PI_2,
        sign() * FRAC_PI_2,
        (sign() + 1.0) * FRAC_PI_2,
    );
    d.frames[4].alpha = Expr::num(a5);
    d.frames[4].d = Expr::num(0.0);
    d.frames[4].theta = Expr::num(0.0);
    d.frames[5].alpha = Expr::num(a6);
    d.frames[5].gamma = Expr::num(g6);
}

/// Random chains of each class with the wrist mirror, and with it missed by one parameter
/// (gamma6 = 0.7; alpha6 = 1.2; the offset wrist's d5 = 0.2): every solution reproduces the
/// pose, the source among them, whether the second wrist solution is the mirror of the first
/// or solved root by root (where the mirror does not hold, Rz(pi) W(-t) Rz(pi) differs from
/// W(t) by O(1), so a mirrored solution would miss the orientation by O(1)).
#[test]
fn random_chains_with_and_without_the_wrist_mirror() {
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for class in [IgmClass::SphericalWrist, IgmClass::OffsetWrist] {
        for k in 0..12 {
            let mut d = random_of_class(&mut rng, class).into_description();
            give_wrist_mirror(&mut rng, &mut d);
            let miss = match k % 4 {
                0 | 1 => "mirror",
                2 => {
                    d.frames[5].gamma = Expr::num(0.7);
                    "gamma6 = 0.7"
                }
                _ if class == IgmClass::SphericalWrist => {
                    d.frames[5].alpha = Expr::num(1.2);
                    "alpha6 = 1.2"
                }
                _ => {
                    d.frames[4].d = Expr::num(0.2);
                    "d5 = 0.2"
                }
            };
            let r = Robot::new(d).unwrap();
            let label = format!("{} #{k} ({miss})", class.name());
            check_random_poses(&label, &r, class, 50, 100 + k, false);
        }
    }
}

/// Spherical wrists at and near their singularity (q5 = 0 aligns axes 4 and 6) on the RX-90,
/// the TX40 and random chains with the wrist mirror: every
/// solution finite and reproducing the pose to 1e-8 (the double root of theta5 is solved root
/// by root, not mirrored; theta5 from acos(Z / rho) near ±1 carries eps / |theta5| of the
/// rounding of Z: up to 3.6e-9 found); the source among them while the
/// wrist is not within the tolerance of its singularity.
#[test]
fn near_singular_wrists() {
    let mut rng = ChaCha8Rng::seed_from_u64(29);
    let mut robots = vec![
        ("RX-90".to_string(), common::robot("rx90.toml")),
        ("TX40".to_string(), common::robot("tx40.toml")),
    ];
    for k in 0..4 {
        let mut d = random_of_class(&mut rng, IgmClass::SphericalWrist).into_description();
        give_wrist_mirror(&mut rng, &mut d);
        robots.push((format!("spherical wrist #{k}"), Robot::new(d).unwrap()));
    }
    let mut worst: f64 = 0.0;
    for (label, r) in &robots {
        let ik = ClosedFormIgm::new(r).unwrap();
        for q5 in [1e-2, -1e-4, 1e-5, 3e-6, -1e-7, 1e-9, 1e-12, 0.0] {
            for _ in 0..20 {
                let mut q: Vec<f64> = (0..6).map(|_| rng.random_range(-PI..PI)).collect();
                q[4] = q5;
                let target = pose(r, ik.frame(), &q);
                let sols = ik.solve(&target).unwrap();
                assert!(
                    sols.len() >= 2,
                    "{label}: q = {q:?}: {} solutions",
                    sols.len()
                );
                let mut best = f64::INFINITY;
                for s in sols.as_slice() {
                    let qs = full_q(r, &ik, s);
                    assert!(qs.iter().all(|x| x.is_finite()), "{label}: {qs:?}");
                    let err = (pose(r, ik.frame(), &qs) - target).amax();
                    worst = worst.max(err);
                    assert!(err <= 1e-8, "{label}: {qs:?} of q = {q:?} off by {err:e}");
                    best = best.min(angle_gap(&qs, &q));
                }
                if q5.abs() >= 1e-5 {
                    assert!(best <= 1e-6, "{label}: q = {q:?} not among ({best:e})");
                }
            }
        }
    }
    eprintln!("near-singular wrists: largest pose error of a solution {worst:.1e}");
}
