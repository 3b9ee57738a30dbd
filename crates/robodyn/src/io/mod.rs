//! Robot files: native TOML, SYMORO's .par and URDF, every error with a file position.
//!
//! [`load_description`] reads any of them (chosen by extension) into a [`RobotDescription`];
//! [`load`] also validates it into a [`Robot`], which needs a numeric value for every symbol.

pub mod par;
pub mod toml_format;
pub mod urdf;

pub use toml_format::SourceMap;

use crate::error::{Error, Result};
use crate::model::RobotDescription;
use crate::Robot;
use std::collections::BTreeMap;
use std::path::Path;

/// The file formats robodyn reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Toml,
    Par,
    Urdf,
}

impl Format {
    /// Format from a file extension (`.toml`, `.par`, `.urdf`).
    pub fn from_path(path: &Path) -> Result<Format> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("toml") => Ok(Format::Toml),
            Some("par") => Ok(Format::Par),
            Some("urdf") | Some("xml") => Ok(Format::Urdf),
            _ => Err(Error::Input(format!(
                "{}: unknown robot file extension (expected .toml, .par or .urdf)",
                path.display()
            ))),
        }
    }
}

/// Read a text file; files that are not UTF-8 (SYMORO+ writes Latin-1 comments such as
/// "Noë") are decoded as Latin-1.
fn read(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|e| Error::io(path.display().to_string(), e))?;
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.as_bytes().iter().map(|&b| b as char).collect(),
    })
}

/// Read a robot description from a file, with the positions of its entries.
pub fn load_description_mapped(path: &Path) -> Result<(RobotDescription, SourceMap)> {
    let text = read(path)?;
    let file = path.display().to_string();
    match Format::from_path(path)? {
        Format::Toml => toml_format::parse_description(&text, Some(&file)),
        Format::Par => par::parse_description(&text, Some(&file)),
        Format::Urdf => urdf::parse_description(&text, Some(&file)),
    }
}

/// Read a robot description from a file.
pub fn load_description(path: &Path) -> Result<RobotDescription> {
    load_description_mapped(path).map(|(d, _)| d)
}

/// Read and validate a robot. `overrides` gives or replaces symbol values (the CLI's `--set`).
pub fn load_with(path: &Path, overrides: &BTreeMap<String, f64>) -> Result<Robot> {
    let (mut desc, map) = load_description_mapped(path)?;
    desc.symbols
        .extend(overrides.iter().map(|(k, v)| (k.clone(), *v)));
    Robot::new(desc).map_err(|e| map.locate(e))
}

/// Read and validate a robot.
pub fn load(path: &Path) -> Result<Robot> {
    load_with(path, &BTreeMap::new())
}

/// Write a description in the format given by the file's extension.
pub fn save_description(desc: &RobotDescription, path: &Path) -> Result<()> {
    let text = match Format::from_path(path)? {
        Format::Toml => toml_format::write_description(desc),
        Format::Par => par::write_description(desc),
        Format::Urdf => {
            return Err(Error::Input(
                "writing URDF is not supported: convert to .toml or .par".into(),
            ))
        }
    };
    std::fs::write(path, text).map_err(|e| Error::io(path.display().to_string(), e))
}
