//! Robot files: native TOML, SYMORO's .par and URDF, every error with a file position.
//!
//! [`load_description`] reads any of them (chosen by extension) into a [`RobotDescription`];
//! [`load`] also validates it into a [`Robot`], which needs a numeric value for every symbol.

mod consistency;
pub mod fuzz_checks;
pub mod par;
pub mod source;
pub mod table;
pub mod toml_format;
pub mod urdf;

pub use crate::model::inertial::body_inconsistency;
pub use consistency::physical_consistency;
pub use source::{LineIndex, SourceMap};

use crate::error::{Error, Item, Location, Result};
use crate::model::RobotDescription;
use crate::Robot;
use std::collections::BTreeMap;
use std::path::Path;

/// Something a reader noticed that is not an error: the file loads, but may not mean what its
/// author meant (a SYMORO reading that differs from robodyn's, inertial parameters no rigid body
/// has, a name a writer had to escape).
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    /// File and line, when known.
    pub location: Location,
    /// The frame, link, key... concerned.
    pub item: Option<Item>,
    /// What was noticed.
    pub message: String,
}

impl Warning {
    /// A warning about `item`, without a position yet.
    pub fn new(item: Item, message: impl Into<String>) -> Warning {
        Warning {
            location: Location::default(),
            item: Some(item),
            message: message.into(),
        }
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let loc = self.location.to_string();
        if !loc.is_empty() {
            write!(f, "{loc}: ")?;
        }
        if let Some(item) = &self.item {
            write!(f, "{item}: ")?;
        }
        f.write_str(&self.message)
    }
}

/// The file formats robodyn reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// robodyn's TOML (`docs/robot-format.md`).
    Toml,
    /// SYMORO's `.par`.
    Par,
    /// URDF (read only).
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

impl Format {
    /// Format of a robot file's text (for a file read from standard input): URDF when it starts
    /// with `<`, TOML when a line starts a `[[frame]]` or `[[link]]` table, otherwise `.par`.
    pub fn sniff(text: &str) -> Format {
        let t = text.trim_start_matches('\u{feff}').trim_start();
        if t.starts_with('<') {
            Format::Urdf
        } else if t.lines().any(|l| {
            let l = l.trim_start();
            l.starts_with("[[frame]]") || l.starts_with("[[link]]")
        }) {
            Format::Toml
        } else {
            Format::Par
        }
    }
}

/// Whether a path names standard input/output (`-`).
pub fn is_stdio(path: &Path) -> bool {
    path.as_os_str() == "-"
}

/// Read a text file (see [`decode_text`]); `-` is standard input.
fn read(path: &Path) -> Result<String> {
    let bytes = if is_stdio(path) {
        let mut b = Vec::new();
        std::io::Read::read_to_end(&mut std::io::stdin().lock(), &mut b)
            .map_err(|e| Error::io("<stdin>", e))?;
        b
    } else {
        std::fs::read(path).map_err(|e| Error::io(path.display().to_string(), e))?
    };
    Ok(decode_text(bytes))
}

/// The text of a robot file: UTF-8, or else Latin-1 (SYMORO+ writes Latin-1 comments such as
/// "Noë").
pub fn decode_text(bytes: Vec<u8>) -> String {
    match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => e.as_bytes().iter().map(|&b| b as char).collect(),
    }
}

/// Read a robot description from a file, with the positions of its entries. The map's
/// [`SourceMap::warnings`] hold what the reader noticed and the physical-consistency check
/// ([`physical_consistency`]) found, with their lines. The path `-` reads standard input, the
/// format found by [`Format::sniff`].
pub fn load_description_mapped(path: &Path) -> Result<(RobotDescription, SourceMap)> {
    load_description_with(path, &BTreeMap::new())
}

/// [`load_description_mapped`] with symbol values given or replaced (`overrides`, the CLI's
/// `--set`) before the physical-consistency check, so that the check sees the values used.
pub fn load_description_with(
    path: &Path,
    overrides: &BTreeMap<String, f64>,
) -> Result<(RobotDescription, SourceMap)> {
    let text = read(path)?;
    let (file, format) = if is_stdio(path) {
        ("<stdin>".to_string(), Format::sniff(&text))
    } else {
        (path.display().to_string(), Format::from_path(path)?)
    };
    let (mut desc, mut map) = match format {
        Format::Toml => toml_format::parse_description(&text, Some(&file)),
        Format::Par => par::parse_description(&text, Some(&file)),
        Format::Urdf => urdf::parse_description(&text, Some(&file)),
    }?;
    for w in physical_consistency(&desc) {
        map.warn(w);
    }
    set_symbols(&mut desc, &mut map, overrides);
    Ok((desc, map))
}

/// Give or replace symbol values of a loaded description (the CLI's `--set`) and check the
/// physical consistency again on the new values: its warnings replace those of the old values
/// in `map` (the reader's own warnings stay).
pub fn set_symbols(
    desc: &mut RobotDescription,
    map: &mut SourceMap,
    values: &BTreeMap<String, f64>,
) {
    if values.is_empty() {
        return;
    }
    let old = physical_consistency(desc);
    map.warnings.retain(|w| {
        !old.iter()
            .any(|o| o.item == w.item && o.message == w.message)
    });
    desc.symbols
        .extend(values.iter().map(|(k, v)| (k.clone(), *v)));
    for w in physical_consistency(desc) {
        map.warn(w);
    }
}

/// Read and validate a robot, with the warnings of [`load_description_with`].
pub fn load_with_warnings(
    path: &Path,
    overrides: &BTreeMap<String, f64>,
) -> Result<(Robot, Vec<Warning>)> {
    let (desc, map) = load_description_with(path, overrides)?;
    let robot = Robot::new(desc).map_err(|e| map.locate(e))?;
    Ok((robot, map.warnings))
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
