//! Kinematics against finite differences (independent of the Jacobian formulas): the frame
//! placement differentiated along a path gives J q̇ (all three references), the velocity
//! differentiated gives J̇ q̇ + J q̈, J differentiated gives J̇, the centre of mass likewise; on
//! random trees of `robodyn-testing` (fixed seeds, revolute, prismatic and fixed frames,
//! general gamma and b) and on every bundled robot (the equivalent trees of the closed ones),
//! for every frame and a frame with a random offset. Plus the errors of the checked path.
//!
//! Central differences with step h = 1e-4 along q(t) = q + t q̇ + t²/2 q̈: the truncation error
//! is h²/6 |f'''| and the rounding error ~ eps |f| / h. With |q̇| < 2 rad/s per joint, |q̈| < 5,
//! and metre-scale robots, |f'''| stays below ~1e3 (a few joints' speeds cubed times a lever
//! arm) and |f| below ~1e2: together under 2e-6 + 1e-10. The tolerance is 1e-5 times
//! max(1, |expected|), still far below a wrong term (a missing Coriolis or lever-arm term is
//! of the order of the velocities themselves).

use nalgebra::{DMatrix, Matrix3, Vector3};
use rand::Rng;
use robodyn::algorithms::kinematics::{
    center_of_mass, center_of_mass_jacobian_from_q_into, center_of_mass_jacobian_into,
    subtree_mass, total_mass,
};
use robodyn::geometry::Transform;
use robodyn::{
    forward_kinematics_into, frame_acceleration, frame_classical_acceleration,
    frame_classical_drift, frame_jacobian, frame_jacobian_from_q_into, frame_jacobian_into,
    frame_jacobian_time_variation_into, frame_placement, frame_velocity, joint_jacobians_into,
    placements_into, relative_placement, Error, FrameId, KinematicsData, Motion, Reference, Robot,
};
use robodyn_testing as testing;

mod common;

const H: f64 = 1e-4;
const TOL: f64 = 1e-5;

fn close(what: &str, got: &[f64], expected: &[f64]) {
    let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    for (k, (g, e)) in got.iter().zip(expected).enumerate() {
        assert!(
            (g - e).abs() <= TOL * scale,
            "{what}[{k}]: {g} vs {e} (scale {scale})\n got {got:?}\n expected {expected:?}"
        );
    }
}

/// The state at time t along q(t) = q + t qd + t²/2 qdd.
fn at(s: &[Vec<f64>; 3], t: f64) -> [Vec<f64>; 3] {
    let [q, qd, qdd] = s;
    let n = q.len();
    [
        (0..n)
            .map(|k| q[k] + t * qd[k] + 0.5 * t * t * qdd[k])
            .collect(),
        (0..n).map(|k| qd[k] + t * qdd[k]).collect(),
        qdd.clone(),
    ]
}

fn fk(robot: &Robot, s: &[Vec<f64>; 3]) -> KinematicsData {
    let mut d = KinematicsData::new(robot);
    forward_kinematics_into(robot, &mut d, &s[0], &s[1], &s[2]).unwrap();
    d
}

/// skew^-1 of (R+ R-^T - R- R+^T) / (4h): the angular velocity in R_0 from two orientations.
fn angular_rate(rp: &Matrix3<f64>, rm: &Matrix3<f64>) -> Vector3<f64> {
    let m = (rp * rm.transpose() - rm * rp.transpose()) / (4.0 * H);
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

/// The velocity of frame f in `reference` by differences of its placement.
fn velocity_by_differences(robot: &Robot, s: &[Vec<f64>; 3], f: &FrameId, r: Reference) -> Motion {
    let tp = frame_placement(robot, &fk(robot, &at(s, H)), f).unwrap();
    let tm = frame_placement(robot, &fk(robot, &at(s, -H)), f).unwrap();
    let t0 = frame_placement(robot, &fk(robot, s), f).unwrap();
    let v = (tp.pos - tm.pos) / (2.0 * H);
    let w = angular_rate(&tp.rot, &tm.rot);
    match r {
        Reference::LocalWorldAligned => Motion::new(v, w),
        Reference::Local => Motion::new(t0.rot.tr_mul(&v), t0.rot.tr_mul(&w)),
        Reference::World => Motion::new(v + t0.pos.cross(&w), w),
    }
}

fn motion_diff(p: Motion, m: Motion) -> Motion {
    Motion::new(
        (p.linear - m.linear) / (2.0 * H),
        (p.angular - m.angular) / (2.0 * H),
    )
}

/// Every frame of `robot` a user can name (the cut joints' excepted), and frame `last` with a
/// random offset.
fn frames(robot: &Robot, rng: &mut impl rand::Rng) -> Vec<FrameId> {
    let mut v: Vec<FrameId> = (0..=robot.nf())
        .filter_map(|j| robot.frame_id_of(j).ok())
        .collect();
    let r = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        0.3,
    );
    let off = Transform {
        rot: *nalgebra::Rotation3::new(r).matrix(),
        pos: Vector3::new(0.2, -0.1, rng.random_range(-0.5..0.5)),
    };
    v.push(v.last().unwrap().with_offset(&off));
    v
}

