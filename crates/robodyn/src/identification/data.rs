//! Measured logs: joint positions and torques (or motor currents) of the actuated joints
//! against time, read as a stream (a CSV file is read row by row, never held whole).
//!
//! Columns (header row, `#` comments allowed): `t`; for each actuated joint j, `q<j>` and
//! `tau<j>` (or `i<j>`, a motor current, with drive gains); optionally `qd<j>` and `qdd<j>`, then
//! used as given instead of filtered central differences. `<j>` is the frame number or, with an
//! underscore, the joint's name in the robot file: `q_joint_1`, `tau_joint_1`. The time must
//! increase with a constant step (checked on every row).

use crate::error::{Error, Result};
use std::io::{BufReader, BufWriter, Read, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// One sample of a log for the N actuated joints.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RawSample {
    /// Time (s).
    pub t: f64,
    /// Positions of the N actuated joints (rad or m).
    pub q: Vec<f64>,
    /// Joint torques (or motor currents when the log has currents).
    pub y: Vec<f64>,
    /// Velocities (rad/s or m/s), when the log gives them.
    pub qd: Option<Vec<f64>>,
    /// Accelerations (rad/s² or m/s²), when the log gives them.
    pub qdd: Option<Vec<f64>>,
}

/// What the torque columns hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effort {
    /// `tau<j>`: joint torques (N m) or forces (N).
    Torque,
    /// `i<j>`: motor currents (A), converted with drive gains.
    Current,
}

/// Facts about a log found by a first read (columns, size, sample time).
#[derive(Clone, Debug, PartialEq)]
pub struct LogSummary {
    /// The log's name (file path).
    pub source: String,
    /// Number of samples.
    pub samples: usize,
    /// Time of the first sample (s).
    pub t0: f64,
    /// Sample time (s).
    pub dt: f64,
    /// What the effort columns hold.
    pub effort: Effort,
    /// Whether qd and qdd are given.
    pub has_derivatives: bool,
}

impl LogSummary {
    /// Duration (samples - 1) dt (s).
    pub fn duration(&self) -> f64 {
        self.dt * (self.samples.saturating_sub(1)) as f64
    }
    /// Sample rate 1 / dt (Hz).
    pub fn sample_rate(&self) -> f64 {
        1.0 / self.dt
    }
}

/// A log: samples in time order. Identification makes several passes over its samples; a
/// source that is not [`LogSource::repeatable`] is read once and recorded ([`record`]).
pub trait LogSource {
    /// Name for messages (file path).
    fn name(&self) -> String;
    /// Read the log from its start; samples come in order.
    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()>;
    /// What the effort columns hold.
    fn effort(&self) -> Effort {
        Effort::Torque
    }
    /// Whether every read gives the same samples (a log in memory, a recording). A file may
    /// change between two reads (a log still being written) and a stream can be read once:
    /// false by default.
    fn repeatable(&self) -> bool {
        false
    }
}

/// Labels of the joints whose columns are read: frame numbers and names.
#[derive(Clone, Debug)]
pub struct JointLabels {
    /// Frame numbers j of the columns `q<j>`.
    pub numbers: Vec<usize>,
    /// Joint names of the columns `q_<name>`.
    pub names: Vec<String>,
}

/// Longest line of a log (bytes): a longer one is refused with its line number before it is
/// held in memory (a file of zeros, a binary file, a corrupted log).
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// Largest magnitude of a number in a log or in the observation matrix: the least squares sum
/// squares of rows, and 1e150^2 = 1e300 leaves room for 1e8 rows below the largest double.
pub const MAX_MAGNITUDE: f64 = 1e150;

/// A CSV log: a file, read again at each read, or a stream (standard input), read once.
pub struct CsvLog {
    name: String,
    labels: JointLabels,
    headers: Vec<String>,
    cols: Columns,
    source: Source,
}

type CsvReader = csv::Reader<LineLimit<Box<dyn Read + Send>>>;

enum Source {
    File(PathBuf),
    Once(Mutex<Option<CsvReader>>),
}

