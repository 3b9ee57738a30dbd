//! Where trajectory rows go: a CSV stream (rows written as they are computed, so a simulation
//! that stops keeps what it wrote) and an in-memory recorder (for the plot, `plot.rs`).

use crate::error::{Error, Result};
use std::io::Write;
use std::path::Path;

/// Receives the trajectory: the column names once, then one row per output time.
pub trait TrajectorySink {
    /// Receive the column names.
    fn begin(&mut self, headers: &[String]) -> Result<()>;
    /// Receive one row.
    fn row(&mut self, values: &[f64]) -> Result<()>;
    /// Flush; called at the end and when the simulation stops on an error.
    fn finish(&mut self) -> Result<()> {
        Ok(())
    }
}

pub use crate::report::number::{format_number, Number};

/// CSV stream with a header line; numbers by [`format_number`]; flushed after each row.
pub struct CsvSink<W: Write> {
    out: W,
    name: String,
}

impl CsvSink<std::io::BufWriter<std::fs::File>> {
    /// Create (truncate) a CSV file.
    pub fn create(path: &Path) -> Result<Self> {
        let f =
            std::fs::File::create(path).map_err(|e| Error::io(path.display().to_string(), e))?;
        Ok(CsvSink::new(
            std::io::BufWriter::new(f),
            path.display().to_string(),
        ))
    }
}

impl<W: Write> CsvSink<W> {
    /// Stream to any writer; `name` is used in error messages.
    pub fn new(out: W, name: impl Into<String>) -> Self {
        CsvSink {
            out,
            name: name.into(),
        }
    }

    /// The writer.
    pub fn into_inner(self) -> W {
        self.out
    }

    fn io(&self, e: std::io::Error) -> Error {
        Error::io(self.name.clone(), e)
    }
}

impl<W: Write> TrajectorySink for CsvSink<W> {
    fn begin(&mut self, headers: &[String]) -> Result<()> {
        writeln!(self.out, "{}", headers.join(",")).map_err(|e| self.io(e))
    }
    fn row(&mut self, values: &[f64]) -> Result<()> {
        let mut first = true;
        for &v in values {
            let v = format_number(v);
            let r = if first {
                write!(self.out, "{v}")
            } else {
                write!(self.out, ",{v}")
            };
            r.map_err(|e| self.io(e))?;
            first = false;
        }
        writeln!(self.out).map_err(|e| self.io(e))?;
        // rows reach the file as they are computed (a long or stopped run keeps them)
        self.out.flush().map_err(|e| self.io(e))
    }
    fn finish(&mut self) -> Result<()> {
        self.out.flush().map_err(|e| self.io(e))
    }
}

/// Keeps the trajectory in memory.
#[derive(Clone, Debug, Default)]
pub struct Recorder {
    /// Column names.
    pub headers: Vec<String>,
    /// Rows.
    pub rows: Vec<Vec<f64>>,
}

impl Recorder {
    /// Index of a column.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }

    /// All values of a column.
    pub fn series(&self, name: &str) -> Option<Vec<f64>> {
        let c = self.column(name)?;
        Some(self.rows.iter().map(|r| r[c]).collect())
    }
}

impl TrajectorySink for Recorder {
    fn begin(&mut self, headers: &[String]) -> Result<()> {
        self.headers = headers.to_vec();
        Ok(())
    }
    fn row(&mut self, values: &[f64]) -> Result<()> {
        self.rows.push(values.to_vec());
        Ok(())
    }
}

/// Sends every row to two sinks.
pub struct Tee<'a>(
    pub &'a mut dyn TrajectorySink,
    pub &'a mut dyn TrajectorySink,
);

impl TrajectorySink for Tee<'_> {
    fn begin(&mut self, headers: &[String]) -> Result<()> {
        self.0.begin(headers)?;
        self.1.begin(headers)
    }
    fn row(&mut self, values: &[f64]) -> Result<()> {
        self.0.row(values)?;
        self.1.row(values)
    }
    fn finish(&mut self) -> Result<()> {
        let a = self.0.finish();
        let b = self.1.finish();
        a.and(b)
    }
}
