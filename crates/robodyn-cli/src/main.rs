//! `robodyn`: dynamic models of tree and closed-chain robots from the command line.
//! Argument parsing and formatting only; the models live in the `robodyn` library.

mod commands;
mod common;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "robodyn",
    version,
    about = "Dynamic modeling of robots with complex structure (Khalil-Kleinfinger notation)"
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
    /// Customized symbolic models (idm, inertia, h, ddm, closed) as text, LaTeX or code.
    Generate(commands::generate::Args),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info(a) => commands::info::run(a),
        Command::Idm(a) => commands::idm::run(a),
        Command::Generate(a) => commands::generate::run(a),
    };
    if let Err(e) = result {
        eprintln!("robodyn: error: {e}");
        std::process::exit(1);
    }
}
