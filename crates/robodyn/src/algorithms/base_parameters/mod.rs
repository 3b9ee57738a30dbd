//! Base inertial parameters (§10.2.4, §10.3.4–10.3.6).
//!
//! - [`numeric`]: the numerical method (stacked regressor, rank, ordered QR, beta);
//! - [`symbolic`]: the rules of §10.3.6 with the grouping equations as expressions.

pub mod numeric;

pub use numeric::{
    numeric_base_parameters, ConsistentSample, NumericBase, NumericOptions, Sampler, TreeSampler,
};
pub mod symbolic;

pub use symbolic::{collect_by_coefficient, symbolic_base_parameters, SymbolicBase};
pub mod report;

pub mod closed;

pub use closed::ClosedChainSampler;

pub use report::{base_robot, compare_methods, MethodComparison, Report};

use crate::model::{JointType, Robot};

/// Upper bound b_m of the number of base inertial parameters of the links (rotors and friction
/// not included): eq 10.24 for a tree, eq 10.57 for a closed chain with `n_parallelograms`
/// parallelogram loops:
/// b_m = 7 n_r + 4 n_p - 4 n_r0 - 3 n_p0 - 11 n_par - 2 n_g0, with n_r (n_p) the revolute
/// (prismatic) joints of the equivalent tree, n_r0 (n_p0) those connected to the base, n_g0 the
/// revolute joints connected to the base whose axes are parallel to gravity.
pub fn inertial_bound(robot: &Robot, n_parallelograms: usize) -> usize {
    let g = robot.numeric().env.gravity;
    let (mut nr, mut np, mut nr0, mut np0, mut ng0) = (0i64, 0i64, 0i64, 0i64, 0i64);
    for j in 1..=robot.nl() {
        let at_base = robot.ant(j) == 0;
        match robot.frame(j).joint {
            JointType::Revolute => {
                nr += 1;
                if at_base {
                    nr0 += 1;
                    let (rot, _) = robot.numeric().frame(j).transform(&0.0);
                    if rot.column(2).cross(&g).norm() < 1e-9 * g.norm().max(1.0) {
                        ng0 += 1;
                    }
                }
            }
            JointType::Prismatic => {
                np += 1;
                np0 += i64::from(at_base);
            }
            JointType::Fixed => {}
        }
    }
    (7 * nr + 4 * np - 4 * nr0 - 3 * np0 - 11 * n_parallelograms as i64 - 2 * ng0).max(0) as usize
}
