//! Frame Jacobians of closed chains in the actuated coordinates, J_a = J_tr G, against central
//! differences of the closed geometric model along the branch: the loops closed at
//! q_a ± h e_k on the tracker's branch (loop closure, an independent solve), the frame placed
//! on the closed tree, differentiated. On the Acma SR400 (parallelogram), the five-bar and the
//! spatial RSUR loop. The drift J̇_a q̇_a: J_a q̈_a + J̇_a q̇_a against second differences of the
//! closed placement along a closed trajectory (see `check_drift`).
//!
//! h = 1e-5: the truncation error h²/6 |f'''| (~1e-9 for these metre-scale mechanisms away from
//! singularities) and the closure residual over h (the solve's 1e-12 or better, / 1e-5 ~ 1e-7)
//! stay below the tolerance 1e-6 times max(1, |J_a|), while a wrong G (a missing W column, a
//! passive joint held still) changes entries by O(1).

use nalgebra::{DVector, Matrix3, Vector3};
use robodyn::algorithms::kinematics::{closed_frame_drift, closed_frame_jacobian};
use robodyn::{
    closed_state, frame_placement, placements_into, ClosedChain, FrameId, KinematicsData,
    Reference, Robot,
};

mod common;

const H: f64 = 1e-5;

/// 0T_f on the closed tree at q_a (the branch moves there).
fn closed_placement(
    chain: &ClosedChain,
    branch: &mut robodyn::Branch,
    q_a: &[f64],
    f: &FrameId,
) -> robodyn::geometry::Transform {
    let z = vec![0.0; q_a.len()];
    let s = closed_state(chain, branch, q_a, &z, &z).unwrap();
    let robot: &Robot = chain.robot();
    let mut d = KinematicsData::new(robot);
    placements_into(robot, &mut d, s.q.as_slice()).unwrap();
    frame_placement(robot, &d, f).unwrap()
}

fn angular_rate(rp: &Matrix3<f64>, rm: &Matrix3<f64>) -> Vector3<f64> {
    let m = (rp * rm.transpose() - rm * rp.transpose()) / (4.0 * H);
    Vector3::new(m[(2, 1)], m[(0, 2)], m[(1, 0)])
}

fn check(name: &str, q_a: &[f64]) {
    let robot = common::robot(name);
    let chain = ClosedChain::new(&robot).unwrap();
    let mut branch = chain.assembly_branch().unwrap();
    for j in (1..=robot.nf()).filter_map(|j| robot.frame_id_of(j).ok()) {
        let f = j.at_point(Vector3::new(0.1, -0.05, 0.2));
        let jac = closed_frame_jacobian(&chain, &mut branch, q_a, &f, Reference::LocalWorldAligned)
            .unwrap();
        assert_eq!(jac.j_a.shape(), (6, chain.dof()));
        let scale = jac.j_a.amax().max(1.0);
        for k in 0..chain.dof() {
            let mut b = branch.clone();
            let (mut qp, mut qm) = (q_a.to_vec(), q_a.to_vec());
            qp[k] += H;
            qm[k] -= H;
            let tp = closed_placement(&chain, &mut b, &qp, &f);
            let tm = closed_placement(&chain, &mut b, &qm, &f);
            let v = (tp.pos - tm.pos) / (2.0 * H);
            let w = angular_rate(&tp.rot, &tm.rot);
            for r in 0..3 {
                for (got, fd, what) in [
                    (jac.j_a[(r, k)], v[r], "linear"),
                    (jac.j_a[(r + 3, k)], w[r], "angular"),
                ] {
                    assert!(
                        (got - fd).abs() <= 1e-6 * scale,
                        "{name}, frame on {}, column {k}, {what} row {r}: J_a {got} vs FD {fd}",
                        f.parent()
                    );
                }
            }
        }
        // J_a = J_tr G, and the passive rows of G are W
        let g = &jac.state.g;
        let c = robot.coordinates();
        let pc = chain.passive_coordinates();
        for (p, &fr) in pc.frames().iter().enumerate() {
            let row = c.index_of_frame(fr).unwrap();
            for k in 0..chain.dof() {
                assert_eq!(g[(row, k)], jac.state.w[(p, k)]);
            }
        }
    }
}

#[test]
fn sr400_actuated_jacobian_matches_the_closed_geometric_model() {
    check("sr400.toml", &[0.1, 0.2, 0.3, 0.4, 0.5, 1.6]);
}

#[test]
fn fivebar_actuated_jacobian_matches_the_closed_geometric_model() {
    check("fivebar.toml", &[0.1, -0.15]);
}

#[test]
fn spatial_loop_actuated_jacobian_matches_the_closed_geometric_model() {
    check("spatial_loop.toml", &[0.2]);
}

/// Step of the second differences of the acceleration check: their truncation error
/// h²/12 |f''''| (~1e-7 for these metre-scale mechanisms at unit joint speeds) and the closure
/// residual over h² (a closure at the chain's tolerance 1e-13: 1e-13 / 1e-6 = 1e-7) stay below
/// the tolerance 2e-6 times max(1, |J_a|, |a|); a missing Ġ q̇_a or J̇_tr q̇_tr term changes
/// the acceleration by O(|q̇|²) ~ 0.1 .. 1.
const H2: f64 = 1e-3;

