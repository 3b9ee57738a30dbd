//! The customized geometric and kinematic models (`ModelKind::Dgm`, `ModelKind::Jacobian`)
//! against the numeric routes, on random q, to 1e-12:
//! - iT_j against `geometry::frame_transforms`: (0T_i)^-1 0T_j;
//! - iJ_j against the derivative of the numeric DGM: the frames' numeric transforms composed on
//!   hyper-dual numbers (exact to rounding), the angular rows from dA/dq A^T, both rotated into
//!   frame i; that derivative is itself checked against central differences of
//!   `frame_transforms`.
//!
//! Robots: the RX-90 (symbolic and numeric), the TX40, the SCARA, the SR400's equivalent tree
//! and a random tree with fixed frames (frames on different branches, a fixed frame as j).
//! `codegen_compile.rs` compiles and runs the same programs in Rust, C, Python and MATLAB
//! ([`kinematic_cases`]).

use nalgebra::{Matrix3, Vector3};
use num_dual::HyperDual64;
use rand::Rng;
use robodyn::codegen::{generate, Frames, GenOptions, ModelKind};
use robodyn::geometry::{frame_transforms, Transform};
use robodyn::model::FrameConstants;
use robodyn::{Robot, RobotDescription};
use robodyn_symbolic::Program;
use robodyn_testing::{random_tree_description, rng, TreeOptions};
use std::path::Path;

/// A generated program, its inputs per state (q, then the parameters `p` when it takes them)
/// and the reference outputs.
pub(crate) struct KinematicCase {
    pub prog: Program,
    pub inputs: Vec<Vec<Vec<f64>>>,
    pub expected: Vec<Vec<f64>>,
    pub what: String,
}

fn robot_file(name: &str) -> RobotDescription {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../robots")
        .join(name);
    robodyn::io::load_description(&path).unwrap()
}

/// 0T_k (k = 0: the identity).
fn placement(t: &[Transform], k: usize) -> Transform {
    if k == 0 {
        Transform::identity()
    } else {
        t[k - 1]
    }
}

/// iT_j from `frame_transforms`, as [s n a P] column by column.
fn dgm_reference(robot: &Robot, q: &[f64], i: usize, j: usize) -> Vec<f64> {
    let t = frame_transforms(robot, q).unwrap();
    let tij = placement(&t, i).inverse().compose(&placement(&t, j));
    tij.rot.iter().chain(tij.pos.iter()).copied().collect()
}

/// 0A_j, 0P_j composed from the numeric frames on hyper-dual numbers, with the movable joint
/// `seed` (index in the joint vector) carrying the derivative direction.
fn dual_placement(
    robot: &Robot,
    q: &[f64],
    seed: usize,
    j: usize,
) -> (Matrix3<HyperDual64>, Vector3<HyperDual64>) {
    let frames = robot.coordinates().frames();
    let mut rot = Matrix3::identity();
    let mut pos = Vector3::zeros();
    let mut path = vec![j];
    while let Some(&k) = path.last().filter(|&&k| k != 0) {
        path.push(robot.ant(k));
    }
    for &k in path.iter().rev().skip(1) {
        let f: FrameConstants<HyperDual64> =
            robot.numeric().frame(k).map(|x| HyperDual64::from_re(*x));
        let qk = match frames.iter().position(|&m| m == k) {
            Some(c) => HyperDual64::new(q[c], if c == seed { 1.0 } else { 0.0 }, 0.0, 0.0),
            None => HyperDual64::from_re(0.0),
        };
        let (r, p) = f.transform(&qk);
        pos += rot * p;
        rot *= r;
    }
    (rot, pos)
}

/// Column c of a 6 x n Jacobian stored row by row: [iA_0 v; iA_0 w].
fn put_column(jac: &mut [f64], c: usize, to_i: &Matrix3<f64>, v: Vector3<f64>, w: Vector3<f64>) {
    let n = jac.len() / 6;
    let (v, w) = (to_i * v, to_i * w);
    for r in 0..3 {
        jac[r * n + c] = v[r];
        jac[(r + 3) * n + c] = w[r];
    }
}

/// iJ_j, 6 x n row by row: d 0P_j / dq and the axial vector of d 0A_j / dq 0A_j^T for each
/// movable joint, rotated into frame i.
fn jacobian_reference(robot: &Robot, q: &[f64], i: usize, j: usize) -> Vec<f64> {
    let n = q.len();
    let t = frame_transforms(robot, q).unwrap();
    let to_i = placement(&t, i).rot.transpose();
    let mut jac = vec![0.0; 6 * n];
    for c in 0..n {
        let (rot, pos) = dual_placement(robot, q, c, j);
        let a = rot.map(|x| x.re);
        let da = rot.map(|x| x.eps1);
        let v = pos.map(|x| x.eps1);
        let w_skew = da * a.transpose();
        let w = Vector3::new(w_skew[(2, 1)], w_skew[(0, 2)], w_skew[(1, 0)]);
        put_column(&mut jac, c, &to_i, v, w);
    }
    jac
}

