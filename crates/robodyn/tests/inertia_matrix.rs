//! Inertia matrix A(q) (composite links) and H(q, qd), checked against independent routes:
//! Newton–Euler columns, link-by-link kinetic energy, a closed-form planar 2R arm, and the
//! symbolic scalar.

use nalgebra::{DMatrix, DVector, Vector3};
use robodyn::algorithms::inertia_matrix::composite_inertia_matrix;
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::model::{param, DynModel, JointType, LinkDesc, RobotDescription};
use robodyn::{
    h_vector, h_vector_into, inertia_matrix, inertia_matrix_into, inverse_dynamics, Data, Expr,
    Robot,
};
use robodyn_testing::{random_state, random_tree, random_tree_description, rng, TreeOptions};

/// The same robot with g = 0, no friction and no external wrench (rotor inertia kept), fixed base.
fn inertial_only(robot: &Robot) -> Robot {
    let mut d = robot.description().clone();
    for l in d.links.iter_mut() {
        l.params[param::FS] = Expr::zero();
        l.params[param::FV] = Expr::zero();
        for w in l.wrench.iter_mut() {
            *w = Expr::zero();
        }
    }
    for v in [&mut d.gravity, &mut d.w0, &mut d.wp0, &mut d.vp0] {
        *v = [Expr::zero(), Expr::zero(), Expr::zero()];
    }
    Robot::new(d).unwrap()
}

fn max_abs(m: &DMatrix<f64>) -> f64 {
    m.iter().fold(0.0, |a, x| a.max(x.abs()))
}

#[test]
fn a_is_symmetric_positive_definite_and_equals_newton_euler_columns() {
    let mut r = rng(11);
    let mut worst: f64 = 0.0;
    for case in 0..40 {
        let n = 2 + case % 29;
        let robot = random_tree(&mut r, n, &TreeOptions::default());
        let m = robot.dof();
        let [q, _, _] = random_state(&mut r, m);
        let a = inertia_matrix(&robot, &q).unwrap();
        assert_eq!(a.shape(), (m, m), "over the movable joints");
        let scale = max_abs(&a);
        assert!(scale > 0.0);
        // symmetric
        assert!(
            max_abs(&(&a - a.transpose())) <= 1e-12 * scale,
            "case {case}"
        );
        // positive definite
        let eig = a.clone().symmetric_eigenvalues();
        assert!(eig.min() > 0.0, "case {case}: min eigenvalue {}", eig.min());
        // reference: column i = Newton–Euler with g = 0, qd = 0, qdd = e_i on the inertial-only robot
        let reference = inertial_only(&robot);
        let zero = vec![0.0; m];
        let mut ane = DMatrix::zeros(m, m);
        for i in 0..m {
            let mut e = vec![0.0; m];
            e[i] = 1.0;
            ane.set_column(i, &inverse_dynamics(&reference, &q, &zero, &e).unwrap());
        }
        let err = max_abs(&(&a - &ane));
        worst = worst.max(err / scale);
        assert!(
            err <= 1e-11 * scale,
            "case {case} (n = {n}): |A - A_NE| = {err:e}"
        );
        // tree sparsity: A_ij = 0 unless one is an ancestor of the other
        let s = robot.structure();
        let c = robot.coordinates();
        for (x, &i) in c.frames().iter().enumerate() {
            for (y, &j) in c.frames().iter().enumerate() {
                if !s.is_ancestor(i, j) && !s.is_ancestor(j, i) {
                    assert_eq!(a[(x, y)], 0.0, "A_{i}{j}");
                }
            }
        }
    }
    eprintln!("worst |A - A_NE| / max|A|: {worst:e}");
}

/// Gamma(q, qd, qdd) = A(q) qdd + H(q, qd) with friction, wrenches, gravity and a moving base.
#[test]
fn newton_euler_is_a_qdd_plus_h() {
    let mut r = rng(12);
    for case in 0..30 {
        let n = 2 + case % 29;
        let mut d = random_tree_description(&mut r, n, &TreeOptions::default());
        d.w0 = [0.3, -0.2, 0.5].map(Expr::num);
        d.wp0 = [0.1, 0.4, -0.3].map(Expr::num);
        d.vp0 = [0.5, 0.0, -1.0].map(Expr::num);
        let robot = Robot::new(d).unwrap();
        let [q, qd, qdd] = random_state(&mut r, robot.dof());
        let a = inertia_matrix(&robot, &q).unwrap();
        let h = h_vector(&robot, &q, &qd).unwrap();
        let tau = inverse_dynamics(&robot, &q, &qd, &qdd).unwrap();
        let pred = &a * DVector::from_column_slice(&qdd) + h;
        let scale = tau.amax().max(1.0);
        assert!(
            (&pred - &tau).amax() <= 1e-10 * scale,
            "case {case}: {}",
            (&pred - &tau).amax()
        );
    }
}

