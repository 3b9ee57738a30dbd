//! Errors are values: every error says where (file, line, frame, link, loop) and why.

use std::fmt;
use std::sync::Arc;

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
    /// File name.
    pub file: Option<String>,
    /// 1-based line.
    pub line: Option<usize>,
    /// 1-based column.
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

/// Where a matrix was found singular ([`Error::Singular`]): values, not text.
#[derive(Clone, Debug, PartialEq)]
pub enum Configuration {
    /// At the pivot of joint `joint` (frame number) of the tree's factorization (L'DL of A or
    /// the articulated-body inertias).
    Pivot {
        /// The joint (frame number).
        joint: usize,
        /// The pivot found.
        pivot: f64,
    },
    /// At the joint values `values` of the vector `name` (`q_tr`: the variables of a closed
    /// chain's equivalent tree, joint j at index j-1, fixed frames 0).
    Joints {
        /// The vector's name.
        name: &'static str,
        /// Its values (rad, m).
        values: Vec<f64>,
    },
}

impl fmt::Display for Configuration {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Configuration::Pivot { joint, pivot } => write!(f, "joint {joint} (pivot {pivot:.3e})"),
            Configuration::Joints { name, values } => write!(f, "{name} = {}", fmt_values(values)),
        }
    }
}

/// Joint values in messages: `[0.1, -0.25, 1.5]` (6 significant digits).
pub(crate) fn fmt_values(v: &[f64]) -> String {
    crate::report::number::vector(v, 6)
}

/// The error type of the library. Callers match on the variant; the message says where and why
/// in words (no library message names a command-line flag).
#[derive(Debug, Clone, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A robot description is invalid (bad structure, unknown symbol, NaN...).
    #[error("{}{item}: {reason}", fmt_loc(.location))]
    Invalid {
        /// Where in the source file, when known.
        location: Location,
        /// The frame, link, symbol... concerned.
        item: Item,
        /// Why.
        reason: String,
    },
    /// A file could not be parsed.
    #[error("{}{reason}", fmt_loc(.location))]
    Parse {
        /// File, line and column.
        location: Location,
        /// Why.
        reason: String,
    },
    /// A physically inconsistent parameter (negative mass, rotor inertia or friction).
    #[error("{}{item}: {reason}", fmt_loc(.location))]
    Physical {
        /// Where in the source file, when known.
        location: Box<Location>,
        /// The link parameter concerned.
        item: Item,
        /// Why.
        reason: String,
    },
    /// A vector or matrix has the wrong size for the model (or a `Data` was made for another
    /// model).
    #[error("{what} has {got} entries, {expected} expected ({context})")]
    Dimension {
        /// The argument (`q`, `qd`, `tau`, `A`, `data`...).
        what: String,
        /// The size the model needs.
        expected: usize,
        /// The size given.
        got: usize,
        /// What the entries are (e.g. "movable joints [1, 2, 4]").
        context: String,
    },
    /// An input is NaN or infinite.
    #[error("{what}[{index}] = {value} is not a finite number")]
    NotFinite {
        /// The argument.
        what: String,
        /// 0-based index of the first non-finite entry.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A matrix is singular (or so ill-conditioned that a solve is meaningless): its reciprocal
    /// condition number `rcond` is below `limit`.
    #[error("{what} is singular at {at}: reciprocal condition number {rcond:.3e} (limit {limit:.1e}){}", fmt_hint(.hint))]
    Singular {
        /// Which matrix (`Wp`, `A_cl`, `A`), with what it is the derivative of.
        what: String,
        /// 1 / (||M||_1 ||M^-1||_1) (0 when the factorization broke down).
        rcond: f64,
        /// The hard limit it fell below.
        limit: f64,
        /// The configuration: a joint's pivot or joint values.
        at: Configuration,
        /// What it means for the mechanism.
        hint: String,
    },
    /// The loop-closure equations have no solution near the guess.
    #[error("{loop_label} does not close at q_a = {} (actuated joints), after {iterations} damped Newton iterations from the guess q_p = {} (passive joints): closure residual {residual:.3e} (tolerance {tolerance:.1e}); the configuration is unreachable or the guess is too far", fmt_values(.at), fmt_values(.guess))]
    LoopNotClosed {
        /// "loop 1 (cut joint 5 between links 2 and 4)".
        loop_label: String,
        /// Largest closure residual reached (m or rad).
        residual: f64,
        /// The tolerance it had to meet.
        tolerance: f64,
        /// The actuated values q_a (rad, m).
        at: Vec<f64>,
        /// The passive values the damped Newton started from (rad, m).
        guess: Vec<f64>,
        /// Damped Newton iterations made.
        iterations: usize,
    },
    /// A configuration cannot be reached on the branch tracker's assembly branch.
    #[error("q_a = {} cannot be reached on the assembly branch: {reason}", fmt_values(.at))]
    BranchLost {
        /// The target actuated values q_a (rad, m).
        at: Vec<f64>,
        /// Why (a singularity or fold on the path, no convergence).
        reason: String,
    },
    /// A closed-chain configuration the branch tracker cannot reach within its step budget
    /// (`ClosedChain::step_budget`): the move is too long to follow and cannot be shortened.
    #[error("q_a = {} cannot be reached on the assembly branch within the continuation's budget of {budget} steps: {reason}", fmt_values(.at))]
    ContinuationBudget {
        /// The target actuated values q_a (rad, m).
        at: Vec<f64>,
        /// The step budget.
        budget: usize,
        /// Why the move could not be followed or shortened.
        reason: String,
    },
    /// A closed robot without an assembly whose default start (q = 0) is singular.
    #[error("{robot}: the loops close at q = 0 but Wp is singular there (reciprocal condition number {rcond:.1e}): the start of loop closure does not define an assembly branch; give the joint values of an assembled, regular configuration (the robot's `assembly`, or an explicit start q_a, q_p)")]
    SingularStart {
        /// Robot name.
        robot: String,
        /// Reciprocal condition number of Wp at q = 0.
        rcond: f64,
    },
    /// An error in row `row` (1-based) of a table of states.
    #[error("row {row}: {source}")]
    Row {
        /// 1-based row number.
        row: usize,
        /// The error of that row.
        source: Box<Error>,
    },
    /// Input/output error on a file.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's error.
        source: Arc<std::io::Error>,
    },
    /// An option of a computation does not fit the robot or the data: `option` names the field
    /// of the options struct (`"identification::Options::estimator"`, ...), so that a front end
    /// can say which of its own settings to change; the message says why in library terms.
    #[error("{reason}")]
    Setting {
        /// The options field, as `module::Struct::field` (stable: front ends match on it).
        option: &'static str,
        /// Why, and what to choose instead.
        reason: String,
    },
    /// Other input data that do not fit the robot (message only).
    #[error("{0}")]
    Input(String),
    /// Other numerical failures (no convergence...), with what was involved (message only).
    #[error("{0}")]
    Numerical(String),
}

