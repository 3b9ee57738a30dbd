//! Every file a command writes (`--output`, `--plot`, `--write-robot`, `convert`'s OUT,
//! `generate`'s file...) goes through [`Output`]: written all or nothing.
//!
//! The content is written to a temporary file in the target's directory and renamed onto the
//! target only when the command succeeds ([`Output::commit`]); a reader sees the previous file or
//! the new one, never a mixture, two processes writing one file leave one of their files whole,
//! and a run that fails (an error, a full disk) leaves the previous file as it was and removes
//! its temporary file. Standard output (`-`, or no file where it is optional), targets that are
//! not regular files (`/dev/null`, a pipe) and files under `/dev` and `/proc` (`/dev/stdout`)
//! are written directly. Two outputs of one command that name the same file are refused before
//! anything is written ([`check_distinct`]).

use crate::common::CliResult;
use robodyn::simulation::output::Number;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Where an [`Output`] writes.
enum Sink {
    Stdout(std::io::BufWriter<std::io::Stdout>),
    /// A target that is not a regular file, written in place.
    Direct(std::io::BufWriter<std::fs::File>),
    /// A temporary file renamed onto `target` by [`Output::commit`].
    Temporary {
        file: std::io::BufWriter<tempfile::NamedTempFile>,
        target: PathBuf,
        /// The target's permissions, when it exists (kept by the new file).
        permissions: Option<std::fs::Permissions>,
    },
}

/// An output file written all or nothing (see the module documentation).
pub struct Output {
    sink: Sink,
    /// The file as the user named it, or "standard output".
    name: String,
}

impl Output {
    /// Start writing to `path` (`None` or `-`: standard output). The temporary file is made
    /// now, so a target in a missing or read-only directory is an error before any work.
    pub fn create(path: Option<&Path>) -> CliResult<Output> {
        let Some(path) = path.filter(|p| !robodyn::io::is_stdio(p)) else {
            return Ok(Output {
                sink: Sink::Stdout(std::io::BufWriter::new(std::io::stdout())),
                name: "standard output".into(),
            });
        };
        let name = path.display().to_string();
        let fail = |e: std::io::Error| format!("{name}: {e}");
        // a symbolic link is followed: the file it points to is replaced, the link kept
        let target = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let meta = std::fs::metadata(&target).ok();
        // `/dev/stdout` may resolve to the regular file a shell redirected to: written in place,
        // as every file under /dev and /proc and every file that is not a regular file
        let special = path.starts_with("/dev") || path.starts_with("/proc");
        if let Some(m) = meta.as_ref().filter(|m| !m.is_file() || special) {
            if m.is_dir() {
                return Err(format!("{name}: is a directory").into());
            }
            let f = std::fs::OpenOptions::new()
                .write(true)
                .truncate(true)
                .open(&target)
                .map_err(fail)?;
            return Ok(Output {
                sink: Sink::Direct(std::io::BufWriter::new(f)),
                name,
            });
        }
        let dir = match target.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let file_name = target
            .file_name()
            .map_or_else(|| "output".into(), |f| f.to_string_lossy().into_owned());
        let mut builder = tempfile::Builder::new();
        let prefix = format!(".{file_name}.");
        builder.prefix(&prefix).suffix(".tmp");
        #[cfg(unix)]
        {
            // a new file gets the usual permissions (0666 less the umask), not 0600
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(std::fs::Permissions::from_mode(0o666));
        }
        let tmp = builder.tempfile_in(&dir).map_err(|e| {
            format!(
                "{name}: cannot write in the directory {}: {e}",
                dir.display()
            )
        })?;
        Ok(Output {
            sink: Sink::Temporary {
                file: std::io::BufWriter::new(tmp),
                target,
                permissions: meta.map(|m| m.permissions()),
            },
            name,
        })
    }

    /// The file as named on the command line, or "standard output" (for messages).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether this is standard output.
    pub fn is_stdout(&self) -> bool {
        matches!(self.sink, Sink::Stdout(_))
    }

    /// The buffered writer of the content.
    pub fn writer(&mut self) -> &mut dyn Write {
        match &mut self.sink {
            Sink::Stdout(w) => w,
            Sink::Direct(w) => w,
            Sink::Temporary { file, .. } => file,
        }
    }

    /// Write bytes (an error names the file).
    pub fn write_all(&mut self, bytes: &[u8]) -> CliResult {
        let r = self.writer().write_all(bytes);
        r.map_err(|e| self.io(e))
    }

    /// Write the content through a library function that writes a file by its path (the SVG
    /// plots): it writes the temporary file. Standard output gets the file's bytes.
    pub fn write_by_path<E: Into<Box<dyn std::error::Error>>>(
        &mut self,
        f: impl FnOnce(&Path) -> Result<(), E>,
    ) -> CliResult {
        match &mut self.sink {
            Sink::Temporary { file, .. } => {
                file.flush().map_err(|e| format!("{}: {e}", self.name))?;
                let path = file.get_ref().path().to_path_buf();
                f(&path).map_err(|e| self.named(e.into()))
            }
            _ => {
                let tmp = tempfile::NamedTempFile::new()?;
                f(tmp.path()).map_err(|e| self.named(e.into()))?;
                let bytes = std::fs::read(tmp.path())?;
                self.writer().write_all(&bytes).map_err(|e| self.io(e))
            }
        }
    }