/// 1/2 qd' A qd equals the sum of the link kinetic energies computed from link velocities
/// (w_j, V_j of O_j by the velocity recursion) plus the rotor energies 1/2 Ia qd^2.
#[test]
fn kinetic_energy_from_link_velocities() {
    let mut r = rng(13);
    for case in 0..20 {
        let n = 2 + case;
        let robot = random_tree(&mut r, n, &TreeOptions::default());
        let [q, qd, _] = random_state(&mut r, n);
        let c = robot.coordinates();
        let pick = |v: &[f64]| -> Vec<f64> { c.frames().iter().map(|&j| v[j - 1]).collect() };
        let a = inertia_matrix(&robot, &pick(&q)).unwrap();
        let mut qdv = DVector::from_column_slice(&qd);
        for j in 1..=n {
            if robot.frame(j).joint == JointType::Fixed {
                qdv[j - 1] = 0.0;
            }
        }
        let qdm = DVector::from_vec(pick(qdv.as_slice()));
        let t_a = 0.5 * qdm.dot(&(&a * &qdm));
        let model = robot.numeric();
        let mut w = vec![Vector3::zeros(); n + 1];
        let mut v = vec![Vector3::zeros(); n + 1];
        let mut t = 0.0;
        for j in 1..=n {
            let fr = model.frame(j);
            let i = fr.ant;
            let (rot, pos) = fr.transform(&q[j - 1]);
            let rt = rot.transpose();
            let z = Vector3::z();
            let mut wj = rt * w[i];
            let mut vj = rt * (v[i] + w[i].cross(&pos));
            match fr.joint {
                JointType::Revolute => wj += z * qdv[j - 1],
                JointType::Prismatic => vj += z * qdv[j - 1],
                JointType::Fixed => {}
            }
            let l = model.link(j);
            t += 0.5 * (l.mass * vj.dot(&vj) + wj.dot(&(l.inertia * wj)))
                + vj.dot(&wj.cross(&l.ms))
                + 0.5 * l.ia * qdv[j - 1] * qdv[j - 1];
            w[j] = wj;
            v[j] = vj;
        }
        assert!(
            (t - t_a).abs() <= 1e-11 * t.abs().max(1.0),
            "case {case}: {t} vs {t_a}"
        );
    }
}

/// Planar 2R arm (alpha = 0, d2 = L): the textbook closed form
/// A11 = ZZ1 + ZZ2 + M2 L^2 + 2 L (MX2 C2 - MY2 S2) + Ia1, A12 = ZZ2 + L (MX2 C2 - MY2 S2),
/// A22 = ZZ2 + Ia2.
#[test]
fn planar_2r_closed_form() {
    let mut d = RobotDescription::new("2R", 2, 2);
    let l = 0.7;
    d.frame_mut(2).ant = 1;
    d.frame_mut(2).d = Expr::num(l);
    let p = |zz: f64, mx: f64, my: f64, m: f64, ia: f64| {
        let mut ld = LinkDesc::zero("l");
        ld.params[param::XX] = Expr::num(zz * 0.5);
        ld.params[param::YY] = Expr::num(zz * 0.7);
        ld.params[param::ZZ] = Expr::num(zz);
        ld.params[param::MX] = Expr::num(mx);
        ld.params[param::MY] = Expr::num(my);
        ld.params[param::M] = Expr::num(m);
        ld.params[param::IA] = Expr::num(ia);
        ld
    };
    d.links[0] = p(0.9, 0.4, 0.1, 2.0, 0.05);
    d.links[1] = p(0.3, 0.25, -0.08, 1.5, 0.02);
    let robot = Robot::new(d).unwrap();
    for &(q1, q2) in &[(0.0, 0.0), (0.3, 1.1), (-2.0, 2.5)] {
        let a = inertia_matrix(&robot, &[q1, q2]).unwrap();
        let c = 0.25 * f64::cos(q2) - (-0.08) * f64::sin(q2);
        let a11 = 0.9 + 0.3 + 1.5 * l * l + 2.0 * l * c + 0.05;
        let a12 = 0.3 + l * c;
        let a22 = 0.3 + 0.02;
        assert!((a[(0, 0)] - a11).abs() < 1e-13);
        assert!((a[(0, 1)] - a12).abs() < 1e-13);
        assert!((a[(1, 0)] - a12).abs() < 1e-13);
        assert!((a[(1, 1)] - a22).abs() < 1e-13);
    }
}