/// The frame's placement, velocity (v_O, w) and acceleration (a_O, ẇ) in R_0 along the closed
/// trajectory q_a(t) = q_a + t q̇_a + t²/2 q̈_a at t = 0, by central differences of the closed
/// geometric model at t = -h, 0, h: v = (O+ - O-)/2h, a = (O+ - 2 O + O-)/h², [w] the skew part
/// of (R+ - R-)/2h R^T, [ẇ] the skew part of R̈ R^T (R̈ R^T = [ẇ] + [w]², [w]² symmetric).
fn motion_by_differences(
    chain: &ClosedChain,
    branch: &robodyn::Branch,
    s: [&[f64]; 3],
    f: &FrameId,
) -> (robodyn::geometry::Transform, [Vector3<f64>; 4]) {
    let at = |t: f64| -> Vec<f64> {
        (0..s[0].len())
            .map(|k| s[0][k] + t * s[1][k] + 0.5 * t * t * s[2][k])
            .collect()
    };
    let mut b = branch.clone();
    let tm = closed_placement(chain, &mut b, &at(-H2), f);
    let t0 = closed_placement(chain, &mut b, &at(0.0), f);
    let tp = closed_placement(chain, &mut b, &at(H2), f);
    let vee = |m: Matrix3<f64>| {
        let k = (m - m.transpose()) / 2.0;
        Vector3::new(k[(2, 1)], k[(0, 2)], k[(1, 0)])
    };
    let v = (tp.pos - tm.pos) / (2.0 * H2);
    let a = (tp.pos - 2.0 * t0.pos + tm.pos) / (H2 * H2);
    let w = vee((tp.rot - tm.rot) / (2.0 * H2) * t0.rot.transpose());
    let wd = vee((tp.rot - 2.0 * t0.rot + tm.rot) / (H2 * H2) * t0.rot.transpose());
    (t0, [v, a, w, wd])
}

/// J_a q̈_a + J̇_a q̇_a of `closed_frame_drift` against the frame's acceleration along a closed
/// trajectory by second differences of the closed geometric model, in the three references:
/// LocalWorldAligned (a_O, ẇ); Local the derivative of (R^T v_O, R^T w), R^T (a_O - w x v_O, ẇ);
/// World the derivative of (v_O + O x w, w), (a_O + v_O x w + O x ẇ, ẇ). `g_moves`: whether
/// Ġ q̇_a is non-zero on this mechanism (on the SR400's parallelogram q_p is linear in q_a, so
/// Ġ = 0 and only J̇_tr q̇_tr is tested there).
fn check_drift(name: &str, s: [&[f64]; 3], g_moves: bool) {
    let robot = common::robot(name);
    let chain = ClosedChain::new(&robot).unwrap().with_tolerance(1e-13);
    let mut branch = chain.assembly_branch().unwrap();
    let qdd_a = DVector::from_column_slice(s[2]);
    let mut checked = 0;
    // the largest J_tr Ġ q̇_a and J̇_tr q̇_tr over the frames: each must matter (else the
    // check could not see it missing)
    let (mut g_term, mut tree_term) = (0.0f64, 0.0f64);
    for j in (1..=robot.nf()).filter_map(|j| robot.frame_id_of(j).ok()) {
        let f = j.at_point(Vector3::new(0.1, -0.05, 0.2));
        let (t, [v, a, w, wd]) = motion_by_differences(&chain, &branch, s, &f);
        for r in Reference::ALL {
            let d = closed_frame_drift(&chain, &mut branch, s[0], s[1], &f, r).unwrap();
            let got = &d.jacobian.j_a * &qdd_a + d.drift.to_vector();
            let jg = &d.jacobian.j_tree * &d.jacobian.state.qdd;
            g_term = g_term.max(jg.amax());
            tree_term = tree_term.max((d.drift.to_vector() - jg).amax());
            let (lin, ang) = match r {
                Reference::LocalWorldAligned => (a, wd),
                Reference::Local => (t.rot.tr_mul(&(a - w.cross(&v))), t.rot.tr_mul(&wd)),
                Reference::World => (a + v.cross(&w) + t.pos.cross(&wd), wd),
            };
            let fd = [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z];
            let scale = d.jacobian.j_a.amax().max(got.amax()).max(1.0);
            for (i, (g, e)) in got.iter().zip(fd).enumerate() {
                assert!(
                    (g - e).abs() <= 2e-6 * scale,
                    "{name}, frame on {}, {}, row {i}: J_a qdd_a + drift {g} vs FD {e}",
                    f.parent(),
                    r.name()
                );
            }
            // J_a is that of closed_frame_jacobian
            let jac = closed_frame_jacobian(&chain, &mut branch, s[0], &f, r).unwrap();
            assert_eq!(jac.j_a, d.jacobian.j_a, "{name}, {}: J_a", r.name());
            checked += 1;
        }
    }
    assert!(checked >= 9, "{name}: {checked} frame-references checked");
    assert!(
        (g_term > 1e-2 || !g_moves) && tree_term > 1e-2,
        "{name}: J_tr Ġ q̇_a up to {g_term}, J̇_tr q̇_tr up to {tree_term}: too small to be tested"
    );
}

#[test]
fn sr400_actuated_acceleration_matches_the_closed_geometric_model() {
    check_drift(
        "sr400.toml",
        [
            &[0.1, 0.2, 0.3, 0.4, 0.5, 1.6],
            &[0.7, -0.5, 0.9, 0.6, -0.8, 0.4],
            &[0.3, 0.2, -0.4, 0.5, 0.1, -0.2],
        ],
        false,
    );
}

#[test]
fn fivebar_actuated_acceleration_matches_the_closed_geometric_model() {
    check_drift(
        "fivebar.toml",
        [&[0.1, -0.15], &[0.8, -0.6], &[0.4, 0.3]],
        true,
    );
}

#[test]
fn spatial_loop_actuated_acceleration_matches_the_closed_geometric_model() {
    check_drift("spatial_loop.toml", [&[0.2], &[1.1], &[-0.7]], true);
}