/// Central differences of `frame_transforms` (h = 1e-6): iJ_j, row by row.
fn jacobian_differences(robot: &Robot, q: &[f64], i: usize, j: usize) -> Vec<f64> {
    let n = q.len();
    let h = 1e-6;
    let t = frame_transforms(robot, q).unwrap();
    let to_i = placement(&t, i).rot.transpose();
    let a = placement(&t, j).rot;
    let mut jac = vec![0.0; 6 * n];
    for c in 0..n {
        let at = |d: f64| {
            let mut x = q.to_vec();
            x[c] += d;
            placement(&frame_transforms(robot, &x).unwrap(), j)
        };
        let (plus, minus) = (at(h), at(-h));
        let v = (plus.pos - minus.pos) / (2.0 * h);
        let w_skew = (plus.rot - minus.rot) / (2.0 * h) * a.transpose();
        let w = Vector3::new(w_skew[(2, 1)], w_skew[(0, 2)], w_skew[(1, 0)]);
        put_column(&mut jac, c, &to_i, v, w);
    }
    jac
}

fn random_q(r: &mut impl Rng, n: usize) -> Vec<f64> {
    (0..n).map(|_| r.random_range(-3.0..3.0)).collect()
}

/// The robots and frames checked: (tag, description, frames, numeric).
fn setups() -> Vec<(String, RobotDescription, Frames, bool)> {
    let f = |frame: Option<usize>, reference: Option<usize>| Frames { frame, reference };
    let mut out = Vec::new();
    let rx90 = robot_file("rx90.toml");
    for (k, frames) in [
        Frames::TERMINAL,
        f(None, None),
        f(None, Some(3)),
        f(Some(4), Some(2)),
        f(Some(2), Some(5)),
    ]
    .into_iter()
    .enumerate()
    {
        out.push((format!("rx90_{k}"), rx90.clone(), frames, false));
    }
    out.push(("rx90_num".into(), rx90, Frames::TERMINAL, true));
    for (tag, file) in [("tx40", "tx40.toml"), ("scara", "scara.toml")] {
        let d = robot_file(file);
        out.push((format!("{tag}_0"), d.clone(), Frames::TERMINAL, false));
        out.push((format!("{tag}_1"), d, f(None, None), false));
    }
    // the SR400's equivalent tree: terminal link 6
    let sr400 = robot_file("sr400.toml");
    out.push(("sr400_0".into(), sr400.clone(), Frames::TERMINAL, false));
    out.push(("sr400_1".into(), sr400, f(Some(8), Some(4)), false));
    // a random tree with fixed frames: j a leaf, i on another branch, j a fixed frame
    let opts = TreeOptions {
        p_fixed: 0.3,
        p_serial: 0.5,
        ..TreeOptions::default()
    };
    let tree = random_tree_description(&mut rng(2026), 9, &opts);
    let leaves: Vec<usize> = (1..=tree.nl)
        .filter(|&k| (1..=tree.nl).all(|m| tree.frame(m).ant != k))
        .collect();
    assert!(leaves.len() >= 2, "the random tree has branches");
    let fixed = (1..=tree.nl)
        .find(|&k| !tree.frame(k).joint.is_movable())
        .expect("the random tree has a fixed frame");
    for (k, frames) in [
        f(Some(leaves[0]), Some(0)),
        f(Some(leaves[0]), Some(leaves[1])),
        f(Some(leaves[1]), None),
        f(Some(fixed), Some(leaves[0])),
    ]
    .into_iter()
    .enumerate()
    {
        out.push((format!("tree_{k}"), tree.clone(), frames, k == 3));
    }
    out
}

/// The values of a program's parameters `p` (the robot's geometric symbols), in its order.
fn parameters(prog: &Program, desc: &RobotDescription) -> Vec<f64> {
    prog.inputs
        .iter()
        .filter(|g| g.by_name)
        .flat_map(|g| g.symbols.iter().flatten())
        .map(|s| desc.symbols[s])
        .collect()
}

