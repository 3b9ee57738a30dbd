//! Measured logs: joint positions and torques (or motor currents) of the actuated joints
//! against time, read as a stream (a CSV file is read row by row, never held whole).
//!
//! Columns (header row, `#` comments allowed): `t`; for each actuated joint j, `q<j>` and
//! `tau<j>` (or `i<j>`, a motor current, with drive gains); optionally `qd<j>` and `qdd<j>`, then
//! used as given instead of filtered central differences. `<j>` is the frame number or, with an
//! underscore, the joint's name in the robot file: `q_joint_1`, `tau_joint_1`. The time must
//! increase with a constant step (checked on every row).

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

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

/// A log that can be read several times (identification makes one pass per estimate).
pub trait LogSource {
    /// Name for messages (file path).
    fn name(&self) -> String;
    /// Read the log from its start; samples come in order.
    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()>;
    /// What the effort columns hold.
    fn effort(&self) -> Effort {
        Effort::Torque
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

/// A CSV log on disk.
#[derive(Clone, Debug)]
pub struct CsvLog {
    /// The file.
    pub path: PathBuf,
    labels: JointLabels,
    cols: Columns,
}

#[derive(Clone, Debug)]
struct Columns {
    t: usize,
    q: Vec<usize>,
    y: Vec<usize>,
    effort: Effort,
    qd: Option<Vec<usize>>,
    qdd: Option<Vec<usize>>,
    width: usize,
}

fn find(headers: &[String], prefix: &str, number: usize, name: &str) -> Option<usize> {
    let a = format!("{prefix}{number}");
    let b = format!("{prefix}_{name}");
    headers.iter().position(|h| *h == a || *h == b)
}

impl CsvLog {
    /// Open a log and find its columns for `labels` (error naming the missing column).
    pub fn open(path: &Path, labels: &JointLabels) -> Result<CsvLog> {
        let file = path.display().to_string();
        let mut rdr = reader(path)?;
        let headers: Vec<String> = rdr
            .headers()
            .map_err(|e| io(&file, e))?
            .iter()
            .map(str::to_string)
            .collect();
        let t = headers
            .iter()
            .position(|h| h == "t")
            .ok_or_else(|| Error::Input(format!("{file}: no column `t` (time, s)")))?;
        let all = |prefix: &str| -> Option<Vec<usize>> {
            labels
                .numbers
                .iter()
                .zip(&labels.names)
                .map(|(&j, n)| find(&headers, prefix, j, n))
                .collect()
        };
        let missing = |prefix: &str| -> String {
            labels
                .numbers
                .iter()
                .zip(&labels.names)
                .filter(|(&j, n)| find(&headers, prefix, j, n).is_none())
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
        let (qd, qdd) = (all("qd"), all("qdd"));
        let (qd, qdd) = match (qd, qdd) {
            (Some(a), Some(b)) => (Some(a), Some(b)),
            (None, None) => (None, None),
            (Some(_), None) | (None, Some(_)) => {
                return Err(Error::Input(format!(
                    "{file}: give both qd<j> and qdd<j> for every actuated joint, or neither \
                     (then they are central differences of the filtered positions)"
                )))
            }
        };
        Ok(CsvLog {
            path: path.to_path_buf(),
            labels: labels.clone(),
            cols: Columns {
                t,
                q,
                y,
                effort,
                qd,
                qdd,
                width: headers.len(),
            },
        })
    }

    /// The joints whose columns are read.
    pub fn labels(&self) -> &JointLabels {
        &self.labels
    }
}

fn reader(path: &Path) -> Result<csv::Reader<std::fs::File>> {
    csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_path(path)
        .map_err(|e| io(&path.display().to_string(), e))
}

/// A read error of the log (a CSV error keeps its underlying I/O error when it has one).
fn io(file: &str, e: csv::Error) -> Error {
    if e.is_io_error() {
        if let csv::ErrorKind::Io(source) = e.into_kind() {
            return Error::io(file, source);
        }
        unreachable!("is_io_error");
    }
    Error::Input(format!("{file}: {e}"))
}

impl LogSource for CsvLog {
    fn name(&self) -> String {
        self.path.display().to_string()
    }

    fn effort(&self) -> Effort {
        self.cols.effort
    }

    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        let file = self.name();
        let mut rdr = reader(&self.path)?;
        let c = &self.cols;
        let mut rec = csv::StringRecord::new();
        let mut row = 0usize;
        loop {
            match rdr.read_record(&mut rec) {
                Ok(false) => break,
                Ok(true) => {}
                Err(e) => return Err(io(&file, e)),
            }
            row += 1;
            let line = rec.position().map_or(row as u64 + 1, |p| p.line());
            if rec.len() != c.width {
                return Err(Error::Input(format!(
                    "{file}:{line}: {} fields, the header has {}",
                    rec.len(),
                    c.width
                )));
            }
            let num = |k: usize| -> Result<f64> {
                let s = &rec[k];
                match s.parse::<f64>() {
                    Ok(x) if x.is_finite() => Ok(x),
                    _ => Err(Error::Input(format!(
                        "{file}:{line}: `{s}` is not a finite number"
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
}

/// Relative tolerance on the sample time: every step t_k - t_(k-1) must equal the first one to
/// this fraction (logs written with few digits round t).
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
    /// [`SAMPLE_TIME_TOLERANCE`]. Errors: [`Error::Input`] naming both times.
    pub fn check(&mut self, t: f64) -> Result<()> {
        if let Some(last) = self.last {
            let step = t - last;
            if step <= 0.0 {
                return Err(Error::Input(format!(
                    "t = {t} is not after the previous time {last}"
                )));
            }
            match self.dt {
                None => self.dt = Some(step),
                Some(dt) => {
                    if (step - dt).abs() > SAMPLE_TIME_TOLERANCE * dt {
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

/// First read: size, time step, columns present. Errors carry the file and line.
pub fn summarize(log: &dyn LogSource, n: usize) -> Result<LogSummary> {
    let mut tc = TimeCheck::default();
    let mut has_derivatives = None;
    log.read(&mut |s| {
        if s.q.len() != n || s.y.len() != n {
            return Err(Error::Input(format!(
                "a sample has {} positions and {} torques, {n} expected",
                s.q.len(),
                s.y.len()
            )));
        }
        let d = s.qd.is_some() && s.qdd.is_some();
        if *has_derivatives.get_or_insert(d) != d {
            return Err(Error::Input(
                "qd/qdd given on some samples only".to_string(),
            ));
        }
        tc.check(s.t)
    })?;
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
        has_derivatives: has_derivatives.unwrap_or(false),
    })
}