    /// An error of the writer, naming this output.
    fn named(&self, e: Box<dyn std::error::Error>) -> Box<dyn std::error::Error> {
        let m = e.to_string();
        // the temporary file's name means nothing to the user
        match &self.sink {
            Sink::Temporary { file, .. } => {
                let tmp = file.get_ref().path().display().to_string();
                if m.contains(&tmp) {
                    m.replace(&tmp, &self.name).into()
                } else {
                    format!("{}: {m}", self.name).into()
                }
            }
            _ => e,
        }
    }

    fn io(&self, e: std::io::Error) -> Box<dyn std::error::Error> {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            return e.into();
        }
        format!("{}: {e}", self.name).into()
    }

    /// Finish: flush, and put the new file in place of the target (a rename in its directory).
    /// Without it (an error before), the target is untouched.
    pub fn commit(self) -> CliResult {
        let name = self.name;
        let fail = |e: std::io::Error| -> Box<dyn std::error::Error> {
            if e.kind() == std::io::ErrorKind::BrokenPipe {
                e.into()
            } else {
                format!("{name}: {e}").into()
            }
        };
        match self.sink {
            Sink::Stdout(mut w) => w.flush().map_err(fail),
            Sink::Direct(mut w) => w.flush().map_err(fail),
            Sink::Temporary {
                file,
                target,
                permissions,
            } => {
                let tmp = file.into_inner().map_err(|e| fail(e.into_error()))?;
                // on the disk before the rename: a crash leaves the old file or the new one
                tmp.as_file().sync_all().map_err(fail)?;
                if let Some(p) = permissions {
                    std::fs::set_permissions(tmp.path(), p).map_err(fail)?;
                }
                tmp.persist(&target).map_err(|e| fail(e.error))?;
                Ok(())
            }
        }
    }
}

/// Commit several outputs of one command, in order (after all of them were written).
pub fn commit_all(outputs: Vec<Output>) -> CliResult {
    for o in outputs {
        o.commit()?;
    }
    Ok(())
}

/// Write `text` to `path` (standard output for `None` or `-`), all or nothing.
pub fn write_text(path: Option<&Path>, text: &str) -> CliResult {
    let mut o = Output::create(path)?;
    o.write_all(text.as_bytes())?;
    o.commit()
}

/// What identifies a file: its canonical path (symbolic links and `..` resolved; for a file
/// that does not exist yet, its directory's) and, when it exists, its device and inode (hard
/// links).
fn identity(p: &Path) -> (PathBuf, Option<(u64, u64)>) {
    let path = std::fs::canonicalize(p).unwrap_or_else(|_| {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let dir = std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf());
        match p.file_name() {
            Some(f) => dir.join(f),
            None => dir,
        }
    });
    #[cfg(unix)]
    let inode = {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(p).ok().map(|m| (m.dev(), m.ino()))
    };
    #[cfg(not(unix))]
    let inode = None;
    (path, inode)
}

/// Refuse two outputs of one command that are the same file (`--output x.csv --plot x.csv`,
/// or `./x.csv` and a link to it), or both standard output: the second would overwrite the
/// first. `outputs` pairs each option's name (`--output`) with its file, if given.
pub fn check_distinct(outputs: &[(&str, Option<&Path>)]) -> CliResult {
    let given: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|(o, p)| p.map(|p| (*o, p)))
        .collect();
    for (i, (oa, a)) in given.iter().enumerate() {
        for (ob, b) in &given[..i] {
            let same = match (robodyn::io::is_stdio(a), robodyn::io::is_stdio(b)) {
                (true, true) => true,
                (false, false) => {
                    let (ia, ib) = (identity(a), identity(b));
                    ia.0 == ib.0 || ia.1.is_some() && ia.1 == ib.1
                }
                _ => false,
            };
            if same {
                return Err(format!(
                    "{ob} {} and {oa} {} are the same file: each output needs its own file \
                     (nothing was written)",
                    b.display(),
                    a.display()
                )
                .into());
            }
        }
    }
    Ok(())
}

/// Output format of tables.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TableFormat {
    /// A header line of column names, then one row per line.
    #[default]
    Csv,
    /// A list of objects, one per row, keyed by column name.
    Json,
}

/// A table written row by row (CSV, or a JSON list of objects) into an [`Output`]: rows go out
/// as they are computed, so a table of millions of rows needs no memory beyond one row. Every
/// value must be finite ([`TableWriter::row`]).
pub struct TableWriter {
    out: Output,
    format: TableFormat,
    headers: Vec<String>,
    rows: usize,
}