/// DGM and Jacobian programs of every setup, with three random states each and the reference
/// outputs ([`dgm_reference`], [`jacobian_reference`]).
pub(crate) fn kinematic_cases() -> Vec<KinematicCase> {
    let mut cases = Vec::new();
    for (s, (tag, desc, frames, numeric)) in setups().into_iter().enumerate() {
        let robot = Robot::new(desc.clone()).unwrap();
        let (i, j) = frames.resolve(&desc).unwrap();
        let mut r = rng(500 + s as u64);
        let states: Vec<Vec<f64>> = (0..3).map(|_| random_q(&mut r, robot.dof())).collect();
        for model in [ModelKind::Dgm(frames), ModelKind::Jacobian(frames)] {
            let opt = GenOptions {
                model,
                numeric,
                name: Some(format!("{tag}_{}", model.name())),
                ..GenOptions::default()
            };
            let prog = generate(&desc, &opt).unwrap();
            let p = parameters(&prog, &desc);
            let reference = |q: &[f64]| match model {
                ModelKind::Dgm(_) => dgm_reference(&robot, q, i, j),
                _ => jacobian_reference(&robot, q, i, j),
            };
            cases.push(KinematicCase {
                inputs: states.iter().map(|q| vec![q.clone(), p.clone()]).collect(),
                expected: states.iter().map(|q| reference(q)).collect(),
                prog,
                what: format!("{tag} {} {i}->{j}", model.name()),
            });
        }
    }
    cases
}

/// Largest difference relative to max(1, largest reference entry).
pub(crate) fn rel_err(got: &[f64], expected: &[f64]) -> f64 {
    assert_eq!(got.len(), expected.len());
    let scale = expected.iter().fold(1.0f64, |m, x| m.max(x.abs()));
    got.iter()
        .zip(expected)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale
}

/// The program's outputs (interpreted) for one input set (one vector per input group).
pub(crate) fn evaluate(prog: &Program, set: &[Vec<f64>]) -> Vec<f64> {
    let values = |s: &str| {
        prog.inputs.iter().zip(set).find_map(|(g, v)| {
            g.symbols
                .iter()
                .position(|x| x.as_deref() == Some(s))
                .map(|k| v[k])
        })
    };
    prog.evaluate(&values).unwrap()
}

#[test]
fn generated_dgm_and_jacobian_equal_the_numeric_routes() {
    let mut worst = 0.0f64;
    for c in kinematic_cases() {
        for (set, expected) in c.inputs.iter().zip(&c.expected) {
            let got = evaluate(&c.prog, set);
            let e = rel_err(&got, expected);
            assert!(e < 1e-12, "{}: off by {e:e}", c.what);
            worst = worst.max(e);
        }
    }
    println!("DGM and Jacobian (interpreted) vs numeric: worst {worst:e}");
}

/// The reference Jacobian (hyper-dual derivative of the numeric DGM) equals central
/// differences of `frame_transforms` (truncation ~h^2, rounding ~1e-16/h: 1e-8).
#[test]
fn reference_jacobian_equals_central_differences() {
    for (s, (tag, desc, frames, _)) in setups().into_iter().enumerate() {
        let robot = Robot::new(desc.clone()).unwrap();
        let (i, j) = frames.resolve(&desc).unwrap();
        let q = random_q(&mut rng(700 + s as u64), robot.dof());
        let e = rel_err(
            &jacobian_reference(&robot, &q, i, j),
            &jacobian_differences(&robot, &q, i, j),
        );
        assert!(e < 1e-8, "{tag}: {e:e}");
    }
}

/// The generated Jacobian is zero in the columns of the joints that do not move frame j, and
/// its angular rows of a local Jacobian (i = j) at a revolute joint j are (0, 0, 1).
#[test]
fn jacobian_structure() {
    let opts = TreeOptions {
        p_fixed: 0.0,
        p_prismatic: 0.0,
        p_serial: 0.4,
        ..TreeOptions::default()
    };
    let desc = random_tree_description(&mut rng(31), 8, &opts);
    let j = (1..=desc.nl)
        .find(|&k| (1..=desc.nl).all(|m| desc.frame(m).ant != k) && desc.frame(k).ant != 0)
        .unwrap();
    let frames = Frames {
        frame: Some(j),
        reference: None,
    };
    let prog = generate(
        &desc,
        &GenOptions {
            model: ModelKind::Jacobian(frames),
            ..GenOptions::default()
        },
    )
    .unwrap();
    let n = desc.nl;
    let mut on_path = vec![false; n + 1];
    let mut k = j;
    while k != 0 {
        on_path[k] = true;
        k = desc.frame(k).ant;
    }
    for (idx, o) in prog.outputs.iter().enumerate() {
        let (row, col) = (idx / n, idx % n + 1);
        if !on_path[col] {
            assert!(
                o.expr.is_zero(),
                "{}: joint {col} does not move frame {j}",
                o.name
            );
        }
        if col == j && row >= 3 {
            assert_eq!(o.expr.as_f64(), Some(if row == 5 { 1.0 } else { 0.0 }));
        }
    }
}