impl std::fmt::Debug for CsvLog {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CsvLog")
            .field("name", &self.name)
            .field("headers", &self.headers)
            .finish_non_exhaustive()
    }
}

#[derive(Clone, Debug)]
struct Columns {
    t: usize,
    q: Vec<usize>,
    y: Vec<usize>,
    effort: Effort,
    qd: Option<Vec<usize>>,
    qdd: Option<Vec<usize>>,
}

fn find(headers: &[String], prefix: &str, number: usize, name: &str) -> Option<usize> {
    let a = format!("{prefix}{number}");
    let b = format!("{prefix}_{name}");
    headers.iter().position(|h| *h == a || *h == b)
}

impl Columns {
    /// The columns of `labels`' joints in `headers` (an error naming the missing ones, or the
    /// header's repeated or empty name).
    fn find(headers: &[String], labels: &JointLabels, file: &str) -> Result<Columns> {
        crate::io::table::check_header(headers)
            .map_err(|reason| Error::Input(format!("{file}:1: {reason}")))?;
        let t = headers
            .iter()
            .position(|h| h == "t")
            .ok_or_else(|| Error::Input(format!("{file}: no column `t` (time, s)")))?;
        let all = |prefix: &str| -> Option<Vec<usize>> {
            labels
                .numbers
                .iter()
                .zip(&labels.names)
                .map(|(&j, n)| find(headers, prefix, j, n))
                .collect()
        };
        let missing = |prefix: &str| -> String {
            labels
                .numbers
                .iter()
                .zip(&labels.names)
                .filter(|(&j, n)| find(headers, prefix, j, n).is_none())
                .map(|(j, n)| format!("`{prefix}{j}` (or `{prefix}_{n}`)"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let q = all("q").ok_or_else(|| {
            Error::Input(format!(
                "{file}: missing position column(s) {} of the actuated joints {:?}",
                missing("q"),
                labels.numbers
            ))
        })?;
        let (y, effort) = match (all("tau"), all("i")) {
            (Some(y), _) => (y, Effort::Torque),
            (None, Some(y)) => (y, Effort::Current),
            (None, None) => {
                return Err(Error::Input(format!(
                    "{file}: missing torque column(s) {} (or motor currents `i<j>` with drive \
                     gains) of the actuated joints {:?}",
                    missing("tau"),
                    labels.numbers
                )))
            }
        };
        let (qd, qdd) = match (all("qd"), all("qdd")) {
            (Some(a), Some(b)) => (Some(a), Some(b)),
            (None, None) => (None, None),
            (Some(_), None) | (None, Some(_)) => {
                return Err(Error::Input(format!(
                    "{file}: give both qd<j> and qdd<j> for every actuated joint, or neither \
                     (then they are central differences of the filtered positions)"
                )))
            }
        };
        Ok(Columns {
            t,
            q,
            y,
            effort,
            qd,
            qdd,
        })
    }
}

impl CsvLog {
    /// Open a log and find its columns for `labels` (error naming the missing column, or a
    /// repeated one). `-` is standard input, read once.
    pub fn open(path: &Path, labels: &JointLabels) -> Result<CsvLog> {
        if crate::io::is_stdio(path) {
            return CsvLog::from_reader("<stdin>", std::io::stdin(), labels);
        }
        let name = path.display().to_string();
        let mut rdr = csv_reader(open_file(path)?);
        let headers = read_headers(&mut rdr, &name)?;
        Ok(CsvLog {
            cols: Columns::find(&headers, labels, &name)?,
            name,
            labels: labels.clone(),
            headers,
            source: Source::File(path.to_path_buf()),
        })
    }

    /// A log streamed from `reader` (a pipe, standard input, bytes in memory), named `name` in
    /// messages. It can be read once: [`super::identify`] records it as it reads it.
    pub fn from_reader(
        name: &str,
        reader: impl Read + Send + 'static,
        labels: &JointLabels,
    ) -> Result<CsvLog> {
        let mut rdr = csv_reader(Box::new(reader));
        let headers = read_headers(&mut rdr, name)?;
        Ok(CsvLog {
            cols: Columns::find(&headers, labels, name)?,
            name: name.to_string(),
            labels: labels.clone(),
            headers,
            source: Source::Once(Mutex::new(Some(rdr))),
        })
    }

    /// The joints whose columns are read.
    pub fn labels(&self) -> &JointLabels {
        &self.labels
    }

    /// The rows after the header, each checked (field count, finite numbers of bounded
    /// magnitude) and passed to `visit`; an input error of `visit` gets the file and line.
    fn read_rows(
        &self,
        rdr: &mut CsvReader,
        visit: &mut dyn FnMut(RawSample) -> Result<()>,
    ) -> Result<()> {
        let file = &self.name;
        let c = &self.cols;
        let mut rec = csv::StringRecord::new();
        let mut row = 0usize;
        while rdr.read_record(&mut rec).map_err(|e| io(file, e))? {
            row += 1;
            let line = rec.position().map_or(row as u64 + 1, |p| p.line());
            if rec.len() != self.headers.len() {
                return Err(Error::Input(format!(
                    "{file}:{line}: {} fields, the header has {}",
                    rec.len(),
                    self.headers.len()
                )));
            }
            let num = |k: usize| -> Result<f64> {
                let s = &rec[k];
                let column = &self.headers[k];
                match s.parse::<f64>() {
                    Ok(x) if x.is_finite() && x.abs() <= MAX_MAGNITUDE => Ok(x),
                    Ok(x) if x.is_finite() => Err(Error::Input(format!(
                        "{file}:{line}: column `{column}`: {s} is too large (magnitude above \
                         {MAX_MAGNITUDE:e}: its square overflows the least squares)"
                    ))),
                    _ => Err(Error::Input(format!(
                        "{file}:{line}: column `{column}`: `{s}` is not a finite number"
                    ))),
                }
            };
            let pick = |idx: &[usize]| idx.iter().map(|&k| num(k)).collect::<Result<Vec<f64>>>();
            let s = RawSample {
                t: num(c.t)?,
                q: pick(&c.q)?,
                y: pick(&c.y)?,
                qd: c.qd.as_deref().map(pick).transpose()?,
                qdd: c.qdd.as_deref().map(pick).transpose()?,
            };
            visit(s).map_err(|e| match e {
                Error::Input(m) => Error::Input(format!("{file}:{line}: {m}")),
                other => other,
            })?;
        }
        Ok(())
    }
}

fn open_file(path: &Path) -> Result<Box<dyn Read + Send>> {
    let f = std::fs::File::open(path).map_err(|e| Error::io(path.display().to_string(), e))?;
    Ok(Box::new(f))
}

/// The CSV reader of logs: fields trimmed, `#` comment lines, no quoting (a log is numbers:
/// one record per line, so that [`MAX_LINE_BYTES`] bounds a record), the field count checked
/// by [`CsvLog`] with the line.
fn csv_reader(source: Box<dyn Read + Send>) -> CsvReader {
    csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .quoting(false)
        .flexible(true)
        .from_reader(LineLimit::new(source, MAX_LINE_BYTES))
}

fn read_headers(rdr: &mut CsvReader, file: &str) -> Result<Vec<String>> {
    Ok(rdr
        .headers()
        .map_err(|e| io(file, e))?
        .iter()
        .map(str::to_string)
        .collect())
}

/// A line longer than the limit (the error inside the I/O error of [`LineLimit`]).
#[derive(Debug)]
struct LineTooLong {
    line: u64,
    limit: usize,
}

impl std::fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a line longer than {} bytes: not a log of numbers (a binary or corrupted file?)",
            self.limit
        )
    }
}

