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

/// Offset-wrist chains whose parallel axes 3 and 4 are turned by gamma and flipped or not
/// (alpha = 0 or pi: axes antiparallel): theta4 is found from the direction of the parallel
/// joints' sum, whose signs and constant follow C2 and C3.
#[test]
fn offset_wrist_with_turned_and_flipped_parallel_axes() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    for k in 0..16 {
        let mut d = random_of_class(&mut rng, IgmClass::OffsetWrist).into_description();
        for j in [2, 3] {
            let flip = if (k >> (j - 2)) & 1 == 1 { PI } else { 0.0 };
            d.frames[j].alpha = Expr::num(flip);
            d.frames[j].gamma = Expr::num(rng.random_range(-3.0..3.0));
        }
        let r = Robot::new(d).unwrap();
        check_random_poses(
            &format!("flipped #{k}"),
            &r,
            IgmClass::OffsetWrist,
            50,
            k,
            false,
        );
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
/// the TX40 and random chains with the wrist mirror: every solution finite and reproducing
/// the pose to 1e-12 (theta5 from 1 -+ cos(delta) found without cancellation; with theta5 =
/// acos(Z / rho) near ±1 the error reached 3.6e-9, eps / |theta5| of the rounding of Z); the
/// source among them while the wrist is not within the tolerance of its singularity.
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
                    assert!(err <= 1e-12, "{label}: {qs:?} of q = {q:?} off by {err:e}");
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

/// Solves the pose of q: at least one solution (the pose is reachable: q reaches it), each
/// finite and reproducing the pose to `tol`; returns the largest pose error and the closest
/// solution's distance to q (modulo 2 pi).
fn reachable_pose_answers(
    label: &str,
    r: &Robot,
    ik: &ClosedFormIgm,
    q: &[f64],
    tol: f64,
) -> (f64, f64) {
    let target = pose(r, ik.frame(), q);
    let sols = ik.solve(&target).unwrap();
    assert!(
        !sols.is_empty(),
        "{label}: no solution for the reachable pose of q = {q:?}"
    );
    let (mut worst, mut best) = (0.0f64, f64::INFINITY);
    for s in sols.as_slice() {
        let qs = full_q(r, ik, s);
        assert!(qs.iter().all(|x| x.is_finite()), "{label}: {qs:?}");
        let err = (pose(r, ik.frame(), &qs) - target).amax();
        assert!(
            err <= tol,
            "{label}: solution {qs:?} ({:?}) of q = {q:?} off by {err:e}",
            s.singular
        );
        worst = worst.max(err);
        best = best.min(angle_gap(&qs, q));
    }
    (worst, best)
}

/// Random chains of both classes with the wrist singular at q5 = 0 (`give_wrist_mirror`; 12
/// per class) and the RX-90, TX40: q5 at and next to 0 (and pi: axes 4 and 6 anti-aligned),
/// 20 random poses each: never an empty answer, every solution reproducing the pose.
#[test]
fn singular_wrists_always_answer() {
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let mut robots = vec![
        ("RX-90".to_string(), common::robot("rx90.toml")),
        ("TX40".to_string(), common::robot("tx40.toml")),
    ];
    for class in [IgmClass::SphericalWrist, IgmClass::OffsetWrist] {
        for k in 0..12 {
            let mut d = random_of_class(&mut rng, class).into_description();
            give_wrist_mirror(&mut rng, &mut d);
            robots.push((format!("{} #{k}", class.name()), Robot::new(d).unwrap()));
        }
    }
    let mut worst: f64 = 0.0;
    for (label, r) in &robots {
        let ik = ClosedFormIgm::new(r).unwrap();
        for q5 in [0.0, 1e-15, -1e-12, 1e-9, -1e-6, PI, PI - 1e-9] {
            for _ in 0..20 {
                let mut q: Vec<f64> = (0..6).map(|_| rng.random_range(-PI..PI)).collect();
                q[4] = q5;
                let (err, _) =
                    reachable_pose_answers(&format!("{label}, q5 = {q5:e}"), r, &ik, &q, 1e-10);
                worst = worst.max(err);
            }
        }
    }
    eprintln!("singular wrists: largest pose error of a solution {worst:.1e}");
}

/// The point the class's arm places (spherical: the wrist centre O4; offset: W, where axes 5
/// and 6 meet) and O1, z1, O2 at q, by the direct geometric model.
fn arm_points(r: &Robot, class: IgmClass, q: &[f64]) -> [nalgebra::Vector3<f64>; 4] {
    let t = frame_transforms(r, q).unwrap();
    let axis = |k: usize| (t[k].pos, t[k].rot.column(2).into_owned());
    let point = match class {
        IgmClass::SphericalWrist => t[3].pos,
        IgmClass::OffsetWrist => {
            // the common point of axes 5 and 6
            let ((p5, u5), (p6, u6)) = (axis(4), axis(5));
            let w = p5 - p6;
            let (b, d, e) = (u5.dot(&u6), u5.dot(&w), u6.dot(&w));
            p5 + u5 * ((b * e - d) / (1.0 - b * b))
        }
    };
    [point, t[0].pos, t[0].rot.column(2).into_owned(), t[1].pos]
}

/// q3 with the arm stretched: |O4 - O2|² = A + B cos q3 + C sin q3 (O4 fixed in link 3, O2
/// on axis 2, axes 2 and 3 parallel) is largest at atan2(C, B).
fn stretched_q3(r: &Robot, q: &[f64]) -> f64 {
    let f = |q3: f64| {
        let mut x = q.to_vec();
        x[2] = q3;
        let t = frame_transforms(r, &x).unwrap();
        (t[3].pos - t[1].pos).norm_squared()
    };
    let (f0, f1, f2) = (f(0.0), f(FRAC_PI_2), f(PI));
    (f1 - (f0 + f2) / 2.0).atan2((f0 - f2) / 2.0)
}

/// q2, q3 putting the arm's point on axis 1 (Gauss-Newton from random starts, central
/// differences), or None.
fn shoulder_q<R: Rng>(rng: &mut R, r: &Robot, class: IgmClass, q: &[f64]) -> Option<Vec<f64>> {
    let off_axis = |x: &[f64]| {
        let [p, o1, z1, _] = arm_points(r, class, x);
        let v = p - o1;
        v - z1 * z1.dot(&v)
    };
    for _ in 0..10 {
        let mut x = q.to_vec();
        (x[1], x[2]) = (rng.random_range(-PI..PI), rng.random_range(-PI..PI));
        for _ in 0..50 {
            let e = off_axis(&x);
            if e.norm() < 1e-15 {
                return Some(x);
            }
            let h = 1e-6;
            let col = |i: usize| {
                let (mut a, mut b) = (x.clone(), x.clone());
                a[i] += h;
                b[i] -= h;
                (off_axis(&a) - off_axis(&b)) / (2.0 * h)
            };
            let j = nalgebra::Matrix3x2::from_columns(&[col(1), col(2)]);
            let step = (j.transpose() * j).try_inverse()? * j.transpose() * e;
            x[1] -= step[0];
            x[2] -= step[1];
        }
    }
    None
}

/// Random chains of both classes at and next to their elbow singularity (the arm stretched
/// or folded) and at their shoulder singularity (the arm's point on axis 1), 10 poses each:
/// never an empty answer, every solution reproducing the pose.
#[test]
fn singular_arms_always_answer() {
    let mut rng = ChaCha8Rng::seed_from_u64(37);
    let mut worst: f64 = 0.0;
    let mut shoulders = 0;
    for class in [IgmClass::SphericalWrist, IgmClass::OffsetWrist] {
        for k in 0..12 {
            let r = random_of_class(&mut rng, class);
            let ik = ClosedFormIgm::new(&r).unwrap();
            for _ in 0..10 {
                let q: Vec<f64> = (0..6).map(|_| rng.random_range(-PI..PI)).collect();
                let q3 = stretched_q3(&r, &q);
                for (what, d) in [
                    ("stretched", 0.0),
                    ("folded", PI),
                    ("near", 1e-12),
                    ("near", -1e-9),
                    ("near", 1e-6),
                ] {
                    let mut x = q.clone();
                    x[2] = q3 + d;
                    let label = format!("{} #{k} elbow {what} {d:e}", class.name());
                    worst = worst.max(reachable_pose_answers(&label, &r, &ik, &x, 1e-10).0);
                }
                if let Some(x) = shoulder_q(&mut rng, &r, class, &q) {
                    let label = format!("{} #{k} shoulder", class.name());
                    worst = worst.max(reachable_pose_answers(&label, &r, &ik, &x, 1e-10).0);
                    shoulders += 1;
                }
            }
        }
    }
    assert!(shoulders >= 80, "{shoulders} shoulder-singular poses found");
    eprintln!(
        "singular arms: {shoulders} shoulder poses; largest pose error of a solution {worst:.1e}"
    );
}
