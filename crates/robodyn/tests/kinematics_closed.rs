//! Frame Jacobians of closed chains in the actuated coordinates, J_a = J_tr G, against central
//! differences of the closed geometric model along the branch: the loops closed at
//! q_a ± h e_k on the tracker's branch (loop closure, an independent solve), the frame placed
//! on the closed tree, differentiated. On the Acma SR400 (parallelogram) and the five-bar.
//!
//! h = 1e-5: the truncation error h²/6 |f'''| (~1e-9 for these metre-scale mechanisms away from
//! singularities) and the closure residual over h (the solve's 1e-12 or better, / 1e-5 ~ 1e-7)
//! stay below the tolerance 1e-6 times max(1, |J_a|), while a wrong G (a missing W column, a
//! passive joint held still) changes entries by O(1).

use nalgebra::{Matrix3, Vector3};
use robodyn::algorithms::kinematics::closed_frame_jacobian;
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