impl std::error::Error for LineTooLong {}

/// A reader that fails (with [`LineTooLong`]) as soon as a line exceeds `limit` bytes, so that
/// no record grows without bound. A line ends at `\n` (counted) or `\r` (old Mac files).
struct LineLimit<R> {
    inner: R,
    limit: usize,
    current: usize,
    line: u64,
}

impl<R> LineLimit<R> {
    fn new(inner: R, limit: usize) -> Self {
        LineLimit {
            inner,
            limit,
            current: 0,
            line: 1,
        }
    }
}

impl<R: Read> Read for LineLimit<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' || b == b'\r' {
                self.line += u64::from(b == b'\n');
                self.current = 0;
            } else {
                self.current += 1;
                if self.current > self.limit {
                    return Err(std::io::Error::new(
                        std::io::ErrorKind::InvalidData,
                        LineTooLong {
                            line: self.line,
                            limit: self.limit,
                        },
                    ));
                }
            }
        }
        Ok(n)
    }
}

/// A read error of the log (a CSV error keeps its underlying I/O error when it has one; a line
/// too long is an input error with its line).
fn io(file: &str, e: csv::Error) -> Error {
    if !e.is_io_error() {
        return Error::Input(format!("{file}: {e}"));
    }
    let csv::ErrorKind::Io(source) = e.into_kind() else {
        unreachable!("an I/O error")
    };
    match source
        .get_ref()
        .and_then(|inner| inner.downcast_ref::<LineTooLong>())
    {
        Some(long) => Error::Input(format!("{file}:{}: {long}", long.line)),
        None => Error::io(file, source),
    }
}

