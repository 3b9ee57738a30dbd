//! One module per algorithm, named as the chapter names it.

pub mod direct_dynamics;
pub mod inertia_matrix;
pub mod inverse_dynamics;
