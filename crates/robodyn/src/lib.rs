//! robodyn: dynamic models of robots with complex structure (trees and closed kinematic chains)
//! in the Khalil–Kleinfinger notation, following chapter 10 of Khalil & Dombre.
//!
//! Layout (Pinocchio's Model/Data split):
//! - [`model`]: what a robot is (description, topology, numeric constants), immutable;
//! - [`data`]: per-evaluation buffers, reused across calls;
//! - [`algorithms`]: one module per algorithm, free functions over (model, workspace, inputs);
//! - [`io`]: robot files (TOML, SYMORO .par, URDF) with positioned errors;
//! - [`geometry`]: iT_j and 0T_j.

// Joint and link numbers are 1-based indices into several parallel arrays (a(j), frames, links):
// index loops read like the equations.
#![allow(clippy::needless_range_loop)]
#![warn(missing_docs)]

pub mod algorithms;
#[cfg(feature = "codegen")]
#[allow(missing_docs)] // documented by the code-generation work (issue 14.8)
pub mod codegen;
pub mod data;
pub mod error;
pub mod geometry;
#[cfg(feature = "io")]
#[allow(missing_docs)] // documented by the readers' rewrite (issue 14.8)
pub mod io;
pub(crate) mod linalg;
pub mod model;
pub mod scalar;
pub mod simulation;
#[cfg(feature = "testing")]
pub mod testing;
// The library's own samplers use the seeded generator without exposing the test helpers.
#[cfg(not(feature = "testing"))]
#[allow(dead_code)]
pub(crate) mod testing;

pub use algorithms::closed_chain::{
    closed_direct_dynamics, closed_direct_dynamics_into, closed_inverse_dynamics,
    closed_inverse_dynamics_into, closed_regressor_into, closed_state, loop_closure,
    loop_closure_into, Branch, ClosedChain, ClosedData, Conditioning, ConditioningLimits,
};
pub use algorithms::direct_dynamics::{direct_dynamics, direct_dynamics_into, Method};
pub use algorithms::inertia_matrix::{
    h_vector, h_vector_into, inertia_matrix, inertia_matrix_into,
};
pub use algorithms::inverse_dynamics::{inverse_dynamics, inverse_dynamics_into};
pub use algorithms::regressor::{regressor, regressor_into, wrench_torques, wrench_torques_into};
pub use data::Data;
pub use error::{Error, Result};
pub use model::{BaseMotion, Coordinates, DynModel, Environment, Robot, RobotDescription, Wrench};
pub use robodyn_symbolic::Expr;
pub use scalar::DynScalar;