/// All checks on one robot and state.
fn check_robot(label: &str, robot: &Robot, s: &[Vec<f64>; 3], rng: &mut impl rand::Rng) {
    let n = robot.dof();
    let d0 = fk(robot, s);
    let (dp, dm) = (fk(robot, &at(s, H)), fk(robot, &at(s, -H)));
    let mut jac = DMatrix::zeros(6, n);
    let mut jd = DMatrix::zeros(6, n);
    let mut js = DMatrix::zeros(6, n);
    // a data holding another state: the support-only pass must not read its other links
    let mut stale = fk(robot, &at(s, 0.3));
    // the World columns stored by joint_jacobians_into (read as copies), and a data whose
    // stored columns are of another state, then placed at this one (they must not be read)
    let mut dj = KinematicsData::new(robot);
    joint_jacobians_into(robot, &mut dj, &s[0]).unwrap();
    let mut old_columns = KinematicsData::new(robot);
    joint_jacobians_into(robot, &mut old_columns, &at(s, 0.3)[0]).unwrap();
    placements_into(robot, &mut old_columns, &s[0]).unwrap();
    let qd = nalgebra::DVector::from_column_slice(&s[1]);
    let qdd = nalgebra::DVector::from_column_slice(&s[2]);
    for (fi, f) in frames(robot, rng).iter().enumerate() {
        for r in Reference::ALL {
            let ctx = format!("{label}, frame #{fi} (on {}), {}", f.parent(), r.name());
            // J q̇ = the velocity (recursion) = the derivative of the placement
            frame_jacobian_into(robot, &d0, f, r, &mut jac).unwrap();
            // from q on the frame's support only: the same Jacobian (the same products on
            // the support's placements), and the data then holds no full pass
            frame_jacobian_from_q_into(robot, &mut stale, &s[0], f, r, &mut js).unwrap();
            assert!(
                (&js - &jac).amax() <= 1e-15 * jac.amax().max(1.0),
                "{ctx}: support-only J"
            );
            for (what, d) in [
                ("stored columns", &dj),
                ("columns of another state", &old_columns),
            ] {
                frame_jacobian_into(robot, d, f, r, &mut js).unwrap();
                assert_eq!(js, jac, "{ctx}: J after {what}");
            }
            assert!(
                frame_placement(robot, &stale, f).is_err(),
                "{ctx}: level reset"
            );
            let v = frame_velocity(robot, &d0, f, r).unwrap();
            let fd = velocity_by_differences(robot, s, f, r);
            close(
                &format!("{ctx}: J qd vs FD"),
                (&jac * &qd).as_slice(),
                fd.to_vector().as_slice(),
            );
            close(
                &format!("{ctx}: velocity vs FD"),
                v.to_vector().as_slice(),
                fd.to_vector().as_slice(),
            );
            // d/dt (J q̇) = J̇ q̇ + J q̈, and the acceleration of the recursion
            let vd = motion_diff(
                frame_velocity(robot, &dp, f, r).unwrap(),
                frame_velocity(robot, &dm, f, r).unwrap(),
            );
            frame_jacobian_time_variation_into(robot, &d0, f, r, &mut jd).unwrap();
            let jdq = &jd * &qd + &jac * &qdd;
            close(
                &format!("{ctx}: dJ qd + J qdd vs FD"),
                jdq.as_slice(),
                vd.to_vector().as_slice(),
            );
            let acc = match r {
                Reference::LocalWorldAligned => frame_classical_acceleration(robot, &d0, f, r),
                _ => frame_acceleration(robot, &d0, f, r),
            }
            .unwrap();
            close(
                &format!("{ctx}: acceleration vs FD"),
                acc.to_vector().as_slice(),
                vd.to_vector().as_slice(),
            );
            // J̇ = d/dt J (along q + t q̇: J̇ does not depend on q̈)
            let path = [s[0].clone(), s[1].clone(), vec![0.0; n]];
            let jp = frame_jacobian(robot, &at(&path, H)[0], f, r).unwrap();
            let jm = frame_jacobian(robot, &at(&path, -H)[0], f, r).unwrap();
            let fd_j = (jp - jm) / (2.0 * H);
            close(&format!("{ctx}: dJ vs FD"), jd.as_slice(), fd_j.as_slice());
            // the classical drift is the classical acceleration at q̈ = 0
            let drift = frame_classical_drift(robot, &d0, f, r).unwrap();
            let at_rest = fk(robot, &path);
            let a0 = frame_classical_acceleration(robot, &at_rest, f, r).unwrap();
            close(
                &format!("{ctx}: drift"),
                drift.to_vector().as_slice(),
                a0.to_vector().as_slice(),
            );
        }
    }
    check_com(label, robot, s, &d0, &dp, &dm);
}

