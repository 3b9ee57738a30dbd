//! `robodyn convert IN OUT`: convert a robot file (TOML, SYMORO .par, URDF) to TOML or .par,
//! formats chosen by the extensions.

use crate::common::CliResult;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// Input robot file (.toml, .par or .urdf).
    pub input: PathBuf,
    /// Output robot file (.toml or .par), written all or nothing.
    pub output: PathBuf,
}

pub fn run(a: Args) -> CliResult {
    let desc = robodyn::io::load_description(&a.input)?;
    crate::output::save_robot(&desc, &a.output)
}
