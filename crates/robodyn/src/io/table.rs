//! State tables: CSV with a header of column names and one state per row of finite numbers
//! (`q1, qd1, qdd1, ...`), as the commands read them with `--input`.
//!
//! [`TableReader`] reads one row at a time from any reader (a file, standard input, a pipe)
//! with bounded memory: a line longer than [`MAX_LINE_BYTES`] is an error naming its line, so
//! a file of one endless line (`/dev/zero`) ends with an error instead of exhausting memory.
//! [`Table`] reads a whole table through it.

use crate::error::{Error, Result};
use std::io::Read;

/// The longest line a table may have, in bytes (1 MiB: a state of 1000 joints is ~75 kB).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// A reader that fails on a line longer than `max` bytes, and knows the line it is on.
struct LineLimit<R> {
    inner: R,
    max: usize,
    /// Bytes since the last newline.
    current: usize,
    /// 1-based line of the next byte.
    line: u64,
    /// The line that was too long, once one was.
    too_long: Option<u64>,
}

impl<R: Read> Read for LineLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' {
                self.line += 1;
                self.current = 0;
            } else {
                self.current += 1;
                if self.current > self.max {
                    self.too_long = Some(self.line);
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::InvalidData,
                        "line too long",
                    ));
                }
            }
        }
        Ok(n)
    }
}

/// A table read row by row: the header first ([`TableReader::headers`]), then
/// [`TableReader::next_row`] until it returns `false`.
pub struct TableReader<R: Read> {
    rdr: csv::Reader<LineLimit<R>>,
    headers: Vec<String>,
    file: String,
    rec: csv::ByteRecord,
    line: u64,
}

impl<R: Read> TableReader<R> {
    /// Read the header from `input` (fields are trimmed; `#` starts a comment line). Errors name
    /// the file and the line: a repeated or empty column name, no header, a line longer than
    /// [`MAX_LINE_BYTES`].
    pub fn new(input: R, file: &str) -> Result<TableReader<R>> {
        Self::with_max_line(input, file, MAX_LINE_BYTES)
    }

    /// [`TableReader::new`] with another line limit (bytes).
    pub fn with_max_line(input: R, file: &str, max_line: usize) -> Result<TableReader<R>> {
        let limited = LineLimit {
            inner: input,
            max: max_line,
            current: 0,
            line: 1,
            too_long: None,
        };
        let rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(limited);
        let mut t = TableReader {
            rdr,
            headers: Vec::new(),
            file: file.to_string(),
            rec: csv::ByteRecord::new(),
            line: 1,
        };
        let headers: Vec<String> = match t.rdr.headers() {
            Ok(h) => h.iter().map(str::to_string).collect(),
            Err(e) => return Err(t.csv_error(e)),
        };
        check_header(&headers).map_err(|reason| t.error(Some(1), reason))?;
        t.headers = headers;
        Ok(t)
    }

    /// The column names, in file order (unique, not empty).
    pub fn headers(&self) -> &[String] {
        &self.headers
    }

    /// The file the table comes from (for messages).
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The line of the last row read (1-based; the header is line 1).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// Read the next row into `row` (cleared; one value per column): `false` at the end. A row
    /// whose length differs from the header's or a field that is not a finite number is an
    /// error with its line.
    pub fn next_row(&mut self, row: &mut Vec<f64>) -> Result<bool> {
        row.clear();
        // one record reused for every row, fields as bytes: a number is ASCII, anything else
        // is refused below with its text
        match self.rdr.read_byte_record(&mut self.rec) {
            Ok(false) => return Ok(false),
            Ok(true) => {}
            Err(e) => return Err(self.csv_error(e)),
        }
        self.rec.trim();
        let line = self.rec.position().map(|p| p.line());
        self.line = line.unwrap_or(self.line);
        for (k, field) in self.rec.iter().enumerate() {
            let x: Option<f64> = std::str::from_utf8(field).ok().and_then(|f| f.parse().ok());
            let reason = match x {
                Some(x) if x.is_finite() => {
                    row.push(x);
                    continue;
                }
                Some(x) => format!("column `{}`: {x} is not a finite number", self.headers[k]),
                None => format!(
                    "column `{}`: `{}` is not a number",
                    self.headers[k],
                    String::from_utf8_lossy(field)
                ),
            };
            return Err(self.error(line, reason));
        }
        Ok(true)
    }