impl LogSource for CsvLog {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn effort(&self) -> Effort {
        self.cols.effort
    }

    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        match &self.source {
            Source::File(path) => {
                let mut rdr = csv_reader(open_file(path)?);
                if read_headers(&mut rdr, &self.name)? != self.headers {
                    return Err(Error::Input(format!(
                        "{}: the header changed since the file was opened",
                        self.name
                    )));
                }
                self.read_rows(&mut rdr, visit)
            }
            Source::Once(reader) => {
                let taken = reader.lock().unwrap_or_else(|e| e.into_inner()).take();
                let mut rdr = taken.ok_or_else(|| {
                    Error::Input(format!(
                        "{}: a stream is read once; it was read already",
                        self.name
                    ))
                })?;
                self.read_rows(&mut rdr, visit)
            }
        }
    }
}

/// A log held in memory (tests, logs made by simulation).
#[derive(Clone, Debug)]
pub struct MemoryLog {
    /// Name for messages.
    pub name: String,
    /// The samples, in time order.
    pub samples: Vec<RawSample>,
}

impl LogSource for MemoryLog {
    fn name(&self) -> String {
        self.name.clone()
    }
    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        for (k, s) in self.samples.iter().enumerate() {
            visit(s.clone()).map_err(|e| match e {
                Error::Input(m) => Error::Input(format!("{} sample {}: {m}", self.name, k + 1)),
                other => other,
            })?;
        }
        Ok(())
    }
    fn repeatable(&self) -> bool {
        true
    }
}

/// Relative tolerance on the sample time: every step t_k - t_(k-1) must equal the first one to
/// this fraction (logs written with few digits round t), beyond the resolution of the time
/// stamps themselves (see [`TimeCheck::check`]).
pub const SAMPLE_TIME_TOLERANCE: f64 = 1e-3;

/// Checks the time column while a log streams by: increasing with a constant step.
#[derive(Clone, Debug, Default)]
pub struct TimeCheck {
    t0: Option<f64>,
    last: Option<f64>,
    dt: Option<f64>,
    /// Samples checked so far.
    pub samples: usize,
}

impl TimeCheck {
    /// Check the next time `t` (s): after the previous one, by the first step to
    /// [`SAMPLE_TIME_TOLERANCE`] plus the resolution of the stamps (8 ulp of |t|: Unix time
    /// stamps, t ~ 1.7e9 s, are 2.4e-7 s apart, a tenth of a 5 kHz step). Errors:
    /// [`Error::Input`] naming both times.
    pub fn check(&mut self, t: f64) -> Result<()> {
        if let Some(last) = self.last {
            let step = t - last;
            if step <= 0.0 {
                return Err(Error::Input(format!(
                    "t = {t} is not after the previous time {last}"
                )));
            }
            let resolution = 8.0 * f64::EPSILON * t.abs().max(last.abs());
            match self.dt {
                None => self.dt = Some(step),
                Some(dt) => {
                    if (step - dt).abs() > SAMPLE_TIME_TOLERANCE * dt + 2.0 * resolution {
                        return Err(Error::Input(format!(
                            "time step {step} s at t = {t} differs from the first step {dt} s: \
                             the log must be sampled uniformly (resample it first)"
                        )));
                    }
                }
            }
        } else {
            self.t0 = Some(t);
        }
        self.last = Some(t);
        self.samples += 1;
        Ok(())
    }

