//! One module per algorithm, named as the chapter names it.

pub mod inverse_dynamics;