fn fmt_hint(h: &str) -> String {
    if h.is_empty() {
        String::new()
    } else {
        format!("; {h}")
    }
}

/// The rule for a result computed from finite inputs: every entry finite. Finite inputs can
/// still overflow (a velocity of 1e200 squared, a gravity of 1e308 times a mass), and a model
/// never returns such a number: the first non-finite entry `what[k]` is an
/// [`Error::Numerical`] saying so. The checked functions (`*_into`) apply it to their outputs.
pub fn check_finite_result(what: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(k) => Err(overflow(&format!("{what}[{k}]"), values[k])),
        None => Ok(()),
    }
}

/// [`check_finite_result`] for a matrix: the entry is named `what[row, column]` (0-based).
pub fn check_finite_matrix(what: &str, m: &nalgebra::DMatrix<f64>) -> Result<()> {
    if all_finite(m.as_slice()) {
        return Ok(());
    }
    first_non_finite(what, m)
}

/// No entry is infinite or NaN, by a branch-free sum over 16 lanes (it vectorizes, and the
/// lanes' independent chains hide the additions' latency): the sum of finite numbers is finite
/// or overflows (then the entries are searched one by one), and an infinite or NaN entry makes
/// it infinite or NaN.
fn all_finite(x: &[f64]) -> bool {
    let chunks = x.chunks_exact(16);
    let rest: f64 = chunks.remainder().iter().sum();
    let lanes = chunks.fold([0.0; 16], |mut acc, c| {
        acc.iter_mut().zip(c).for_each(|(a, x)| *a += x);
        acc
    });
    if rest.is_finite() && lanes.iter().all(|p| p.is_finite()) {
        return true;
    }
    x.iter().all(|v| v.is_finite())
}

/// The error of the first non-finite entry of `m`, named `what[row, column]`; Ok when none.
fn first_non_finite(what: &str, m: &nalgebra::DMatrix<f64>) -> Result<()> {
    match m.as_slice().iter().position(|x| !x.is_finite()) {
        Some(k) => {
            let (r, c) = (k % m.nrows(), k / m.nrows());
            Err(overflow(&format!("{what}[{r}, {c}]"), m[(r, c)]))
        }
        None => Ok(()),
    }
}

