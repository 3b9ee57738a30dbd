//! Errors are values: every error says where (file, line, frame, link, loop) and why.

use std::fmt;

/// What part of a robot description an error refers to.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Item {
    /// The description as a whole (counts, structure).
    Robot,
    /// Frame j, optionally one of its parameters (`d`, `ant`, ...).
    Frame(usize, Option<String>),
    /// Link j, optionally one of its parameters (`XX`, `M`, `FX`, ...).
    Link(usize, Option<String>),
    /// A base quantity (`G`, `W0`, ...), optionally a component.
    Base(String),
    /// A symbol definition.
    Symbol(String),
    /// Closed loop number l (1-based), with its cut joint.
    Loop(usize),
}

impl fmt::Display for Item {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Item::Robot => write!(f, "robot"),
            Item::Frame(j, None) => write!(f, "frame {j}"),
            Item::Frame(j, Some(p)) => write!(f, "frame {j}, {p}"),
            Item::Link(j, None) => write!(f, "link {j}"),
            Item::Link(j, Some(p)) => write!(f, "link {j}, {p}"),
            Item::Base(p) => write!(f, "{p}"),
            Item::Symbol(s) => write!(f, "symbol {s}"),
            Item::Loop(l) => write!(f, "loop {l}"),
        }
    }
}

/// Position in a source file.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Location {
    pub file: Option<String>,
    pub line: Option<usize>,
    pub column: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if let Some(file) = &self.file {
            write!(f, "{file}")?;
        }
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.column {
                write!(f, ":{c}")?;
            }
        }
        Ok(())
    }
}

/// The error type of the library.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// A robot description is invalid (bad structure, unknown symbol, NaN, negative mass...).
    #[error("{}{item}: {reason}", fmt_loc(.location))]
    Invalid {
        location: Location,
        item: Item,
        reason: String,
    },
    /// A file could not be parsed.
    #[error("{}{reason}", fmt_loc(.location))]
    Parse { location: Location, reason: String },
    /// Input data (states, sizes) do not fit the robot.
    #[error("{0}")]
    Input(String),
    /// A numerical failure (singular matrix, no convergence), with what was involved.
    #[error("{0}")]
    Numerical(String),
    /// I/O.
    #[error("{path}: {reason}")]
    Io { path: String, reason: String },
}

fn fmt_loc(l: &Location) -> String {
    let s = l.to_string();
    if s.is_empty() {
        s
    } else {
        format!("{s}: ")
    }
}

impl Error {
    pub fn invalid(item: Item, reason: impl Into<String>) -> Error {
        Error::Invalid {
            location: Location::default(),
            item,
            reason: reason.into(),
        }
    }

    pub fn parse(file: Option<&str>, line: usize, reason: impl Into<String>) -> Error {
        Error::Parse {
            location: Location {
                file: file.map(str::to_string),
                line: Some(line),
                column: None,
            },
            reason: reason.into(),
        }
    }

    /// Attach a file name (and a line, if the error has none yet).
    pub fn at(mut self, file: Option<&str>, line: Option<usize>) -> Error {
        if let Error::Invalid { location, .. } | Error::Parse { location, .. } = &mut self {
            if location.file.is_none() {
                location.file = file.map(str::to_string);
            }
            if location.line.is_none() {
                location.line = line;
            }
        }
        self
    }

    /// The description item an `Invalid` error refers to.
    pub fn item(&self) -> Option<&Item> {
        match self {
            Error::Invalid { item, .. } => Some(item),
            _ => None,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
