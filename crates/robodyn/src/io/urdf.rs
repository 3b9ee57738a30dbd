//! URDF import (placeholder, filled below).
use crate::error::{Error, Result};
use crate::io::SourceMap;
use crate::model::RobotDescription;

pub fn parse_description(_text: &str, file: Option<&str>) -> Result<(RobotDescription, SourceMap)> {
    Err(Error::Input(format!(
        "{}: URDF not yet",
        file.unwrap_or("")
    )))
}
