//! robodyn: dynamic models of robots with complex structure (trees and closed kinematic chains)
//! in the Khalil–Kleinfinger notation, following chapter 10 of Khalil & Dombre.
//!
//! Layout (Pinocchio's Model/Data split):
//! - [`model`]: what a robot is (description, topology, numeric constants), immutable;
//! - [`workspace`]: per-evaluation buffers, reused across calls;
//! - [`algorithms`]: one module per algorithm, free functions over (model, workspace, inputs);
//! - [`io`]: robot files (TOML, SYMORO .par, URDF) with positioned errors;
//! - [`geometry`]: iT_j and 0T_j.

// Joint and link numbers are 1-based indices into several parallel arrays (a(j), frames, links):
// index loops read like the equations.
#![allow(clippy::needless_range_loop)]

pub mod algorithms;
pub mod codegen;
pub mod error;
pub mod geometry;
pub mod identification;
pub mod io;
pub mod model;
pub mod report;
pub mod scalar;
pub mod simulation;
pub mod testing;
pub mod workspace;

pub use error::{Error, Result};
pub use model::{Robot, RobotDescription};
pub use robodyn_symbolic::Expr;
pub use scalar::DynScalar;
pub use workspace::Workspace;
