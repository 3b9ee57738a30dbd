//! Base inertial parameters (§10.2.4, §10.3.4–10.3.6).
//!
//! - [`numeric`]: the numerical method (stacked regressor, rank, ordered QR, beta).

pub mod numeric;

pub use numeric::{
    numeric_base_parameters, ConsistentSample, NumericBase, NumericOptions, Sampler, TreeSampler,
};
