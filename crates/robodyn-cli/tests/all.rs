//! Every integration test of `robodyn-cli` in ONE test binary: each `tests/*.rs` file is a module
//! here, left where it is. One binary builds and links far faster than one per file (see the
//! README's test section); `every_test_file_is_a_module` fails when a `tests/*.rs` file is not
//! listed below. One file's tests: `cargo test --release -p robodyn-cli --test all -- FILE::`.
// each file keeps its own `mod common;`, as when it was a test binary of its own
#![allow(clippy::duplicate_mod)]

/// Visible skips of the optional checks, and the guard below.
#[path = "../../robodyn/tests/common/harness.rs"]
pub mod harness;

#[path = "cli_bad_input.rs"]
mod cli_bad_input;
#[path = "cli_base_params_closed.rs"]
mod cli_base_params_closed;
#[path = "cli_closed.rs"]
mod cli_closed;
#[path = "cli_closed_budget.rs"]
mod cli_closed_budget;
#[path = "cli_closed_derivatives.rs"]
mod cli_closed_derivatives;
#[path = "cli_closed_rows.rs"]
mod cli_closed_rows;
#[path = "cli_columns.rs"]
mod cli_columns;
#[path = "cli_conventions.rs"]
mod cli_conventions;
#[path = "cli_derivatives.rs"]
mod cli_derivatives;
#[path = "cli_floating_kinematics.rs"]
mod cli_floating_kinematics;
#[path = "cli_floating_models.rs"]
mod cli_floating_models;
#[path = "cli_floating_simulate.rs"]
mod cli_floating_simulate;
#[path = "cli_gains_payload.rs"]
mod cli_gains_payload;
#[path = "cli_generate.rs"]
mod cli_generate;
#[path = "cli_generate_derivatives.rs"]
mod cli_generate_derivatives;
#[path = "cli_generate_floating.rs"]
mod cli_generate_floating;
#[path = "cli_generate_names.rs"]
mod cli_generate_names;
#[path = "cli_identify.rs"]
mod cli_identify;
#[path = "cli_identify_hostile.rs"]
mod cli_identify_hostile;
#[path = "cli_identify_many.rs"]
mod cli_identify_many;
#[path = "cli_identify_predictions.rs"]
mod cli_identify_predictions;
#[path = "cli_info.rs"]
mod cli_info;
#[path = "cli_info_assembly.rs"]
mod cli_info_assembly;
#[path = "cli_kinematics.rs"]
mod cli_kinematics;
#[path = "cli_long_inputs.rs"]
mod cli_long_inputs;
#[path = "cli_outputs.rs"]
mod cli_outputs;
#[path = "cli_presentation.rs"]
mod cli_presentation;
#[path = "cli_random_options.rs"]
mod cli_random_options;
#[path = "cli_readme.rs"]
mod cli_readme;
#[path = "cli_simulate_names.rs"]
mod cli_simulate_names;
#[path = "cli_transmission.rs"]
mod cli_transmission;
#[path = "cli_view.rs"]
mod cli_view;

/// The guard: a `tests/*.rs` file that is not a module above would never be compiled or run.
#[test]
fn every_test_file_is_a_module() {
    harness::every_test_file_is_a_module(env!("CARGO_MANIFEST_DIR"), include_str!("all.rs"));
}
