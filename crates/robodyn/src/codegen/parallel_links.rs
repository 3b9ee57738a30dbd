//! Links of a closed chain that keep the orientation of an earlier link (§10.3.5): in a
//! parallelogram the opposite links stay parallel, 0R_k = 0R_m C with C constant, so on the
//! closure manifold w_k = C^T w_m, wd_k = C^T wd_m and jU_k = C^T jU_m C. The customized
//! closed-chain model takes them from link m instead of propagating them along the tree
//! (`inverse_dynamics::forward_recursion_sharing`), which is what the loop constraint buys.
//!
//! Found numerically: on several closed configurations sampled around the assembly
//! configuration (`ClosedChainSampler`), mR_k must be the same signed permutation matrix (so
//! that sharing costs no operation) to 1e-9.

use crate::algorithms::base_parameters::closed::ClosedChainSampler;
use crate::algorithms::inverse_dynamics::SharedOrientation;
use crate::error::Result;
use crate::geometry::frame_transforms_per_frame;
use crate::model::path_from_base;
use crate::Robot;
use nalgebra::Matrix3;

/// Number of closed configurations on which mR_k is compared.
const SAMPLES: usize = 5;

/// Entry k - 1: the link m whose orientation link k takes, 0R_k = 0R_m C on the closure
/// manifold with C a signed permutation (None for trees, for links without such a partner and
/// for the source of each class, the link of the class closest to the base; m may be > k).
pub fn parallel_links(robot: &Robot) -> Result<Vec<Option<SharedOrientation<f64>>>> {
    let nl = robot.nl();
    if robot.is_tree() {
        return Ok(vec![None; nl]);
    }
    let mut sampler = ClosedChainSampler::new(robot)?;
    let mut rng = crate::sampling::rng(10_55);
    let mut rotations = Vec::with_capacity(SAMPLES);
    for _ in 0..SAMPLES {
        let s = sampler.next_state(&mut rng)?;
        let t = frame_transforms_per_frame(robot, s.q.as_slice());
        rotations.push(t[..nl].iter().map(|t| t.rot).collect::<Vec<_>>());
    }
    let signed_permutation = |c: &Matrix3<f64>| -> Option<Matrix3<f64>> {
        let r = c.map(f64::round);
        let ok = (c - r).amax() < 1e-9
            && (0..3).all(|i| r.row(i).abs().sum() == 1.0 && r.column(i).abs().sum() == 1.0);
        ok.then_some(r)
    };
    // revolute joints between link j and the base: the cost of propagating w, wd to link j
    let depth = |j: usize| {
        path_from_base(&robot.structure().ant, j)
            .into_iter()
            .filter(|&k| robot.frame(k).joint.is_revolute())
            .count()
    };
    let relative = |m: usize, k: usize| -> Option<Matrix3<f64>> {
        let c0 = rotations[0][m - 1].tr_mul(&rotations[0][k - 1]);
        let c = signed_permutation(&c0)?;
        rotations[1..]
            .iter()
            .all(|r| (r[m - 1].tr_mul(&r[k - 1]) - c).amax() < 1e-9)
            .then_some(c)
    };
    // classes of links with a constant relative orientation; the source of each class is its
    // link closest to the base (fewest revolute joints, then lowest index), so that the
    // recursion propagates w and wd along the shortest path
    let mut out: Vec<Option<SharedOrientation<f64>>> = vec![None; nl];
    let mut done = vec![false; nl + 1];
    for k in 1..=nl {
        if done[k] {
            continue;
        }
        let class: Vec<(usize, Matrix3<f64>)> = std::iter::once((k, Matrix3::identity()))
            .chain(
                (k + 1..=nl)
                    .filter(|&m| !done[m])
                    .filter_map(|m| relative(k, m).map(|c| (m, c))),
            )
            .collect();
        let &(src, ref c_src) = class
            .iter()
            .min_by_key(|(m, _)| (depth(*m), *m))
            .expect("non-empty");
        for (m, c_m) in &class {
            done[*m] = true;
            if *m != src {
                // 0R_m = 0R_k C_m and 0R_src = 0R_k C_src: srcR_m = C_src^T C_m
                out[*m - 1] = Some(SharedOrientation {
                    link: src,
                    rot: c_src.tr_mul(c_m),
                });
            }
        }
    }
    Ok(out)
}
