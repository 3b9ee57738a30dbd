//! robodyn: dynamic models of robots with complex structure (trees and closed kinematic chains)
//! in the Khalil–Kleinfinger notation, following chapter 10 of Khalil & Dombre.
//!
//! The API in one page is `docs/api.md` of the repository. In short: a model ([`Robot`] for a
//! tree, [`ClosedChain`] built on its tree), per-evaluation buffers made from it ([`Data`],
//! [`ClosedData`]), free functions `foo(model, inputs) -> Result<T>` (checked, allocating) and
//! `foo_into(model, data, [branch], env, inputs, out) -> Result<..>` (checked, allocation-free),
//! joint vectors over the movable joints of a tree or the actuated joints of a closed chain in
//! frame order ([`Coordinates`]), per-call gravity, base motion and external wrenches
//! ([`Environment`]), and for closed chains an explicit branch tracker ([`Branch`]).
//!
//! # Quick start
//!
//! ```
//! use robodyn::{closed_inverse_dynamics, direct_dynamics, inertia_matrix, inverse_dynamics};
//! use robodyn::{ClosedChain, Method};
//! # fn main() -> robodyn::Result<()> {
//! let robots = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots");
//!
//! // A serial robot from URDF: vectors hold its 6 movable joints in frame order.
//! let rx90 = robodyn::io::load(format!("{robots}/rx90.urdf"))?;
//! let n = rx90.dof();
//! println!("joints: {:?}", rx90.coordinates().names());
//! let (q, qd, qdd) = (vec![0.1; n], vec![0.2; n], vec![0.3; n]);
//! let tau = inverse_dynamics(&rx90, &q, &qd, &qdd)?; // N m, Newton–Euler (10.3–10.12)
//! let a = inertia_matrix(&rx90, &q)?; // A(q), n x n, composite links
//! let back = direct_dynamics(&rx90, &q, &qd, tau.as_slice(), Method::ArticulatedBody)?;
//! assert!((back[2] - qdd[2]).abs() < 1e-9);
//! assert_eq!(a.shape(), (n, n));
//!
//! // The Acma SR400, a closed chain: vectors hold the actuated joints (1, 2, 4, 5, 6, 7).
//! let sr400 = robodyn::io::load(format!("{robots}/sr400.toml"))?;
//! let chain = ClosedChain::new(&sr400)?;
//! let mut branch = chain.assembly_branch()?; // the parallelogram assembly of the file
//! let qa = [0.1, 0.2, 0.3, 0.4, 0.5, 1.6];
//! let idm = closed_inverse_dynamics(&chain, &mut branch, &qa, &[0.0; 6], &[0.0; 6])?;
//! println!("Gamma_cl = {} (10.40)", idm.gamma_cl);
//! assert!(!idm.state.conditioning.warning); // far from singularities
//!
//! // Base inertial parameters of the URDF robot (numerical method).
//! use robodyn::algorithms::base_parameters::{
//!     numeric_base_parameters, NumericOptions, ParameterNames, TreeSampler,
//! };
//! use robodyn::algorithms::regressor::{Friction, ParameterSelection, RotorMode};
//! let opt = NumericOptions::new(ParameterSelection::new(&rx90, RotorMode::None, Friction::None));
//! let base = numeric_base_parameters(&rx90, &mut TreeSampler, &opt)?;
//! let names = ParameterNames::of(rx90.description());
//! for r in 0..base.count() {
//!     println!("{}", base.equation(r, &names)); // e.g. XX2 - YY2 + ... (grouping)
//! }
//! # Ok(())
//! # }
//! ```
//!
//! Layout (Pinocchio's Model/Data split):
//! - [`model`]: what a robot is (description, topology, numeric constants, coordinates), immutable;
//! - [`data`]: per-evaluation buffers, reused across calls;
//! - [`algorithms`]: one module per algorithm, free functions over (model, data, inputs);
//! - [`simulation`]: integrators over the direct models;
//! - `io` (feature `io`): robot files (TOML, SYMORO .par, URDF) with positioned errors;
//! - `codegen` (feature `codegen`): customized symbolic models;
//! - `view` (feature `view`): a 3D view of the frames, links and trajectories in one HTML page;
//! - `identification` (feature `identification`): dynamic parameters from measured logs;
//! - [`geometry`]: iT_j and 0T_j;
//! - [`algorithms::kinematics`]: named frames, placements, velocities, accelerations, frame
//!   Jacobians (World, Local, LocalWorldAligned), J̇, centre of mass.
//!
//! Cargo features (default `io`, `plot`, `codegen`, `view`, `identification`):
//! `--no-default-features` builds the numeric dynamics alone, and each feature builds alone. The
//! random robots of the tests and benches are the separate crate `robodyn-testing`.