/// The centre of mass (whole robot and the subtree of each link) against differences.
fn check_com(
    label: &str,
    robot: &Robot,
    s: &[Vec<f64>; 3],
    d0: &KinematicsData,
    dp: &KinematicsData,
    dm: &KinematicsData,
) {
    let n = robot.dof();
    let qd = nalgebra::DVector::from_column_slice(&s[1]);
    let mut jcom = DMatrix::zeros(3, n);
    let roots: Vec<Option<FrameId>> = std::iter::once(None)
        .chain((1..=robot.nl()).map(|j| Some(robot.frame_id_of(j).unwrap())))
        .collect();
    let (mut d0, mut dp, mut dm) = (d0.clone(), dp.clone(), dm.clone());
    for root in &roots {
        let ctx = format!("{label}, CoM of {:?}", root.map(|f| f.parent()));
        let Ok(c0) = center_of_mass(robot, &mut d0, root.as_ref()) else {
            // a massless subtree: the mass says so too
            assert_eq!(
                subtree_mass(robot, root.as_ref().unwrap()).unwrap(),
                0.0,
                "{ctx}"
            );
            continue;
        };
        let cp = center_of_mass(robot, &mut dp, root.as_ref()).unwrap();
        let cm = center_of_mass(robot, &mut dm, root.as_ref()).unwrap();
        let v = (cp.position - cm.position) / (2.0 * H);
        let a = (cp.velocity - cm.velocity) / (2.0 * H);
        close(
            &format!("{ctx}: velocity"),
            c0.velocity.as_slice(),
            v.as_slice(),
        );
        close(
            &format!("{ctx}: acceleration"),
            c0.acceleration.as_slice(),
            a.as_slice(),
        );
        center_of_mass_jacobian_into(robot, &mut d0, root.as_ref(), &mut jcom).unwrap();
        close(
            &format!("{ctx}: Jcom qd"),
            (&jcom * &qd).as_slice(),
            v.as_slice(),
        );
        // from q in one forward and one backward pass (on a data of another state): the same
        // Jacobian, G of center_of_mass, and the placements left in the data
        let mut fresh = fk(robot, &at(s, 0.3));
        let mut jq = DMatrix::zeros(3, n);
        let g =
            center_of_mass_jacobian_from_q_into(robot, &mut fresh, &s[0], root.as_ref(), &mut jq)
                .unwrap();
        let scale = jcom.amax().max(c0.position.amax()).max(1.0);
        assert!(
            (&jq - &jcom).amax() <= 1e-14 * scale,
            "{ctx}: Jcom from q\n{jq}\nvs\n{jcom}"
        );
        assert!(
            (g - c0.position).amax() <= 1e-14 * scale,
            "{ctx}: G from q {g} vs {}",
            c0.position
        );
        let f = root.unwrap_or_else(|| robot.frame_id_of(robot.nl()).unwrap());
        assert_eq!(
            frame_placement(robot, &fresh, &f).unwrap(),
            frame_placement(robot, &d0, &f).unwrap(),
            "{ctx}: placements from q"
        );
        match root {
            None => assert!((c0.mass - total_mass(robot)).abs() < 1e-12, "{ctx}"),
            Some(f) => assert!(
                (c0.mass - subtree_mass(robot, f).unwrap()).abs() < 1e-12,
                "{ctx}"
            ),
        }
    }
}

