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
use crate::geometry::frame_transforms;
use crate::Robot;
use nalgebra::Matrix3;

/// Number of closed configurations on which mR_k is compared.
const SAMPLES: usize = 5;

/// Entry k - 1: the earliest link m < k with 0R_k = 0R_m C on the closure manifold, C a signed
/// permutation (None for trees and links without such a partner).
pub fn parallel_links(robot: &Robot) -> Result<Vec<Option<SharedOrientation<f64>>>> {
    let nl = robot.nl();
    if robot.is_tree() {
        return Ok(vec![None; nl]);
    }
    let mut sampler = ClosedChainSampler::new(robot)?;
    let mut rng = crate::testing::rng(10_55);
    let mut rotations = Vec::with_capacity(SAMPLES);
    for _ in 0..SAMPLES {
        let s = sampler.next_state(&mut rng)?;
        let t = frame_transforms(robot, &s.q);
        rotations.push(t[..nl].iter().map(|t| t.rot).collect::<Vec<_>>());
    }
    let signed_permutation = |c: &Matrix3<f64>| -> Option<Matrix3<f64>> {
        let r = c.map(f64::round);
        let ok = (c - r).amax() < 1e-9
            && (0..3).all(|i| r.row(i).abs().sum() == 1.0 && r.column(i).abs().sum() == 1.0);
        ok.then_some(r)
    };
    Ok((1..=nl)
        .map(|k| {
            (1..k).find_map(|m| {
                let c0 = rotations[0][m - 1].tr_mul(&rotations[0][k - 1]);
                let c = signed_permutation(&c0)?;
                rotations[1..]
                    .iter()
                    .all(|r| (r[m - 1].tr_mul(&r[k - 1]) - c).amax() < 1e-9)
                    .then_some(SharedOrientation { link: m, rot: c })
            })
        })
        .collect())
}
