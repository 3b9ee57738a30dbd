//! Geometric model cross-checks: `geometry::frame_transforms` (0T_j) against an independent
//! product of the elementary 4x4 matrices
//! `iT_j = Rot(z, gamma) Trans(z, b) Rot(x, alpha) Trans(x, d) Rot(z, theta) Trans(z, r)`
//! written directly from the description, multiplied along the path from the base; iP_j against
//! eq 10.18; and the SR400's loop closure of Example 10.1.
#[path = "common/frames.rs"]
mod frames;

use nalgebra::{Matrix4, Vector3};
use rand::Rng;
use robodyn::geometry::{frame_transforms, local_transform};
use robodyn::model::JointType;
use robodyn::Robot;
use robodyn_testing::{self as testing, random_tree, TreeOptions};
use std::f64::consts::FRAC_PI_2;
use std::path::PathBuf;

fn rot_z(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(
        c, -s, 0.0, 0.0, //
        s, c, 0.0, 0.0, //
        0.0, 0.0, 1.0, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

fn rot_x(a: f64) -> Matrix4<f64> {
    let (s, c) = a.sin_cos();
    Matrix4::new(
        1.0, 0.0, 0.0, 0.0, //
        0.0, c, -s, 0.0, //
        0.0, s, c, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

fn trans(x: f64, y: f64, z: f64) -> Matrix4<f64> {
    let mut m = Matrix4::identity();
    m[(0, 3)] = x;
    m[(1, 3)] = y;
    m[(2, 3)] = z;
    m
}

/// The six parameters of frame j with the joint variable added: (gamma, b, alpha, d, theta, r).
fn parameters(robot: &Robot, j: usize, q: f64) -> [f64; 6] {
    let f = robot.frame(j);
    let v = |e: &robodyn::Expr| {
        e.eval(&|s| robot.description().symbols.get(s).copied())
            .unwrap()
    };
    let (mut theta, mut r) = (v(&f.theta), v(&f.r));
    match f.joint {
        JointType::Revolute => theta += q,
        JointType::Prismatic => r += q,
        JointType::Fixed => {}
    }
    [v(&f.gamma), v(&f.b), v(&f.alpha), v(&f.d), theta, r]
}

/// iT_j from the elementary matrices.
fn elementary(robot: &Robot, j: usize, q: f64) -> Matrix4<f64> {
    let [gamma, b, alpha, d, theta, r] = parameters(robot, j, q);
    rot_z(gamma)
        * trans(0.0, 0.0, b)
        * rot_x(alpha)
        * trans(d, 0.0, 0.0)
        * rot_z(theta)
        * trans(0.0, 0.0, r)
}

/// 0T_j by walking the antecedents from j down to the base: 0T_j = ... a(a(j))T_a(j) a(j)T_j.
fn path_product(robot: &Robot, j: usize, q: &[f64]) -> Matrix4<f64> {
    let mut t = Matrix4::identity();
    let mut k = j;
    while k != 0 {
        t = elementary(robot, k, q.get(k - 1).copied().unwrap_or(0.0)) * t;
        k = robot.ant(k);
    }
    t
}

fn max_abs(m: &Matrix4<f64>) -> f64 {
    m.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

#[test]
fn frame_transforms_match_elementary_products_on_random_trees() {
    let mut rng = testing::rng(0x9e0);
    let mut worst = 0.0f64;
    for n in 1..=30 {
        for _ in 0..4 {
            let opt = TreeOptions {
                p_prismatic: 0.3,
                p_fixed: 0.15,
                p_serial: rng.random_range(0.2..1.0),
                ..TreeOptions::default()
            };
            let robot = random_tree(&mut rng, n, &opt);
            let q: Vec<f64> = (0..n).map(|_| rng.random_range(-3.0..3.0)).collect();
            // the public entry point takes the movable joints (fixed frames carry no value)
            let c = robot.coordinates();
            let movable: Vec<f64> = c.frames().iter().map(|&j| q[j - 1]).collect();
            let t = frame_transforms(&robot, &movable).unwrap();
            assert_eq!(t.len(), n);
            for j in 1..=n {
                let d = max_abs(&(t[j - 1].matrix() - path_product(&robot, j, &q)));
                assert!(d < 1e-12, "{n} links, frame {j}: 0T_j differs by {d:e}");
                worst = worst.max(d);
            }
        }
    }
    eprintln!("0T_j vs elementary products: max abs difference {worst:.2e}");
}

/// iP_j = [d C(gamma) + r S(gamma) S(alpha), d S(gamma) - r C(gamma) S(alpha), r C(alpha) + b]
/// (eq 10.18) and iA_j = Rz(gamma) Rx(alpha) Rz(theta), checked on each local transform.
#[test]
fn local_transforms_match_eq_10_18() {
    let mut rng = testing::rng(1018);
    for n in [3, 10, 30] {
        let robot = random_tree(&mut rng, n, &TreeOptions::default());
        for j in 1..=n {
            let q = rng.random_range(-3.0..3.0);
            let [g, b, a, d, theta, r] = parameters(&robot, j, q);
            let p = Vector3::new(
                d * g.cos() + r * g.sin() * a.sin(),
                d * g.sin() - r * g.cos() * a.sin(),
                r * a.cos() + b,
            );
            let t = local_transform(&robot, j, q);
            assert!(
                (t.pos - p).norm() < 1e-14,
                "frame {j}: iP_j {} vs {p}",
                t.pos
            );
            let rot = rot_z(g) * rot_x(a) * rot_z(theta);
            let dr = (t.rot - rot.fixed_view::<3, 3>(0, 0)).abs().max();
            assert!(dr < 1e-14, "frame {j}: iA_j differs by {dr:e}");
        }
    }
}

/// SR400: with theta3 = theta7 + pi/2 - theta2 and theta8 = theta2 - theta7 (Example 10.1) the
/// cut joint's frame 9 and its twin frame 10 share their origin and z axis (the loop closes);
/// with other values of theta3 they do not.
#[test]
fn sr400_loop_closes_with_example_10_1() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml");
    let robot = robodyn::io::load(&path).unwrap();
    assert_eq!((robot.nl(), robot.nj(), robot.nf()), (8, 9, 10));
    let mut rng = testing::rng(10);
    for _ in 0..20 {
        let mut q: Vec<f64> = (0..8).map(|_| rng.random_range(-2.0..2.0)).collect();
        q[2] = q[6] + FRAC_PI_2 - q[1];
        q[7] = q[1] - q[6];
        let t = frames::per_frame(&robot, &q);
        assert_eq!(t.len(), 10);
        let (t9, t10) = (&t[8], &t[9]);
        assert!(
            (t9.pos - t10.pos).norm() < 1e-12,
            "O9 {} vs O10 {}",
            t9.pos,
            t10.pos
        );
        let (z9, z10) = (t9.rot.column(2), t10.rot.column(2));
        assert!((z9 - z10).norm() < 1e-12, "z9 {z9} vs z10 {z10}");
        // Off the closure manifold the loop is open.
        q[2] += 0.1;
        let t = frames::per_frame(&robot, &q);
        assert!((t[8].pos - t[9].pos).norm() > 1e-3);
    }
}

/// Regression (issue 25, item 2): `frame_transforms` takes the movable-joint vector of every
/// other function. On a URDF with a fixed joint between two revolute ones, q = [0, 1] is joint 1
/// at 0 and joint 3 at 1 rad: 0T_3 must be the product of the elementary matrices with q3 = 1
/// (it used to read q as per-frame values, giving the fixed frame the 1 and joint 3 a 0), and
/// a vector over the frames (3 entries) is an error, not a silent placement.
#[test]
fn frame_transforms_take_the_movable_joints_of_a_urdf_with_a_fixed_joint() {
    let urdf = r#"<robot name="fixed_between">
      <link name="base"/><link name="l1"/><link name="l2"/><link name="l3"/>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
        <origin xyz="0 0 0.3"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
      <joint name="weld" type="fixed"><parent link="l1"/><child link="l2"/>
        <origin xyz="0.4 0 0" rpy="1.5707963267948966 0 0"/></joint>
      <joint name="j3" type="revolute"><parent link="l2"/><child link="l3"/>
        <origin xyz="0.2 0.1 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
    </robot>"#;
    let (desc, _) = robodyn::io::urdf::parse_description(urdf, None).unwrap();
    let robot = Robot::new(desc).unwrap();
    assert_eq!(robot.dof(), 2);
    let c = robot.coordinates();
    let (f1, f3) = (c.frame(0), c.frame(1));
    assert!(f3 > f1 + 1, "a fixed frame between the two joints");
    let t = frame_transforms(&robot, &[0.0, 1.0]).unwrap();
    // independent: the elementary matrices with the per-frame values (joint 3 at 1 rad)
    let mut per_frame = vec![0.0; robot.nl()];
    per_frame[f3 - 1] = 1.0;
    for j in 1..=robot.nf() {
        let d = max_abs(&(t[j - 1].matrix() - path_product(&robot, j, &per_frame)));
        assert!(d < 1e-12, "frame {j}: 0T_j differs by {d:e}");
    }
    // and the joint really turned: 0T_3(q3 = 1) = 0T_3(0) Rz(1)
    let t0 = frame_transforms(&robot, &[0.0, 0.0]).unwrap();
    let d = max_abs(&(t[f3 - 1].matrix() - t0[f3 - 1].matrix() * rot_z(1.0)));
    assert!(d < 1e-12, "0T_3 is not turned by q3 = 1: {d:e}");
    // a per-frame array, a short vector, a NaN: errors
    assert!(frame_transforms(&robot, &[0.0, 0.0, 1.0]).is_err());
    assert!(frame_transforms(&robot, &[0.0]).is_err());
    assert!(frame_transforms(&robot, &[0.0, f64::NAN]).is_err());
}