    /// Mean step over the whole log (more digits than one step of a rounded log).
    pub fn dt(&self) -> Option<f64> {
        match (self.t0, self.last) {
            (Some(a), Some(b)) if self.samples > 1 => Some((b - a) / (self.samples - 1) as f64),
            _ => None,
        }
    }
}

/// The checks of every sample of a first read (sizes, numbers, time), giving the summary.
struct SampleCheck {
    n: usize,
    time: TimeCheck,
    has_derivatives: Option<bool>,
}

impl SampleCheck {
    fn new(n: usize) -> Self {
        SampleCheck {
            n,
            time: TimeCheck::default(),
            has_derivatives: None,
        }
    }

    fn check(&mut self, s: &RawSample) -> Result<()> {
        let n = self.n;
        if s.q.len() != n || s.y.len() != n {
            return Err(Error::Input(format!(
                "a sample has {} positions and {} torques, {n} expected",
                s.q.len(),
                s.y.len()
            )));
        }
        let d = s.qd.is_some() && s.qdd.is_some();
        if *self.has_derivatives.get_or_insert(d) != d {
            return Err(Error::Input(
                "qd/qdd given on some samples only".to_string(),
            ));
        }
        if d && (s.qd.as_ref().map_or(0, Vec::len) != n || s.qdd.as_ref().map_or(0, Vec::len) != n)
        {
            return Err(Error::Input(format!(
                "a sample has qd or qdd of a length other than {n}"
            )));
        }
        let groups = [
            ("t", std::slice::from_ref(&s.t)),
            ("q", s.q.as_slice()),
            ("y", s.y.as_slice()),
            ("qd", s.qd.as_deref().unwrap_or_default()),
            ("qdd", s.qdd.as_deref().unwrap_or_default()),
        ];
        for (what, v) in groups {
            if let Some((k, x)) = v
                .iter()
                .enumerate()
                .find(|(_, x)| !(x.is_finite() && x.abs() <= MAX_MAGNITUDE))
            {
                return Err(Error::Input(format!(
                    "{what}[{k}] = {x:e} is not a finite number of magnitude at most \
                     {MAX_MAGNITUDE:e}"
                )));
            }
        }
        self.time.check(s.t)
    }

    fn summary(self, log: &dyn LogSource) -> Result<LogSummary> {
        let tc = self.time;
        let dt = tc.dt().ok_or_else(|| {
            Error::Input(format!(
                "{}: {} sample(s): a log needs at least two",
                log.name(),
                tc.samples
            ))
        })?;
        Ok(LogSummary {
            source: log.name(),
            samples: tc.samples,
            t0: tc.t0.unwrap_or(0.0),
            dt,
            effort: log.effort(),
            has_derivatives: self.has_derivatives.unwrap_or(false),
        })
    }
}

/// First read: size, time step, columns present. Errors carry the file and line.
pub fn summarize(log: &dyn LogSource, n: usize) -> Result<LogSummary> {
    let mut check = SampleCheck::new(n);
    log.read(&mut |s| check.check(&s))?;
    check.summary(log)
}

/// A log read once and recorded: its samples (time, positions, torques, qd and qdd when given)
/// as binary numbers in an anonymous temporary file, deleted when the recording is dropped.
/// Every pass of an identification reads this recording, so they all see the same samples
/// whatever happens to the source (a file still being written, a pipe), and memory does not
/// grow with the log's length.
#[derive(Debug)]
pub struct RecordedLog {
    name: String,
    effort: Effort,
    n: usize,
    derivatives: bool,
    samples: usize,
    file: Mutex<std::fs::File>,
}