fn overflow(entry: &str, value: f64) -> Error {
    Error::Numerical(format!(
        "{entry} = {value} is not a finite number: the result overflows the floating-point \
         range for these finite inputs (velocities, accelerations, parameters, gravity or \
         wrenches too large)"
    ))
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
    /// An invalid description item.
    pub fn invalid(item: Item, reason: impl Into<String>) -> Error {
        Error::Invalid {
            location: Location::default(),
            item,
            reason: reason.into(),
        }
    }

    /// A parse error at a line of a file.
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
        let location = match &mut self {
            Error::Invalid { location, .. } | Error::Parse { location, .. } => Some(location),
            Error::Physical { location, .. } => Some(&mut **location),
            _ => None,
        };
        if let Some(location) = location {
            if location.file.is_none() {
                location.file = file.map(str::to_string);
            }
            if location.line.is_none() {
                location.line = line;
            }
        }
        self
    }

    /// The description item an `Invalid` or `Physical` error refers to.
    pub fn item(&self) -> Option<&Item> {
        match self {
            Error::Invalid { item, .. } | Error::Physical { item, .. } => Some(item),
            _ => None,
        }
    }

    /// A physically inconsistent parameter.
    pub fn physical(item: Item, reason: impl Into<String>) -> Error {
        Error::Physical {
            location: Box::default(),
            item,
            reason: reason.into(),
        }
    }

    /// An I/O error on `path`, keeping the operating system's error as the source.
    pub fn io(path: impl Into<String>, source: std::io::Error) -> Error {
        Error::Io {
            path: path.into(),
            source: Arc::new(source),
        }
    }

    /// A vector of the wrong size.
    pub fn dimension(
        what: impl Into<String>,
        expected: usize,
        got: usize,
        context: impl Into<String>,
    ) -> Error {
        Error::Dimension {
            what: what.into(),
            expected,
            got,
            context: context.into(),
        }
    }

    /// This error as the error of row `row` (1-based) of a table.
    pub fn in_row(self, row: usize) -> Error {
        Error::Row {
            row,
            source: Box::new(self),
        }
    }

    /// The error itself, or the error of its row for [`Error::Row`].
    pub fn innermost(&self) -> &Error {
        match self {
            Error::Row { source, .. } => source.innermost(),
            e => e,
        }
    }
}

/// Check that `v` has `n` entries, all finite: the entry check of every checked function.
pub(crate) fn check_vector(
    what: &str,
    v: &[f64],
    n: usize,
    context: impl FnOnce() -> String,
) -> Result<()> {
    if v.len() != n {
        return Err(Error::dimension(what, n, v.len(), context()));
    }
    // a branch-free pass, vectorizable (an early-exit scan cost ~10 ns per vector, 10 % of a
    // 6-joint Newton–Euler); the index is looked for on failure
    if v.iter().fold(false, |bad, x| bad | !x.is_finite()) {
        return Err(not_finite(what, v));
    }
    Ok(())
}

/// The error naming the first entry of `v` that is not finite.
#[cold]
fn not_finite(what: &str, v: &[f64]) -> Error {
    let index = v.iter().position(|x| !x.is_finite()).unwrap_or(0);
    Error::NotFinite {
        what: what.into(),
        index,
        value: v[index],
    }
}

/// The result type of the library.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// Every position of a non-finite entry (in the 16-lane part and in the remainder) is found
    /// and named; finite entries whose sum overflows are accepted.
    #[test]
    fn finite_matrix_check_finds_every_non_finite_entry() {
        for (r, c) in [(5, 7), (7, 3), (4, 1), (1, 1), (3, 5)] {
            let base = DMatrix::from_fn(r, c, |i, j| 1e308 * (1.0 + (i + 3 * j) as f64 * 1e-3));
            assert!(
                check_finite_matrix("A", &base).is_ok(),
                "{r} x {c}: overflowing sum"
            );
            for k in 0..r * c {
                for bad in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN] {
                    let mut m = base.clone();
                    m.as_mut_slice()[k] = bad;
                    let e = check_finite_matrix("A", &m).unwrap_err().to_string();
                    let name = format!("A[{}, {}]", k % r, k / r);
                    assert!(e.contains(&name), "{r} x {c}, entry {k} = {bad}: {e}");
                }
            }
        }
    }
}
