//! One module per algorithm, named as the chapter names it.

pub mod closed_chain;
pub mod energy;
pub mod inverse_dynamics;
pub mod loop_closure;