/// Operation counts of the RX-90 (printed; the chapter gives none for these models). Khalil's
/// observation holds: the Jacobian expressed in the intermediate frame 3 (3J6) is far cheaper
/// than 0J6 or 6J6.
#[test]
fn rx90_counts() {
    let desc = robot_file("rx90.toml");
    let count = |model| {
        generate(
            &desc,
            &GenOptions {
                model,
                ..GenOptions::default()
            },
        )
        .unwrap()
        .count()
    };
    let f = |reference| Frames {
        frame: Some(6),
        reference,
    };
    let dgm = count(ModelKind::Dgm(Frames::TERMINAL));
    let j0 = count(ModelKind::Jacobian(f(Some(0))));
    let j3 = count(ModelKind::Jacobian(f(Some(3))));
    let j6 = count(ModelKind::Jacobian(f(None)));
    println!("RX-90: 0T6 {dgm}; 0J6 {j0}; 3J6 {j3}; 6J6 {j6}");
    assert_eq!(dgm.func, 12, "sin and cos of six joints");
    assert!(j3.mul + j3.add < (j0.mul + j0.add) / 2);
    assert!(j3.mul + j3.add < (j6.mul + j6.add) / 2);
}

/// Frame choices that do not fit the robot are errors naming the option.
#[test]
fn bad_frames_are_errors() {
    let desc = robot_file("rx90.toml");
    let torso = robot_file("torso2arms.toml");
    for (d, frames, option, words) in [
        (
            &desc,
            Frames {
                frame: Some(7),
                reference: Some(0),
            },
            "frame",
            "not a frame",
        ),
        (
            &desc,
            Frames {
                frame: Some(0),
                reference: Some(0),
            },
            "frame",
            "base",
        ),
        (
            &desc,
            Frames {
                frame: None,
                reference: Some(9),
            },
            "reference",
            "not a frame",
        ),
        (&torso, Frames::TERMINAL, "frame", "terminal links"),
    ] {
        for model in [ModelKind::Dgm(frames), ModelKind::Jacobian(frames)] {
            let err = generate(
                d,
                &GenOptions {
                    model,
                    ..GenOptions::default()
                },
            )
            .unwrap_err();
            match &err {
                robodyn::Error::Setting { option: o, reason } => {
                    assert_eq!(*o, format!("codegen::Frames::{option}"));
                    assert!(reason.contains(words), "{reason}");
                }
                other => panic!("{other:?}"),
            }
        }
    }
}

/// Against the numeric frame Jacobian of `algorithms::kinematics` (`frame_jacobian`, written
/// independently, itself checked against Pinocchio): `LocalWorldAligned` rotated into frame i
/// (for i = j also `Local` directly), on every setup, to 1e-12.
#[test]
fn generated_jacobian_equals_the_numeric_frame_jacobian() {
    use robodyn::{frame_jacobian, Reference};
    let mut worst = 0.0f64;
    for (s, (tag, desc, frames, numeric)) in setups().into_iter().enumerate() {
        let robot = Robot::new(desc.clone()).unwrap();
        let (i, j) = frames.resolve(&desc).unwrap();
        let opt = GenOptions {
            model: ModelKind::Jacobian(frames),
            numeric,
            ..GenOptions::default()
        };
        let prog = generate(&desc, &opt).unwrap();
        let p = parameters(&prog, &desc);
        let id = robot.frame_id_of(j).unwrap();
        let n = robot.dof();
        let mut r = rng(800 + s as u64);
        for _ in 0..3 {
            let q = random_q(&mut r, n);
            let got = evaluate(&prog, &[q.clone(), p.clone()]);
            let lwa = frame_jacobian(&robot, &q, &id, Reference::LocalWorldAligned).unwrap();
            let to_i = placement(&frame_transforms(&robot, &q).unwrap(), i)
                .rot
                .transpose();
            let mut expected = vec![0.0; 6 * n];
            for c in 0..n {
                let v = Vector3::new(lwa[(0, c)], lwa[(1, c)], lwa[(2, c)]);
                let w = Vector3::new(lwa[(3, c)], lwa[(4, c)], lwa[(5, c)]);
                put_column(&mut expected, c, &to_i, v, w);
            }
            let e = rel_err(&got, &expected);
            assert!(e < 1e-12, "{tag}: {i}J{j} off frame_jacobian by {e:e}");
            worst = worst.max(e);
            if i == j {
                let local = frame_jacobian(&robot, &q, &id, Reference::Local).unwrap();
                let row_by_row: Vec<f64> = (0..6)
                    .flat_map(|k| (0..n).map(move |c| (k, c)))
                    .map(|e| local[e])
                    .collect();
                let e = rel_err(&got, &row_by_row);
                assert!(
                    e < 1e-12,
                    "{tag}: {j}J{j} off the Local frame_jacobian by {e:e}"
                );
            }
        }
    }
    println!("generated Jacobian vs frame_jacobian: worst {worst:e}");
}
