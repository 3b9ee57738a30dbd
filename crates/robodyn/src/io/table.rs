//! State tables: CSV with a header of column names and one state per row of finite numbers
//! (`q1, qd1, qdd1, ...`), as the commands read them with `--input`.

use crate::error::{Error, Result};

/// A table of named numeric columns.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    /// Column names, in file order (unique).
    pub headers: Vec<String>,
    /// Data rows, each with one value per column.
    pub rows: Vec<Vec<f64>>,
    /// The file the table came from (for messages).
    pub file: String,
}

/// The header of a table of named columns: at least one name, none empty, none repeated (the
/// reason names the columns). Shared with identification's logs.
pub fn check_header(headers: &[String]) -> std::result::Result<(), String> {
    if headers.is_empty() || headers.iter().all(String::is_empty) {
        return Err("no header line (column names)".into());
    }
    for (k, h) in headers.iter().enumerate() {
        if h.is_empty() {
            return Err(format!("column {} has no name", k + 1));
        }
        if let Some(first) = headers[..k].iter().position(|o| o == h) {
            return Err(format!(
                "column `{h}` appears twice (columns {} and {})",
                first + 1,
                k + 1
            ));
        }
    }
    Ok(())
}

impl Table {
    /// Parse CSV text: a header line, then rows of numbers (fields are trimmed; `#` starts a
    /// comment line). Errors name the file, the line and the column: a repeated or empty column
    /// name, a row whose length differs from the header's, a field that is not a finite number.
    pub fn parse(text: &[u8], file: &str) -> Result<Table> {
        let err = |line: Option<u64>, reason: String| match line {
            Some(l) => Error::parse(Some(file), l as usize, reason),
            None => Error::Input(format!("{file}: {reason}")),
        };
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(text);
        let csv_err = |e: csv::Error| {
            let line = e.position().map(|p| p.line());
            let reason = match e.kind() {
                csv::ErrorKind::UnequalLengths {
                    expected_len, len, ..
                } => format!("{len} fields, the header has {expected_len}"),
                _ => e.to_string(),
            };
            err(line, reason)
        };
        let headers: Vec<String> = rdr
            .headers()
            .map_err(csv_err)?
            .iter()
            .map(str::to_string)
            .collect();
        check_header(&headers).map_err(|reason| err(Some(1), reason))?;
        let mut rows = Vec::new();
        // one record reused for every row (no allocation per row but the row itself), fields
        // as bytes: a number is ASCII, anything else is refused below with its text
        let mut rec = csv::ByteRecord::new();
        while rdr.read_byte_record(&mut rec).map_err(csv_err)? {
            rec.trim();
            let line = rec.position().map(|p| p.line());
            let mut row = Vec::with_capacity(headers.len());
            for (k, field) in rec.iter().enumerate() {
                let text = || String::from_utf8_lossy(field);
                let x: f64 = std::str::from_utf8(field)
                    .ok()
                    .and_then(|f| f.parse().ok())
                    .ok_or_else(|| {
                        err(
                            line,
                            format!("column `{}`: `{}` is not a number", headers[k], text()),
                        )
                    })?;
                if !x.is_finite() {
                    return Err(err(
                        line,
                        format!("column `{}`: {x} is not a finite number", headers[k]),
                    ));
                }
                row.push(x);
            }
            rows.push(row);
        }
        Ok(Table {
            headers,
            rows,
            file: file.to_string(),
        })
    }

    /// Read a CSV file (see [`Table::parse`]).
    pub fn read(path: &std::path::Path) -> Result<Table> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| Error::io(file.clone(), e))?;
        Table::parse(&bytes, &file)
    }

    /// Index of a column, if present.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }
}