#[test]
fn random_trees_match_finite_differences() {
    let mut rng = testing::rng(26);
    let opt = testing::TreeOptions::default();
    for case in 0..12 {
        let n = 2 + case % 7;
        let robot = testing::random_tree(&mut rng, n, &opt);
        let s = testing::random_state(&mut rng, robot.dof());
        check_robot(
            &format!("random tree {case} ({n} links)"),
            &robot,
            &s,
            &mut rng,
        );
    }
}

#[test]
fn bundled_robots_match_finite_differences() {
    let mut rng = testing::rng(2611);
    for name in [
        "rx90.toml",
        "rx90.urdf",
        "scara.toml",
        "tx40.toml",
        "torso2arms.toml",
        "sr400.toml",
        "fivebar.toml",
        "fourbar.toml",
        "spatial_loop.toml",
        "twoloops.toml",
    ] {
        let robot = common::robot(name);
        let s = testing::random_state(&mut rng, robot.dof());
        check_robot(name, &robot, &s, &mut rng);
    }
}

#[test]
fn placements_compose_like_the_geometric_model() {
    // frame_transforms (geometry.rs) is the library's other composition of iT_j
    let mut rng = testing::rng(7);
    let robot = testing::random_tree(&mut rng, 8, &testing::TreeOptions::default());
    let [q, _, _] = testing::random_state(&mut rng, robot.dof());
    let t = robodyn::geometry::frame_transforms(&robot, &q).unwrap();
    let mut d = KinematicsData::new(&robot);
    placements_into(&robot, &mut d, &q).unwrap();
    for j in 1..=robot.nf() {
        let f = robot.frame_id_of(j).unwrap();
        let ours = frame_placement(&robot, &d, &f).unwrap();
        assert!(
            (ours.matrix() - t[j - 1].matrix()).amax() < 1e-14,
            "frame {j}"
        );
        let base = robot.frame_id_of(0).unwrap();
        let rel = relative_placement(&robot, &d, &f, &base).unwrap();
        assert!((rel.compose(&ours).matrix() - Transform::identity().matrix()).amax() < 1e-14);
    }
}

fn rx90() -> Robot {
    common::robot("rx90.urdf")
}

#[test]
fn frame_names_resolve_and_unknown_names_list_near_ones() {
    let robot = rx90();
    // a URDF link, a URDF joint, a number
    for name in ["base", "link3", "elbow", "4"] {
        let f = robot.frame_id(name);
        assert!(f.is_ok(), "{name}: {f:?}");
    }
    let err = robot.frame_id("elbw").unwrap_err();
    assert!(matches!(err, Error::Input(_)), "{err:?}");
    let m = err.to_string();
    assert!(m.contains("`elbw`") && m.contains("`elbow`"), "{m}");
    assert!(robot.frame_id("99").is_err());
    // a cut joint's frame is refused, its twin is not
    let sr400 = common::robot("sr400.toml");
    let (nl, nj) = (sr400.nl(), sr400.nj());
    let e = sr400.frame_id_of(nl + 1).unwrap_err().to_string();
    assert!(
        e.contains("cut joint") && e.contains(&format!("twin frame {}", nj + 1)),
        "{e}"
    );
    assert!(sr400.frame_id_of(nj + 1).is_ok());
}