    fn error(&self, line: Option<u64>, reason: String) -> Error {
        match line {
            Some(l) => Error::parse(Some(&self.file), l as usize, reason),
            None => Error::Input(format!("{}: {reason}", self.file)),
        }
    }

    fn csv_error(&self, e: csv::Error) -> Error {
        if let Some(l) = self.rdr.get_ref().too_long {
            return self.error(
                Some(l),
                format!(
                    "the line is longer than {} bytes (a state table has one state per line)",
                    self.rdr.get_ref().max
                ),
            );
        }
        let line = e.position().map(|p| p.line());
        let reason = match e.kind() {
            csv::ErrorKind::UnequalLengths {
                expected_len, len, ..
            } => format!("{len} fields, the header has {expected_len}"),
            csv::ErrorKind::Io(io) => {
                let l = self.rdr.get_ref().line;
                return self.error(Some(l), io.to_string());
            }
            _ => e.to_string(),
        };
        self.error(line, reason)
    }
}

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
    /// name, a row whose length differs from the header's, a field that is not a finite number,
    /// a line longer than [`MAX_LINE_BYTES`].
    pub fn parse(text: &[u8], file: &str) -> Result<Table> {
        Table::from_reader(text, file)
    }

    /// Read a whole table from any reader (see [`Table::parse`]).
    pub fn from_reader<R: Read>(input: R, file: &str) -> Result<Table> {
        let mut t = TableReader::new(input, file)?;
        let mut rows = Vec::new();
        let mut row = Vec::new();
        while t.next_row(&mut row)? {
            rows.push(std::mem::take(&mut row));
            row.reserve(t.headers.len());
        }
        Ok(Table {
            headers: t.headers,
            rows,
            file: t.file,
        })
    }

    /// Read a CSV file (see [`Table::parse`]).
    pub fn read(path: &std::path::Path) -> Result<Table> {
        let file = path.display().to_string();
        let f = std::fs::File::open(path).map_err(|e| Error::io(file.clone(), e))?;
        Table::from_reader(std::io::BufReader::new(f), &file)
    }

    /// Index of a column, if present.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }
}

#[cfg(test)]
mod tests {
    use super::{Table, TableReader};
    use std::io::Read;

    /// A line beyond the limit is an error naming its line, read no further than the limit
    /// (an endless reader ends).
    #[test]
    fn long_line_is_an_error_with_its_line() {
        let e = Table::parse(b"q1,q2\n1,2\n3,4444444444\n", "t.csv").unwrap();
        assert_eq!(e.rows.len(), 2);
        let err = match TableReader::with_max_line(&b"q1,q2\n1,2\n3,4444444444\n"[..], "t.csv", 8) {
            Ok(mut t) => {
                let mut row = Vec::new();
                assert!(t.next_row(&mut row).unwrap());
                t.next_row(&mut row).unwrap_err()
            }
            Err(e) => e,
        };
        let m = err.to_string();
        assert!(
            m.starts_with("t.csv:3: the line is longer than 8 bytes"),
            "{m}"
        );
        // an endless line of zeros: an error, after reading about the limit
        let err = Table::from_reader(std::io::repeat(0), "zeros").unwrap_err();
        assert!(
            err.to_string().starts_with("zeros:1: the line is longer"),
            "{err}"
        );
        let err = Table::from_reader((&b"t,q1\n"[..]).chain(std::io::repeat(b'1')), "ones");
        assert!(
            err.unwrap_err()
                .to_string()
                .starts_with("ones:2: the line is longer"),
            "line 2"
        );
    }

    #[test]
    fn rows_and_errors_keep_their_lines() {
        let t = Table::parse(b"a, b\n# comment\n1, 2\n\n3,4\n", "x").unwrap();
        assert_eq!(t.headers, ["a", "b"]);
        assert_eq!(t.rows, [[1.0, 2.0], [3.0, 4.0]]);
        let e = Table::parse(b"a,b\n1,2\n3,nan\n", "x").unwrap_err();
        assert_eq!(e.to_string(), "x:3: column `b`: NaN is not a finite number");
        let e = Table::parse(b"a,b\n1,2\n3\n", "x").unwrap_err();
        assert_eq!(e.to_string(), "x:3: 1 fields, the header has 2");
        let e = Table::parse(b"a,a\n", "x").unwrap_err();
        assert_eq!(
            e.to_string(),
            "x:1: column `a` appears twice (columns 1 and 2)"
        );
    }
}
