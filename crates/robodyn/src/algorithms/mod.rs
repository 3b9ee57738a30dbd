//! One module per algorithm, named as the chapter names it.

pub mod base_parameters;
pub mod centroidal;
pub mod closed_chain;
pub mod derivatives;
pub mod direct_dynamics;
pub mod energy;
pub mod floating_base;
pub mod inertia_matrix;
pub mod inverse_dynamics;
pub mod inverse_geometry;
pub mod kinematics;
pub mod loop_closure;
pub mod regressor;