#[test]
fn wrong_lengths_nan_and_foreign_data_are_errors() {
    let robot = rx90();
    let n = robot.dof();
    let mut d = KinematicsData::new(&robot);
    let f = robot.frame_id("elbow").unwrap();
    // nothing computed yet
    let e = frame_placement(&robot, &d, &f).unwrap_err().to_string();
    assert!(e.contains("placements"), "{e}");
    let e = forward_kinematics_into(
        &robot,
        &mut d,
        &vec![0.0; n - 1],
        &vec![0.0; n],
        &vec![0.0; n],
    );
    assert!(
        matches!(e, Err(Error::Dimension { ref what, .. }) if what == "q"),
        "{e:?}"
    );
    let mut qd = vec![0.0; n];
    qd[2] = f64::NAN;
    let e = forward_kinematics_into(&robot, &mut d, &vec![0.0; n], &qd, &vec![0.0; n]);
    assert!(
        matches!(e, Err(Error::NotFinite { ref what, index: 2, .. }) if what == "qd"),
        "{e:?}"
    );
    // placements only: no velocity
    placements_into(&robot, &mut d, &vec![0.0; n]).unwrap();
    let e = frame_velocity(&robot, &d, &f, Reference::Local)
        .unwrap_err()
        .to_string();
    assert!(e.contains("forward_kinematics_into"), "{e}");
    // a wrongly sized output
    let mut bad = DMatrix::zeros(6, n + 1);
    let e = frame_jacobian_into(&robot, &d, &f, Reference::World, &mut bad);
    assert!(matches!(e, Err(Error::Dimension { .. })), "{e:?}");
    // data and frame of another robot
    let other = common::robot("scara.toml");
    let e = placements_into(&other, &mut d, &vec![0.0; other.dof()]);
    assert!(matches!(e, Err(Error::Dimension { .. })), "{e:?}");
    let g = other.frame_id_of(1).unwrap();
    let e = frame_placement(&robot, &d, &g);
    assert!(e.is_err(), "{e:?}");
    // overflow from finite inputs is an error, not an infinite number
    let e = forward_kinematics_into(
        &robot,
        &mut d,
        &vec![0.0; n],
        &vec![1e200; n],
        &vec![0.0; n],
    );
    assert!(matches!(e, Err(Error::Numerical(_))), "{e:?}");
}

#[test]
fn rpy_reads_back_at_and_near_the_gimbal_lock() {
    use robodyn::algorithms::kinematics::{rpy, tool_transform};
    use robodyn::model::Tool;
    let mut rng = testing::rng(3);
    let mut rots: Vec<Matrix3<f64>> = (0..200)
        .map(|_| {
            let v = Vector3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
            );
            *nalgebra::Rotation3::new(v).matrix()
        })
        .collect();
    // the body frame of a URDF joint along ±x (pitch ±pi/2), and near it
    for eps in [0.0, 1e-15, 1e-12, 1e-8, 1e-4] {
        for s in [1.0, -1.0] {
            let r = nalgebra::Rotation3::from_euler_angles(
                0.3,
                s * (std::f64::consts::FRAC_PI_2 - eps),
                -1.1,
            );
            rots.push(*r.matrix());
        }
    }
    for r in rots {
        let t = Tool {
            name: "t".into(),
            frame: 0,
            xyz: [0.0; 3],
            rpy: rpy(&r),
        };
        let back = tool_transform(&t).rot;
        assert!((back - r).amax() < 1e-15, "{r} -> {:?} -> {back}", t.rpy);
    }
}

const TOOL_ROBOT: &str = r#"
name = "2R with a tool"
[[frame]]
j = 1
ant = 0
[[frame]]
j = 2
ant = 1
d = 0.5
name = "elbow"
[[link]]
j = 1
M = 1
[[link]]
j = 2
M = 1
name = "forearm"
"#;

#[test]
fn toml_tools_resolve_read_back_and_move_with_their_frame() {
    use robodyn::io::toml_format::{parse_description, parse_robot, write_description};
    let text = format!(
        "{TOOL_ROBOT}\n[[tool]]\nname = \"tcp\"\nframe = \"forearm\"\nxyz = [0.3, 0, 0]\nrpy = [0, 0, \"pi/2\"]\n"
    );
    let robot = parse_robot(&text, None).unwrap();
    let tcp = robot.frame_id("tcp").unwrap();
    assert_eq!(tcp.parent(), 2);
    // at q = (pi/2, 0): O_tcp = 0.5 y0 + 0.3 y0, x_tcp = -x0
    let mut d = KinematicsData::new(&robot);
    placements_into(&robot, &mut d, &[std::f64::consts::FRAC_PI_2, 0.0]).unwrap();
    let t = frame_placement(&robot, &d, &tcp).unwrap();
    assert!(
        (t.pos - Vector3::new(0.0, 0.8, 0.0)).norm() < 1e-15,
        "{}",
        t.pos
    );
    assert!(
        (t.rot.column(0) - Vector3::new(-1.0, 0.0, 0.0)).norm() < 1e-15,
        "{}",
        t.rot
    );
    // written and read back: the same description
    let (desc, _) = parse_description(&text, None).unwrap();
    let (back, _) = parse_description(&write_description(&desc), None).unwrap();
    assert_eq!(back.tools, desc.tools);
}

