//! Rotation forms (`RotationForm`): the recursions skip the zeros of iA_j = pre_rot Rz(theta)
//! when pre_rot carries z onto ±x_k. Checked against the full 3x3 products on every frame of
//! random trees (which mix alpha, gamma in {0, ±pi/2, pi} with general angles), and the forms
//! found on a DH robot are the ones its geometry implies.

use nalgebra::{Matrix3, Vector3};
use rand::Rng;
use robodyn::model::{inertia_to_antecedent, RotationForm};
use robodyn_testing::{random_tree, rng, TreeOptions};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / (1.0 + b.abs())
}

#[test]
fn form_products_equal_the_full_products_on_random_frames() {
    let mut r = rng(181);
    let mut seen = [0usize; 4];
    for case in 0..40 {
        let opt = TreeOptions {
            general_frames: case % 2 == 0,
            ..TreeOptions::default()
        };
        let robot = random_tree(&mut r, 3 + case % 8, &opt);
        for model in [robot.numeric(), robot.dynamic()] {
            for j in 1..=model.nl {
                let fr = model.frame(j);
                match fr.form() {
                    RotationForm::General => seen[3] += 1,
                    RotationForm::Axis(k) => {
                        seen[k as usize] += 1;
                        // the form's zeros are exact
                        let k = k as usize;
                        assert_eq!(fr.pre_rot()[(k, 0)], 0.0, "case {case} frame {j}");
                        assert_eq!(fr.pre_rot()[(k, 1)], 0.0, "case {case} frame {j}");
                        assert_eq!(fr.pre_rot()[(k, 2)].abs(), 1.0, "case {case} frame {j}");
                        for i in (0..3).filter(|&i| i != k) {
                            assert_eq!(fr.pre_rot()[(i, 2)], 0.0, "case {case} frame {j}");
                        }
                    }
                }
                let q = r.random_range(-3.2..3.2);
                let (m, p) = fr.placement(&q);
                let v = Vector3::from_fn(|_, _| r.random_range(-2.0..2.0));
                let full = m * v;
                let full_tr = m.transpose() * v;
                let got = fr.rot_mul(&m, &v);
                let got_tr = fr.rot_tr_mul(&m, &v);
                for c in 0..3 {
                    assert!(rel(got[c], full[c]) < 1e-15, "case {case} frame {j}: R v");
                    assert!(
                        rel(got_tr[c], full_tr[c]) < 1e-15,
                        "case {case} frame {j}: R'v"
                    );
                }
                let a = Matrix3::from_fn(|_, _| r.random_range(-1.0..1.0));
                let jj = a * a.transpose() + Matrix3::identity();
                let ms = Vector3::from_fn(|_, _| r.random_range(-1.0..1.0));
                let mass = r.random_range(0.5..3.0);
                let (j1, u1) = fr.inertia_to_antecedent(&m, &p, &jj, &ms, &mass);
                let (j0, u0) = inertia_to_antecedent(&m, &p, &jj, &ms, &mass);
                for c in 0..9 {
                    assert!(rel(j1[c], j0[c]) < 1e-14, "case {case} frame {j}: J");
                }
                for c in 0..3 {
                    assert!(rel(u1[c], u0[c]) < 1e-14, "case {case} frame {j}: MS");
                }
            }
        }
    }
    // every form was exercised
    assert!(
        seen.iter().all(|&n| n > 5),
        "forms seen (x, y, z, general): {seen:?}"
    );
}

#[test]
fn dh_robot_frames_have_the_forms_their_alpha_implies() {
    // the SR400's frames of the main chain: gamma = 0, alpha in {0, ±pi/2} (Table 10.2's
    // robot): alpha = 0 keeps z (row 2 is (0, 0, 1)), alpha = ±pi/2 sends z to ∓y (row 1)
    let robot = robodyn::io::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/sr400.toml"
    )))
    .unwrap();
    let mut checked = 0;
    for j in 1..=robot.numeric().nl {
        let f = robot.frame(j);
        let (Ok(g), Ok(a)) = (f.gamma.eval(&|_| None), f.alpha.eval(&|_| None)) else {
            continue;
        };
        let half = std::f64::consts::FRAC_PI_2;
        let expected = if g != 0.0 {
            continue;
        } else if a == 0.0 {
            RotationForm::Axis(2)
        } else if (a.abs() - half).abs() < 1e-15 {
            RotationForm::Axis(1)
        } else {
            RotationForm::General
        };
        assert_eq!(robot.numeric().frame(j).form(), expected, "frame {j}");
        checked += 1;
    }
    assert!(checked >= 6, "{checked} frames checked");
}