/// The generic code on expressions: A(q) with symbolic joint variables, evaluated, equals the
/// numeric A (same description); and the allocation-free variants equal the wrappers.
#[test]
fn symbolic_scalar_matches_numeric() {
    let mut r = rng(14);
    for case in 0..4 {
        let n = 3 + case;
        let robot = random_tree(&mut r, n, &TreeOptions::default());
        let desc = robot.description();
        let sym: DynModel<Expr> = DynModel::build(desc, |e| e.clone(), |_, _, e| e.clone());
        let qs: Vec<Expr> = (1..=n).map(|j| Expr::symbol(format!("q{j}"))).collect();
        let qds: Vec<Expr> = (1..=n).map(|j| Expr::symbol(format!("qd{j}"))).collect();
        let mut ws = Data::from_model(&sym);
        let mut a_sym = DMatrix::from_element(n, n, Expr::zero());
        composite_inertia_matrix(&sym, &mut ws, &qs, &mut a_sym);
        let mut h_sym = vec![Expr::zero(); n];
        let zeros = vec![Expr::zero(); n];
        rnea(&sym, &mut ws, &qs, &qds, &zeros, &mut h_sym);
        let [q, qd, _] = random_state(&mut r, n);
        let env = |s: &str| -> Option<f64> {
            let k: usize = s
                .strip_prefix("qd")
                .or_else(|| s.strip_prefix('q'))?
                .parse()
                .ok()?;
            Some(if s.starts_with("qd") {
                qd[k - 1]
            } else {
                q[k - 1]
            })
        };
        // the checked API over the movable joints, and its allocation-free form
        let c = robot.coordinates();
        let pick = |v: &[f64]| -> Vec<f64> { c.frames().iter().map(|&j| v[j - 1]).collect() };
        let (qm, qdm) = (pick(&q), pick(&qd));
        let a = inertia_matrix(&robot, &qm).unwrap();
        let h = h_vector(&robot, &qm, &qdm).unwrap();
        let mut data = Data::new(&robot);
        let mut a2 = DMatrix::zeros(c.len(), c.len());
        inertia_matrix_into(&robot, &mut data, &qm, &mut a2).unwrap();
        let mut h2 = vec![0.0; c.len()];
        h_vector_into(&robot, &mut data, robot.environment(), &qm, &qdm, &mut h2).unwrap();
        assert_eq!(a, a2);
        assert_eq!(h.as_slice(), &h2[..]);
        for (x, &i) in c.frames().iter().enumerate() {
            for (y, &j) in c.frames().iter().enumerate() {
                let v = a_sym[(i - 1, j - 1)].eval(&env).unwrap();
                assert!((v - a[(x, y)]).abs() <= 1e-10 * (1.0 + a[(x, y)].abs()));
            }
            let v = h_sym[i - 1].eval(&env).unwrap();
            assert!((v - h[x]).abs() <= 1e-10 * (1.0 + h[x].abs()), "H{i}");
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    let mut r = rng(15);
    let robot = random_tree(&mut r, 4, &TreeOptions::default());
    let m = robot.dof();
    assert!(matches!(
        inertia_matrix(&robot, &vec![0.0; m - 1]),
        Err(robodyn::Error::Dimension { .. })
    ));
    let mut nan = vec![0.0; m];
    nan[1] = f64::NAN;
    assert!(matches!(
        inertia_matrix(&robot, &nan),
        Err(robodyn::Error::NotFinite { index: 1, .. })
    ));
    assert!(h_vector(&robot, &vec![0.0; m], &vec![0.0; m + 1]).is_err());
    let mut a = DMatrix::zeros(m + 1, m);
    assert!(inertia_matrix_into(&robot, &mut Data::new(&robot), &vec![0.0; m], &mut a).is_err());
}
