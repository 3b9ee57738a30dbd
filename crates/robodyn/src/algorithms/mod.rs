//! One module per algorithm, named as the chapter names it.

pub mod base_parameters;
pub mod inverse_dynamics;
pub mod regressor;