// Joint and link numbers are 1-based indices into several parallel arrays (a(j), frames, links):
// index loops read like the equations.
#![allow(clippy::needless_range_loop)]
#![deny(missing_docs)]

pub mod algorithms;
pub mod batch;
#[cfg(feature = "codegen")]
pub mod codegen;
pub mod data;
pub mod error;
pub mod geometry;
#[cfg(feature = "identification")]
pub mod identification;
#[cfg(feature = "io")]
pub mod io;
pub(crate) mod linalg;
pub mod model;
pub mod report;
pub(crate) mod sampling;
pub mod scalar;
pub mod simulation;
#[cfg(feature = "view")]
pub mod view;

pub use algorithms::centroidal::{
    centroidal_map, centroidal_map_into, centroidal_momentum, Centroidal,
};
pub use algorithms::closed_chain::{
    closed_direct_dynamics, closed_direct_dynamics_derivatives,
    closed_direct_dynamics_derivatives_into, closed_direct_dynamics_into,
    closed_inertia_matrix_into, closed_inverse_dynamics, closed_inverse_dynamics_derivatives,
    closed_inverse_dynamics_derivatives_into, closed_inverse_dynamics_into, closed_regressor_into,
    closed_state, loop_closure, loop_closure_into, Branch, ClosedChain, ClosedData,
    ClosedDdmDerivatives, ClosedDerivativesData, ClosedIdmDerivatives, Conditioning,
    ConditioningLimits,
};
pub use algorithms::derivatives::{
    direct_dynamics_derivatives, direct_dynamics_derivatives_into, inverse_dynamics_derivatives,
    inverse_dynamics_derivatives_batch, inverse_dynamics_derivatives_into, regressor_derivatives,
    regressor_derivatives_into, DdmDerivatives, DerivativesData, IdmDerivatives,
    RegressorDerivatives, RegressorDerivativesData,
};
pub use algorithms::direct_dynamics::{
    direct_dynamics, direct_dynamics_into, direct_dynamics_state_into, DirectState, Method,
};
pub use algorithms::floating_base::{integrate, integrate_into};
pub use algorithms::inertia_matrix::{
    h_vector, h_vector_into, inertia_matrix, inertia_matrix_into,
};
pub use algorithms::inverse_dynamics::{
    inverse_dynamics, inverse_dynamics_into, inverse_dynamics_state_into, State,
};
pub use algorithms::kinematics::{
    center_of_mass, center_of_mass_jacobian_from_q_into, center_of_mass_jacobian_into,
    forward_kinematics_into, frame_acceleration, frame_classical_acceleration,
    frame_classical_drift, frame_jacobian, frame_jacobian_from_q_into, frame_jacobian_into,
    frame_jacobian_time_variation_into, frame_placement, frame_velocity, joint_jacobians_into,
    placements_into, relative_placement, FrameId, KinematicsData, Motion, Reference,
};
pub use algorithms::regressor::{
    regressor, regressor_into, regressor_state_into, wrench_torques, wrench_torques_into,
};
pub use batch::{direct_dynamics_batch, inverse_dynamics_batch, regressor_batch};
pub use data::Data;
pub use error::{Error, Result};
pub use model::{BaseMotion, Coordinates, DynModel, Environment, Robot, RobotDescription, Wrench};
/// The nalgebra of robodyn's matrices and vectors (`DMatrix`, `DVector`, `Matrix3`, ...): use it
/// to build the buffers of the `_into` functions without matching robodyn's nalgebra version.
pub use nalgebra;
pub use robodyn_symbolic::Expr;
pub use scalar::DynScalar;
