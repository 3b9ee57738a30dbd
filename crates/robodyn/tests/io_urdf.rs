//! URDF import is exact: on random URDF trees (fixed seeds), the frames computed from our six
//! parameters by the geometric model coincide with the URDF forward kinematics (composition of
//! joint origins xyz/rpy and axis motions, written here independently with explicit matrices),
//! and the converted inertial parameters give the same mass, centre of mass and inertia in the
//! world frame.
#[path = "common/frames.rs"]
mod frames;

use nalgebra::{Matrix3, Vector3};
use rand::Rng;
use robodyn::model::param;
use robodyn::Robot;
use robodyn_testing as testing;
use std::f64::consts::FRAC_PI_2;

fn rx(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
fn ry(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}
fn rz(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}
/// URDF rpy: fixed-axis roll about x, then pitch about y, then yaw about z.
fn rpy(r: [f64; 3]) -> Matrix3<f64> {
    rz(r[2]) * ry(r[1]) * rx(r[0])
}
/// Rodrigues' formula for a rotation by q about the unit vector a.
fn axis_angle(a: Vector3<f64>, q: f64) -> Matrix3<f64> {
    let k = Matrix3::new(0.0, -a.z, a.y, a.z, 0.0, -a.x, -a.y, a.x, 0.0);
    Matrix3::identity() + q.sin() * k + (1.0 - q.cos()) * k * k
}

struct J {
    name: String,
    kind: &'static str,
    parent: usize,
    xyz: [f64; 3],
    rpy: [f64; 3],
    axis: Vector3<f64>,
}
struct L {
    com: [f64; 3],
    rpy: [f64; 3],
    mass: f64,
    inertia: [f64; 6],
}

fn random_urdf(rng: &mut impl Rng, n: usize) -> (String, Vec<J>, Vec<L>) {
    let angle = |rng: &mut dyn rand::RngCore| -> f64 {
        if rng.random_bool(0.5) {
            rng.random_range(-3.1..3.1)
        } else {
            [0.0, FRAC_PI_2, -FRAC_PI_2, std::f64::consts::PI][rng.random_range(0..4)]
        }
    };
    let mut joints = Vec::new();
    let mut links = Vec::new();
    for k in 0..=n {
        let m: f64 = rng.random_range(0.1..5.0);
        let (a, b, c) = (
            rng.random_range(0.01..0.5),
            rng.random_range(0.01..0.5),
            rng.random_range(0.01..0.5),
        );
        // a physically consistent inertia about the COM, with products
        let r = rpy([angle(rng), angle(rng), angle(rng)]);
        let i = r * Matrix3::from_diagonal(&Vector3::new(b + c, a + c, a + b)) * r.transpose() * m;
        links.push(L {
            com: [
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.3..0.3),
                rng.random_range(-0.3..0.3),
            ],
            rpy: [angle(rng), angle(rng), angle(rng)],
            mass: m,
            inertia: [
                i[(0, 0)],
                i[(0, 1)],
                i[(0, 2)],
                i[(1, 1)],
                i[(1, 2)],
                i[(2, 2)],
            ],
        });
        if k == 0 {
            continue;
        }
        let kind = ["revolute", "continuous", "prismatic", "fixed"][rng.random_range(0..4)];
        let axis = match rng.random_range(0..7) {
            0 => Vector3::z(),
            1 => Vector3::x(),
            2 => -Vector3::y(),
            3 => -Vector3::z(),
            4 => Vector3::new(1e-7, 0.0, 1.0).normalize(), // nearly parallel to z
            _ => Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            )
            .normalize(),
        };
        let zero_origin = rng.random_bool(0.15);
        joints.push(J {
            name: format!("joint_{k}"),
            kind,
            parent: if k == 1 || rng.random_bool(0.5) {
                k - 1
            } else {
                rng.random_range(0..k)
            },
            xyz: if zero_origin {
                [0.0; 3]
            } else {
                [
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                    rng.random_range(-0.5..0.5),
                ]
            },
            rpy: if zero_origin {
                [0.0; 3]
            } else {
                [angle(rng), angle(rng), angle(rng)]
            },
            axis,
        });
    }
    let f = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:?}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut s = String::from("<?xml version=\"1.0\"?>\n<robot name=\"random\">\n");
    for (k, l) in links.iter().enumerate() {
        let i = l.inertia;
        s += &format!(
            "  <link name=\"link_{k}\">\n    <inertial>\n      <origin xyz=\"{}\" rpy=\"{}\"/>\n      <mass value=\"{:?}\"/>\n      <inertia ixx=\"{:?}\" ixy=\"{:?}\" ixz=\"{:?}\" iyy=\"{:?}\" iyz=\"{:?}\" izz=\"{:?}\"/>\n    </inertial>\n  </link>\n",
            f(&l.com), f(&l.rpy), l.mass, i[0], i[1], i[2], i[3], i[4], i[5]
        );
    }
    // joints written in reverse order: the numbering must not depend on the file order
    for (k, j) in joints.iter().enumerate().rev() {
        s += &format!(
            "  <joint name=\"{}\" type=\"{}\">\n    <parent link=\"link_{}\"/>\n    <child link=\"link_{}\"/>\n    <origin xyz=\"{}\" rpy=\"{}\"/>\n    <axis xyz=\"{}\"/>\n  </joint>\n",
            j.name, j.kind, j.parent, k + 1, f(&j.xyz), f(&j.rpy), f(j.axis.as_slice())
        );
    }
    s += "</robot>\n";
    (s, joints, links)
}