#[test]
fn bad_tools_are_errors_at_their_line() {
    use robodyn::io::toml_format::parse_robot;
    let line = TOOL_ROBOT.lines().count() + 2; // the [[tool]] header
    for (tool, reason) in [
        (
            "name = \"t\"\nframe = \"wrist\"",
            "no frame or link is named `wrist`",
        ),
        ("name = \"t\"\nframe = 7", "frame 7 does not exist"),
        ("name = \"t\"\nframe = 2\nxyz = [1, 2]", "xyz has 2 entries"),
        (
            "name = \"t\"\nframe = 2\nrpy = [0, 0, \"q\"]",
            "unknown symbol",
        ),
        (
            "name = \"t\"\nframe = 2\n[[tool]]\nname = \"t\"\nframe = 1",
            "two tools are named `t`",
        ),
        ("frame = 2", "name"),
    ] {
        let text = format!("{TOOL_ROBOT}\n[[tool]]\n{tool}\n");
        let e = parse_robot(&text, Some("r.toml")).unwrap_err().to_string();
        assert!(e.contains(reason), "{tool}: {e}");
        let at = format!("r.toml:{}", line);
        let at_next = format!("r.toml:{}", line + 1);
        let at_later = format!("r.toml:{}", line + 3);
        assert!(
            e.contains(&at)
                || e.contains(&at_next)
                || e.contains(&at_later)
                || e.contains(&format!("r.toml:{}", line + 2)),
            "{tool}: no line in {e}"
        );
    }
}

#[test]
fn frame_motion_read_after_newton_euler_equals_the_forward_pass() {
    use robodyn::algorithms::kinematics::frame_motion_from_newton_euler;
    use robodyn::{inverse_dynamics_into, Data};
    let mut rng = testing::rng(1126);
    let opt = testing::TreeOptions {
        gravity: None, // a random gravity: the read must take it off
        ..Default::default()
    };
    for case in 0..8 {
        let robot = testing::random_tree(&mut rng, 3 + case, &opt);
        let s = testing::random_state(&mut rng, robot.dof());
        let mut data = Data::new(&robot);
        let env = robot.environment().clone();
        let mut tau = vec![0.0; robot.dof()];
        inverse_dynamics_into(&robot, &mut data, &env, &s[0], &s[1], &s[2], &mut tau).unwrap();
        let kd = fk(&robot, &s);
        for f in frames(&robot, &mut rng) {
            let ne = frame_motion_from_newton_euler(&robot, &data, &env, &f).unwrap();
            let t = frame_placement(&robot, &kd, &f).unwrap();
            let a = frame_classical_acceleration(&robot, &kd, &f, Reference::LocalWorldAligned)
                .unwrap();
            let v = frame_velocity(&robot, &kd, &f, Reference::LocalWorldAligned).unwrap();
            let ctx = format!("tree {case}, frame on {}", f.parent());
            let tol = |x: f64| 1e-12 * x.max(1.0);
            assert!(
                (ne.placement.matrix() - t.matrix()).amax() < 1e-12,
                "{ctx}: placement"
            );
            assert!(
                (ne.angular_velocity - v.angular).amax() < tol(v.angular.amax()),
                "{ctx}: w"
            );
            assert!(
                (ne.angular_acceleration - a.angular).amax() < tol(a.angular.amax()),
                "{ctx}: wd"
            );
            assert!(
                (ne.linear_acceleration - a.linear).amax() < tol(a.linear.amax()),
                "{ctx}: a {} vs {}",
                ne.linear_acceleration,
                a.linear
            );
        }
    }
}
