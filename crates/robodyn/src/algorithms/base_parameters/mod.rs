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
