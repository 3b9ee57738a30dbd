//! One module per algorithm, named as the chapter names it.

pub mod energy;
pub mod inverse_dynamics;