/// Read `log` once: the checks and summary of [`summarize`], and the recording of its samples.
pub fn record(log: &dyn LogSource, n: usize) -> Result<(LogSummary, RecordedLog)> {
    let temp = |e: std::io::Error| Error::io("a temporary file for the log's samples", e);
    let mut out = BufWriter::with_capacity(1 << 16, tempfile::tempfile().map_err(temp)?);
    let mut check = SampleCheck::new(n);
    log.read(&mut |s| {
        check.check(&s)?;
        let values = std::iter::once(&s.t)
            .chain(&s.q)
            .chain(&s.y)
            .chain(s.qd.iter().flatten())
            .chain(s.qdd.iter().flatten());
        for v in values {
            out.write_all(&v.to_le_bytes()).map_err(temp)?;
        }
        Ok(())
    })?;
    let file = out.into_inner().map_err(|e| temp(e.into_error()))?;
    let summary = check.summary(log)?;
    let recording = RecordedLog {
        name: log.name(),
        effort: log.effort(),
        n,
        derivatives: summary.has_derivatives,
        samples: summary.samples,
        file: Mutex::new(file),
    };
    Ok((summary, recording))
}

impl RecordedLog {
    /// Samples recorded.
    pub fn samples(&self) -> usize {
        self.samples
    }
}

impl LogSource for RecordedLog {
    fn name(&self) -> String {
        self.name.clone()
    }

    fn effort(&self) -> Effort {
        self.effort
    }

    fn repeatable(&self) -> bool {
        true
    }

    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        let n = self.n;
        let width = 1 + if self.derivatives { 4 * n } else { 2 * n };
        let err = |e| Error::io(format!("the recording of {}", self.name), e);
        let mut file = self.file.lock().unwrap_or_else(|e| e.into_inner());
        file.rewind().map_err(err)?;
        let mut rdr = BufReader::with_capacity(1 << 16, &mut *file);
        let mut bytes = vec![0u8; 8 * width];
        let mut v = vec![0.0; width];
        for k in 0..self.samples {
            rdr.read_exact(&mut bytes).map_err(err)?;
            for (x, b) in v.iter_mut().zip(bytes.chunks_exact(8)) {
                *x = f64::from_le_bytes(b.try_into().expect("8 bytes"));
            }
            let part = |i: usize| v[1 + i * n..1 + (i + 1) * n].to_vec();
            let s = RawSample {
                t: v[0],
                q: part(0),
                y: part(1),
                qd: self.derivatives.then(|| part(2)),
                qdd: self.derivatives.then(|| part(3)),
            };
            visit(s).map_err(|e| match e {
                Error::Input(m) => Error::Input(format!("{} sample {}: {m}", self.name, k + 1)),
                other => other,
            })?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(bytes: Vec<u8>) -> std::io::Result<usize> {
        let mut r = LineLimit::new(std::io::Cursor::new(bytes), 1000);
        let mut out = Vec::new();
        r.read_to_end(&mut out)?;
        Ok(out.len())
    }

    /// Lines end at `\n` or `\r` (CRLF and old Mac files); a line beyond the limit fails with its
    /// number, counted in `\n`.
    #[test]
    fn line_limit() {
        let short = "1,2,3\r\n".repeat(10_000).into_bytes();
        assert_eq!(read_all(short.clone()).unwrap(), short.len());
        let mac = "1,2,3\r".repeat(10_000).into_bytes();
        assert_eq!(read_all(mac.clone()).unwrap(), mac.len());
        let mut long = b"t,q1\n0,0\n".to_vec();
        long.extend(std::iter::repeat_n(b'7', 1001));
        let e = read_all(long).unwrap_err();
        let inner = e.get_ref().unwrap().downcast_ref::<LineTooLong>().unwrap();
        assert_eq!((inner.line, inner.limit), (3, 1000));
        let mut exact = b"t,q1\n".to_vec();
        exact.extend(std::iter::repeat_n(b'7', 1000));
        assert!(read_all(exact).is_ok());
    }
}
