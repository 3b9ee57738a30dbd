//! Every integration test of `robodyn` in ONE test binary: each `tests/*.rs` file is a module
//! here, left where it is. One binary builds and links far faster than one per file (see the
//! README's test section); `every_test_file_is_a_module` fails when a `tests/*.rs` file is not
//! listed below. One file's tests: `cargo test --release -p robodyn --test all -- FILE::`.
// each file keeps its own `mod common;`, as when it was a test binary of its own
#![allow(clippy::duplicate_mod)]

/// Visible skips of the optional checks, and the guard below.
#[path = "common/harness.rs"]
pub mod harness;

#[path = "base_parameters.rs"]
mod base_parameters;
#[path = "base_parameters_closed.rs"]
mod base_parameters_closed;
#[path = "base_parameters_external.rs"]
mod base_parameters_external;
#[path = "base_parameters_float_noise.rs"]
mod base_parameters_float_noise;
#[path = "base_parameters_latex.rs"]
mod base_parameters_latex;
#[path = "base_parameters_semantics.rs"]
mod base_parameters_semantics;
#[path = "batch.rs"]
mod batch;
#[path = "branch_tracker.rs"]
mod branch_tracker;
#[path = "closed_chain.rs"]
mod closed_chain;
#[path = "closed_derivatives.rs"]
mod closed_derivatives;
#[path = "closed_simulation.rs"]
mod closed_simulation;
#[path = "codegen_base.rs"]
mod codegen_base;
#[path = "codegen_bench_sources.rs"]
mod codegen_bench_sources;
#[path = "codegen_compile.rs"]
mod codegen_compile;
#[path = "codegen_counts.rs"]
mod codegen_counts;
#[path = "codegen_derivatives.rs"]
mod codegen_derivatives;
#[path = "codegen_errors.rs"]
mod codegen_errors;
#[path = "codegen_floating.rs"]
mod codegen_floating;
#[path = "codegen_kinematics.rs"]
mod codegen_kinematics;
#[path = "codegen_latex.rs"]
mod codegen_latex;
#[path = "codegen_opcount.rs"]
mod codegen_opcount;
#[path = "codegen_parameters.rs"]
mod codegen_parameters;
#[path = "continuation.rs"]
mod continuation;
#[path = "derivatives.rs"]
mod derivatives;
#[path = "derivatives_pinocchio.rs"]
mod derivatives_pinocchio;
#[path = "direct_dynamics.rs"]
mod direct_dynamics;
#[path = "finite_results.rs"]
mod finite_results;
#[path = "fixed_frames.rs"]
mod fixed_frames;
#[path = "floating_base.rs"]
mod floating_base;
#[path = "floating_base_parameters.rs"]
mod floating_base_parameters;
#[path = "floating_centroidal.rs"]
mod floating_centroidal;
#[path = "floating_kinematics.rs"]
mod floating_kinematics;
#[path = "floating_pinocchio.rs"]
mod floating_pinocchio;
#[path = "floating_simulation.rs"]
mod floating_simulation;
#[path = "fuzz_regressions.rs"]
mod fuzz_regressions;
#[path = "geometry.rs"]
mod geometry;
#[path = "identification_conic.rs"]
mod identification_conic;
#[path = "identification_consistency.rs"]
mod identification_consistency;
#[path = "identification_coverage.rs"]
mod identification_coverage;
#[path = "identification_gains.rs"]
mod identification_gains;
#[path = "identification_hostile.rs"]
mod identification_hostile;
#[path = "identification_joint_drives.rs"]
mod identification_joint_drives;
#[path = "identification_payload.rs"]
mod identification_payload;
#[path = "identification_statistics.rs"]
mod identification_statistics;
#[path = "identification_synthetic.rs"]
mod identification_synthetic;
#[path = "identification_tx40.rs"]
mod identification_tx40;
#[path = "inertia_matrix.rs"]
mod inertia_matrix;
#[path = "inverse_dynamics.rs"]
mod inverse_dynamics;
#[path = "inverse_geometry.rs"]
mod inverse_geometry;
#[path = "inverse_kinematics.rs"]
mod inverse_kinematics;
#[path = "io_consistency.rs"]
mod io_consistency;
#[path = "io_external.rs"]
mod io_external;
#[path = "io_hostile.rs"]
mod io_hostile;
#[path = "io_number_spelling.rs"]
mod io_number_spelling;
#[path = "io_par.rs"]
mod io_par;
#[path = "io_urdf.rs"]
mod io_urdf;
#[path = "io_urdf_pinocchio.rs"]
mod io_urdf_pinocchio;
#[path = "kinematics.rs"]
mod kinematics;
#[path = "kinematics_closed.rs"]
mod kinematics_closed;
#[path = "kinematics_pinocchio.rs"]
mod kinematics_pinocchio;
#[path = "loop_closure.rs"]
mod loop_closure;
#[path = "named_values.rs"]
mod named_values;
#[path = "no_cli_flags.rs"]
mod no_cli_flags;
#[path = "optimal_control.rs"]
mod optimal_control;
#[path = "parallel_links.rs"]
mod parallel_links;
#[path = "properties.rs"]
mod properties;
#[path = "regressor.rs"]
mod regressor;
#[path = "rnea_allocations.rs"]
mod rnea_allocations;
#[path = "rotation_forms.rs"]
mod rotation_forms;
#[path = "simulation.rs"]
mod simulation;
#[path = "transmission.rs"]
mod transmission;
#[path = "view.rs"]
mod view;

/// The guard: a `tests/*.rs` file that is not a module above would never be compiled or run.
#[test]
fn every_test_file_is_a_module() {
    harness::every_test_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("all.rs"));
}