impl TableWriter {
    /// Start a table (its CSV header goes out with the first row, or at the end: a command that
    /// fails before its first row writes nothing, not even to standard output).
    pub fn new(out: Output, format: TableFormat, headers: Vec<String>) -> CliResult<Self> {
        Ok(TableWriter {
            out,
            format,
            headers,
            rows: 0,
        })
    }

    /// The CSV header, before the first row.
    fn header(&mut self) -> CliResult {
        if self.format == TableFormat::Csv && self.rows == 0 {
            let line = self.headers.join(",");
            writeln!(self.out.writer(), "{line}").map_err(|e| self.out.io(e))?;
        }
        Ok(())
    }

    /// Write one row (`row` is its 1-based number in messages, none for a single state), with extra JSON fields (a
    /// closed chain's conditioning; CSV leaves them out). A value that is not finite is an error
    /// naming the row and the column: the model's arithmetic overflowed.
    pub fn row(
        &mut self,
        row: Option<usize>,
        values: &[f64],
        json_extra: Option<&serde_json::Map<String, serde_json::Value>>,
    ) -> CliResult {
        if let Some(c) = values.iter().position(|x| !x.is_finite()) {
            return Err(self.not_finite(row, c, values[c]));
        }
        self.header()?;
        let out = self.out.writer();
        let r = match self.format {
            TableFormat::Csv => csv_row(out, values),
            TableFormat::Json => {
                let mut o: serde_json::Map<String, serde_json::Value> = self
                    .headers
                    .iter()
                    .zip(values)
                    .map(|(h, x)| (h.clone(), serde_json::json!(x)))
                    .collect();
                if let Some(e) = json_extra {
                    o.extend(e.clone());
                }
                json_element(out, self.rows == 0, &o)
            }
        };
        r.map_err(|e| self.out.io(e))?;
        self.rows += 1;
        Ok(())
    }

    fn not_finite(&self, row: Option<usize>, c: usize, x: f64) -> Box<dyn std::error::Error> {
        let column = self.headers.get(c).map_or("a value", String::as_str);
        let written = if self.out.is_stdout() && self.rows > 0 {
            "the rows before it were written to standard output"
        } else {
            "nothing was written"
        };
        let row = row.map_or_else(String::new, |r| format!("row {r}: "));
        format!(
            "{row}{column} = {x}: the result is not a finite number (an input, a symbol \
             value or the gravity is too large for the model's arithmetic); {written}"
        )
        .into()
    }

    /// End the table (the JSON list's end), flush and commit the output.
    pub fn finish(mut self) -> CliResult {
        self.header()?;
        if self.format == TableFormat::Json {
            let end: &[u8] = if self.rows == 0 { b"[]\n" } else { b"\n]\n" };
            let out = self.out.writer();
            out.write_all(end).map_err(|e| self.out.io(e))?;
        }
        self.out.commit()
    }
}

/// One CSV row, each number written in place (no string per number or per line).
fn csv_row(out: &mut dyn Write, values: &[f64]) -> std::io::Result<()> {
    for (k, &x) in values.iter().enumerate() {
        if k > 0 {
            out.write_all(b",")?;
        }
        write!(out, "{}", Number(x))?;
    }
    out.write_all(b"\n")
}

/// One object of a pretty-printed JSON list, as `serde_json::to_writer_pretty` writes a list
/// (two spaces of indentation per level): `[` before the first.
fn json_element(
    out: &mut dyn Write,
    first: bool,
    o: &serde_json::Map<String, serde_json::Value>,
) -> std::io::Result<()> {
    out.write_all(if first { b"[\n" } else { b",\n" })?;
    let text = serde_json::to_string_pretty(o)?;
    for (k, line) in text.lines().enumerate() {
        if k > 0 {
            out.write_all(b"\n")?;
        }
        out.write_all(b"  ")?;
        out.write_all(line.as_bytes())?;
    }
    Ok(())
}

/// Write whole rows of named columns as a table (see [`TableWriter`]).
pub fn write_table(
    path: Option<&Path>,
    format: TableFormat,
    headers: &[String],
    rows: &[Vec<f64>],
) -> CliResult {
    let mut w = TableWriter::new(Output::create(path)?, format, headers.to_vec())?;
    for (k, r) in rows.iter().enumerate() {
        w.row((rows.len() > 1).then_some(k + 1), r, None)?;
    }
    w.finish()
}

/// A result that is not a finite number is an error, never written (a velocity of 1e200 or a
/// gravity of 1e308 overflows the model): `what` names the values.
pub fn check_finite(what: &str, values: &[f64]) -> CliResult {
    match values.iter().find(|x| !x.is_finite()) {
        Some(x) => Err(format!(
            "{what} = {x}: the result is not a finite number (an input, a symbol value or the \
             gravity is too large for the model's arithmetic); nothing was written"
        )
        .into()),
        None => Ok(()),
    }
}

/// Save a robot description in the format of the file's extension, all or nothing.
pub fn save_robot(desc: &robodyn::model::RobotDescription, path: &Path) -> CliResult {
    let format = robodyn::io::Format::from_path(path)?;
    write_text(Some(path), &robodyn::io::description_text(desc, format)?)
}
