//! `robodyn`: dynamic models of tree and closed-chain robots from the command line.
//! Argument parsing and formatting only; the models live in the `robodyn` library.

/// `writeln!` into a `String` (output is built in memory and written once by
/// `common::print_out`, so a closed pipe is an error, not a panic).
macro_rules! outln {
    ($s:expr) => {
        $s.push('\n')
    };
    ($s:expr, $($t:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($s, $($t)*);
    }};
}

mod commands;
mod common;
mod derivatives;
mod hint;
mod kinematic_state;
mod output;
mod rows;
mod states;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "robodyn",
    version,
    about = "Dynamic modeling of robots with complex structure (Khalil-Kleinfinger notation)",
    after_help = GETTING_STARTED
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Describe a robot: frames table, structure, branches, loops, actuated/passive joints.
    Info(commands::info::Args),
    /// Inverse dynamic model: joint torques for given states (Newton-Euler).
    Idm(commands::idm::Args),
    /// Loop closure of a closed-chain robot: q_p for given q_a (and W with --jacobian).
    Closure(commands::closure::Args),
    /// Base inertial parameters: table, grouping equations, values (symbolic and/or numeric).
    BaseParams(commands::base_params::Args),
    /// Regressor Phi of the tree (Gamma = Phi K + Gamma_e) for states from a CSV file.
    Regressor(commands::regressor::Args),
    /// Convert a robot file: TOML, SYMORO .par or URDF -> TOML or .par (by extension).
    Convert(commands::convert::Args),
    /// Direct geometric model: placements (and velocities, accelerations) of frames.
    Fk(commands::fk::Args),
    /// Jacobian of a frame in the world, local or local-world-aligned reference.
    Jacobian(commands::jacobian::Args),
    /// Centre of mass, its velocity, acceleration and Jacobian.
    Com(commands::com::Args),
    /// Inverse geometric model in closed form: every joint solution for a frame's placement.
    Ik(commands::ik::Args),
    /// Inertia matrix A(q) by the composite-link method (csv or json).
    Inertia(commands::inertia::Args),
    /// Direct dynamic model: joint accelerations for given states and torques.
    Ddm(commands::ddm::Args),
    /// Simulate the direct dynamic model under a torque input; CSV trajectory and SVG plot.
    Simulate(commands::simulate::Args),
    /// Customized symbolic models (idm, inertia, h, ddm, closed, w) as text, LaTeX or code.
    Generate(commands::generate::Args),
    /// Identify base parameters, friction and drive parameters from a measured log.
    Identify(commands::identify::Args),
    /// Design an exciting trajectory (finite Fourier series minimizing the condition number).
    Excite(commands::excite::Args),
    /// 3D view of the frames, links and joints (one HTML page; PNG with --png); trajectories.
    View(commands::view::Args),
}

/// Printed after `robodyn --help`: a first command and where the documentation is.
const GETTING_STARTED: &str = "Examples (robot files of the repository's robots/ directory):
  robodyn info robots/sr400.toml
  robodyn idm robots/rx90.toml --q 0.1,0.2,0.3,0.4,0.5,0.6 --qd 1,1,1,1,1,1
  robodyn base-params robots/sr400.toml --no-friction
  robodyn simulate robots/scara.toml --duration 1 --output run.csv --plot run.svg

`robodyn COMMAND --help` lists a command's options, their values and units. Documentation: \
README.md and docs/ of the repository (docs/cli.md: conventions common to all commands; \
docs/robot-format.md: robot files; docs/models/: the models and their checks).";

/// Printed after every command's `--help`: the units of every value and column.
const UNITS: &str = "Units (SI): q<j> rad (revolute) or m (prismatic); qd<j> rad/s or m/s; \
qdd<j> rad/s^2 or m/s^2; tau<j> N m or N; t s; energy J; robot file: lengths m, masses kg, first \
moments kg m, inertias kg m^2, FS N m or N, FV N m s/rad or N s/m, gravity m/s^2. \
`-` as a file is standard input/output. Conventions: docs/cli.md.";

fn main() {
    let command = Cli::command().mut_subcommands(|c| c.after_help(UNITS));
    let cli = Cli::from_arg_matches(&command.get_matches()).unwrap_or_else(|e| e.exit());
    let result = match cli.command {
        Command::Info(a) => commands::info::run(a),
        Command::Idm(a) => commands::idm::run(a),
        Command::Closure(a) => commands::closure::run(a),
        Command::BaseParams(a) => commands::base_params::run(a),
        Command::Regressor(a) => commands::regressor::run(a),
        Command::Convert(a) => commands::convert::run(a),
        Command::Inertia(a) => commands::inertia::run(a),
        Command::Fk(a) => commands::fk::run(a),
        Command::Jacobian(a) => commands::jacobian::run(a),
        Command::Com(a) => commands::com::run(a),
        Command::Ik(a) => commands::ik::run(a),
        Command::Ddm(a) => commands::ddm::run(a),
        Command::Simulate(a) => commands::simulate::run(a),
        Command::Generate(a) => commands::generate::run(a),
        Command::Identify(a) => commands::identify::run(a),
        Command::Excite(a) => commands::excite::run(a),
        Command::View(a) => commands::view::run(a),
    };
    if let Err(e) = result {
        // `robodyn ... | head -1`: the reader has all it wanted; end quietly
        if common::is_broken_pipe(e.as_ref()) {
            std::process::exit(0);
        }
        eprintln!("robodyn: error: {e}");
        if let Some(h) = hint::library_error(e.as_ref()).and_then(hint::hint) {
            eprintln!("robodyn: hint: {h}");
        }
        std::process::exit(1);
    }
}
