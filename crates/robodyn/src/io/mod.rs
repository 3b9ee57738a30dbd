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
mod values;

pub use crate::model::inertial::body_inconsistency;
pub use consistency::physical_consistency;
pub use source::{LineIndex, SourceMap};
pub use values::{known_symbols, set_values};

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

/// The largest robot file read (64 MiB: the largest real URDF is a few hundred kB); a larger
/// one, or an endless one (`/dev/zero`), is an error instead of exhausting memory.
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// Read a text file of at most [`MAX_FILE_BYTES`] (see [`decode_text`]); `-` is standard input.
fn read(path: &Path) -> Result<String> {
    let name = if is_stdio(path) {
        "<stdin>".to_string()
    } else {
        path.display().to_string()
    };
    let input: Box<dyn std::io::Read> = if is_stdio(path) {
        Box::new(std::io::stdin().lock())
    } else {
        Box::new(std::fs::File::open(path).map_err(|e| Error::io(name.clone(), e))?)
    };
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(
        &mut std::io::Read::take(input, MAX_FILE_BYTES + 1),
        &mut bytes,
    )
    .map_err(|e| Error::io(name.clone(), e))?;
    if bytes.len() as u64 > MAX_FILE_BYTES {
        return Err(Error::Input(format!(
            "{name}: longer than {} MiB: not a robot file",
            MAX_FILE_BYTES >> 20
        )));
    }
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
pub fn load_description_mapped(path: impl AsRef<Path>) -> Result<(RobotDescription, SourceMap)> {
    load_description_with(path, &BTreeMap::new())
}

/// [`load_description_mapped`] with symbol values given or replaced (`overrides`, the CLI's
/// `--set`) before the physical-consistency check, so that the check sees the values used.
pub fn load_description_with(
    path: impl AsRef<Path>,
    overrides: &BTreeMap<String, f64>,
) -> Result<(RobotDescription, SourceMap)> {
    load_description_with_options(path, overrides, &LoadOptions::default())
}

/// How a file is read beyond what it says.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct LoadOptions {
    /// Make the base floating: a URDF's root link becomes link 0 of a free-flyer base, with its
    /// `<inertial>` (Pinocchio's `JointModelFreeFlyer` root). A `.toml` or `.par` file says it
    /// itself (`base = "floating"`, `is_floating = 1`); for them this is an error unless the
    /// file's base already floats.
    pub floating: bool,
}

impl LoadOptions {
    /// The options with a floating base.
    pub fn floating() -> LoadOptions {
        LoadOptions { floating: true }
    }
}

/// [`load_description_with`] with [`LoadOptions`].
pub fn load_description_with_options(
    path: impl AsRef<Path>,
    overrides: &BTreeMap<String, f64>,
    options: &LoadOptions,
) -> Result<(RobotDescription, SourceMap)> {
    let path = path.as_ref();
    let text = read(path)?;
    let (file, format) = if is_stdio(path) {
        ("<stdin>".to_string(), Format::sniff(&text))
    } else {
        (path.display().to_string(), Format::from_path(path)?)
    };
    let (mut desc, mut map) = match format {
        Format::Toml => toml_format::parse_description(&text, Some(&file)),
        Format::Par => par::parse_description(&text, Some(&file)),
        Format::Urdf => urdf::parse_description_with(&text, Some(&file), options.floating),
    }?;
    if options.floating && desc.floating_base.is_none() {
        return Err(Error::Input(format!(
            "{file}: a floating base is asked for, but the file's base is {}: a .toml file \
             says base = \"floating\" (with [base_link]), a .par file is_floating = 1 with \
             link 0's parameters (only a URDF's root link is made floating on request)",
            if desc.mobile_base { "mobile" } else { "fixed" }
        )));
    }
    for w in physical_consistency(&desc) {
        map.warn(w);
    }
    set_values_mapped(&mut desc, &mut map, overrides)?;
    Ok((desc, map))
}

/// [`set_values`] on a loaded description, with the physical consistency checked again on the
/// new values: its warnings replace those of the old values in `map` (the reader's own warnings
/// stay).
pub fn set_values_mapped(
    desc: &mut RobotDescription,
    map: &mut SourceMap,
    values: &BTreeMap<String, f64>,
) -> Result<()> {
    if values.is_empty() {
        return Ok(());
    }
    let old = physical_consistency(desc);
    set_values(desc, values)?;
    map.warnings.retain(|w| {
        !old.iter()
            .any(|o| o.item == w.item && o.message == w.message)
    });
    for w in physical_consistency(desc) {
        map.warn(w);
    }
    Ok(())
}

/// Read and validate a robot, with the warnings of [`load_description_with`]; `overrides`
/// give values by name as [`set_values`] does.
pub fn load_with_warnings(
    path: impl AsRef<Path>,
    overrides: &BTreeMap<String, f64>,
) -> Result<(Robot, Vec<Warning>)> {
    load_with_warnings_options(path, overrides, &LoadOptions::default())
}

/// [`load_with_warnings`] with [`LoadOptions`] (a URDF with a floating base).
pub fn load_with_warnings_options(
    path: impl AsRef<Path>,
    overrides: &BTreeMap<String, f64>,
    options: &LoadOptions,
) -> Result<(Robot, Vec<Warning>)> {
    let (desc, map) = load_description_with_options(path, overrides, options)?;
    let robot = Robot::new(desc).map_err(|e| map.locate(e))?;
    Ok((robot, map.warnings))
}

/// Read and validate a robot with [`LoadOptions`] (e.g. a URDF with a floating base:
/// `load_with_options(path, &Default::default(), &LoadOptions::floating())`).
pub fn load_with_options(
    path: impl AsRef<Path>,
    overrides: &BTreeMap<String, f64>,
    options: &LoadOptions,
) -> Result<Robot> {
    load_with_warnings_options(path, overrides, options).map(|(r, _)| r)
}

/// Read a robot description from a file.
pub fn load_description(path: impl AsRef<Path>) -> Result<RobotDescription> {
    load_description_mapped(path).map(|(d, _)| d)
}

/// Read and validate a robot. `overrides` give values by name as [`set_values`] does (symbols,
/// and standard parameters written as numbers); an unknown name is an error.
pub fn load_with(path: impl AsRef<Path>, overrides: &BTreeMap<String, f64>) -> Result<Robot> {
    load_with_warnings(path, overrides).map(|(r, _)| r)
}

/// Read and validate a robot.
pub fn load(path: impl AsRef<Path>) -> Result<Robot> {
    load_with(path, &BTreeMap::new())
}

/// The text of a description in a format (TOML or `.par`; URDF is not written).
pub fn description_text(desc: &RobotDescription, format: Format) -> Result<String> {
    Ok(match format {
        Format::Toml => toml_format::write_description(desc),
        Format::Par => par::write_description(desc),
        Format::Urdf => {
            return Err(Error::Input(
                "writing URDF is not supported: convert to .toml or .par".into(),
            ))
        }
    })
}

/// Write a description in the format given by the file's extension.
pub fn save_description(desc: &RobotDescription, path: impl AsRef<Path>) -> Result<()> {
    let path = path.as_ref();
    let text = description_text(desc, Format::from_path(path)?)?;
    std::fs::write(path, text).map_err(|e| Error::io(path.display().to_string(), e))
}