/// URDF forward kinematics: (rotation, position) of every link frame, link 0 the base.
fn urdf_fk(joints: &[J], q: &dyn Fn(usize) -> f64) -> Vec<(Matrix3<f64>, Vector3<f64>)> {
    let mut out = vec![(Matrix3::identity(), Vector3::zeros())];
    for (k, j) in joints.iter().enumerate() {
        let (pr, pp) = out[j.parent];
        let mut r = pr * rpy(j.rpy);
        let mut p = pp + pr * Vector3::from(j.xyz);
        match j.kind {
            "revolute" | "continuous" => r *= axis_angle(j.axis, q(k)),
            "prismatic" => p += r * j.axis * q(k),
            _ => {}
        }
        out.push((r, p));
    }
    out
}

fn load(text: &str) -> Robot {
    let (d, _) = robodyn::io::urdf::parse_description(text, Some("random.urdf")).unwrap();
    Robot::new(d).unwrap()
}

#[test]
fn frames_match_urdf_forward_kinematics() {
    let mut worst: f64 = 0.0;
    for seed in 0..40u64 {
        let mut rng = testing::rng(seed);
        let n = rng.random_range(2..16);
        let (text, joints, _) = random_urdf(&mut rng, n);
        let robot = load(&text);
        let frame_of = |k: usize| -> usize {
            (1..=robot.nf())
                .find(|&j| robot.frame(j).name == joints[k].name)
                .unwrap()
        };
        let mut c_ref: Vec<Option<Matrix3<f64>>> = vec![None; n];
        for _ in 0..5 {
            let qv: Vec<f64> = (0..robot.nl())
                .map(|_| rng.random_range(-3.0..3.0))
                .collect();
            let q_of = |k: usize| qv[frame_of(k) - 1];
            let fk = urdf_fk(&joints, &q_of);
            let ours = frames::per_frame(&robot, &qv);
            for (k, jt) in joints.iter().enumerate() {
                let t = &ours[frame_of(k) - 1];
                let (lr, lp) = fk[k + 1];
                let e_pos = (t.pos - lp).norm();
                // z_j along the joint axis (for movable joints)
                let e_axis = if jt.kind == "fixed" {
                    0.0
                } else {
                    (t.rot * Vector3::z() - lr * jt.axis).norm()
                };
                // the link frame is fixed in R_j: L^T 0R_j does not depend on q
                let c = lr.transpose() * t.rot;
                let e_c = match c_ref[k] {
                    Some(c0) => (c - c0).norm(),
                    None => {
                        c_ref[k] = Some(c);
                        0.0
                    }
                };
                let e = e_pos.max(e_axis).max(e_c);
                worst = worst.max(e);
                assert!(
                    e < 1e-12,
                    "seed {seed}, joint {}: pos {e_pos:e}, axis {e_axis:e}, frame {e_c:e}",
                    jt.name
                );
            }
        }
    }
    eprintln!("worst frame difference: {worst:e}");
}

#[test]
fn inertials_match_in_the_world_frame() {
    for seed in 100..130u64 {
        let mut rng = testing::rng(seed);
        let n = rng.random_range(2..10);
        let (text, joints, links) = random_urdf(&mut rng, n);
        let robot = load(&text);
        let qv: Vec<f64> = (0..robot.nl())
            .map(|_| rng.random_range(-3.0..3.0))
            .collect();
        let frame_of = |k: usize| {
            (1..=robot.nf())
                .find(|&j| robot.frame(j).name == joints[k].name)
                .unwrap()
        };
        let fk = urdf_fk(&joints, &|k| qv[frame_of(k) - 1]);
        let ours = frames::per_frame(&robot, &qv);
        let k13 = robot.standard_parameters();
        for k in 0..n {
            let j = frame_of(k);
            let p = &k13[13 * (j - 1)..13 * j];
            let l = &links[k + 1];
            // URDF: world COM and world inertia about the COM
            let (lr, lp) = fk[k + 1];
            let com_w = lp + lr * Vector3::from(l.com);
            let i = l.inertia;
            let ig = Matrix3::new(i[0], i[1], i[2], i[1], i[3], i[4], i[2], i[4], i[5]);
            let r = lr * rpy(l.rpy);
            let ig_w = r * ig * r.transpose();
            // ours: MS/M in R_j, J_G = J_O - M (c'c I - c c')
            let t = &ours[j - 1];
            let m = p[param::M];
            let c = Vector3::new(p[param::MX], p[param::MY], p[param::MZ]) / m;
            let jo = Matrix3::new(p[0], p[1], p[2], p[1], p[3], p[4], p[2], p[4], p[5]);
            let jg = jo - m * (c.dot(&c) * Matrix3::identity() - c * c.transpose());
            let ours_com = t.pos + t.rot * c;
            let ours_ig = t.rot * jg * t.rot.transpose();
            assert!((m - l.mass).abs() < 1e-14, "seed {seed}: mass");
            assert!(
                (ours_com - com_w).norm() < 1e-12,
                "seed {seed}, joint {}: com {:e}",
                k + 1,
                (ours_com - com_w).norm()
            );
            assert!(
                (ours_ig - ig_w).norm() < 1e-11 * (1.0 + ig_w.norm()),
                "seed {seed}, joint {}: inertia {:e}",
                k + 1,
                (ours_ig - ig_w).norm()
            );
        }
    }
}

#[test]
fn joint_types_names_mimic_and_common_axes() {
    let text = r#"<robot name="mini">
  <link name="base"/>
  <link name="a"/>
  <link name="b"/>
  <link name="c"/>
  <joint name="shoulder" type="continuous"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
     <origin xyz="0.5 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/><dynamics damping="0.7" friction="0.2"/></joint>
  <joint name="finger" type="revolute"><parent link="b"/><child link="c"/><axis xyz="0 1 0"/>
     <mimic joint="shoulder" multiplier="2" offset="0.1"/></joint>
</robot>"#;
    let (d, _) = robodyn::io::urdf::parse_description(text, None).unwrap();
    assert_eq!(d.nl, 3);
    let names: Vec<&str> = d.frames.iter().map(|f| f.name.as_str()).collect();
    assert_eq!(names, ["shoulder", "slide", "finger"]);
    let sig: Vec<u8> = d.frames.iter().map(|f| f.joint.sigma()).collect();
    assert_eq!(sig, [0, 1, 0]);
    // parallel axes 0.5 apart: d = 0.5 along x, everything else zero
    let f2 = &d.frames[1];
    assert_eq!(f2.d.as_f64(), Some(0.5));
    for e in [&f2.gamma, &f2.b, &f2.alpha, &f2.theta, &f2.r] {
        assert!(e.is_zero(), "{e}");
    }
    // axis y after axis z, same origin: alpha = -pi/2 exactly (x along the common normal)
    let alpha = d.frames[2].alpha.eval(&|_| None).unwrap();
    assert!((alpha + FRAC_PI_2).abs() < 1e-15, "alpha = {alpha}");
    assert!(d.frames[2].alpha.as_f64().is_none(), "-pi/2 is kept exact");
    assert_eq!(d.links[1].params[param::FV].as_f64(), Some(0.7));
    assert_eq!(d.links[1].params[param::FS].as_f64(), Some(0.2));
    assert!(
        d.notes
            .iter()
            .any(|n| n.contains("joint finger mimics shoulder")),
        "{:?}",
        d.notes
    );
}
#[test]
fn decompose_recomposes_any_placement() {
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};
    use robodyn::io::urdf::decompose;
    let mut rng = testing::rng(7);
    let mut worst: f64 = 0.0;
    for k in 0..2000 {
        let axis = Vector3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        let angle = match k % 4 {
            0 => rng.random_range(-3.1..3.1),
            1 => 0.0,
            2 => std::f64::consts::PI,
            _ => rng.random_range(-1e-3..1e-3),
        };
        let t = Isometry3::from_parts(
            Translation3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
            ),
            UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle),
        );
        // nearly parallel axes are split by an auxiliary frame Rx(pi/2), as the importer does
        let parts = if robodyn::io::urdf::needs_auxiliary_frame(&t) {
            let aux = Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), FRAC_PI_2),
            );
            vec![aux, aux.inverse() * t]
        } else {
            vec![t]
        };
        let (mut rot, mut pos) = (Matrix3::identity(), Vector3::zeros());
        for part in &parts {
            let [g, b, al, d, th, r] = decompose(part);
            // Rz(g) Tz(b) Rx(al) Tx(d) Rz(th) Tz(r), composed with explicit matrices
            let lr = rz(g) * rx(al) * rz(th);
            let lp = rz(g)
                * (Vector3::new(0.0, 0.0, b)
                    + rx(al) * (Vector3::new(d, 0.0, 0.0) + rz(th) * Vector3::new(0.0, 0.0, r)));
            pos += rot * lp;
            rot *= lr;
        }
        let e = (rot - t.rotation.to_rotation_matrix().matrix()).norm()
            + (pos - t.translation.vector).norm();
        worst = worst.max(e);
        assert!(e < 1e-12, "case {k}: {e:e}");
    }
    eprintln!("worst recomposition error: {worst:e}");
}
