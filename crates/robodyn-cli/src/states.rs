//! Input tables of states (`idm`, `ddm`, `regressor --input`, `simulate --track/--torque-csv`):
//! which columns are read, which are carried or ignored, which are refused; and reading the
//! states in chunks of bounded size.
//!
//! The rule for the columns of an input table (docs/cli.md, "State tables"):
//! - the command's inputs (`q<j>`, `qd<j>`, `qdd<j>` or `tau<j>` of the robot's joints, named as
//!   `--names` says): the first quantity is required, each other one may be absent as a whole
//!   (zeros, and a note says so) but not in part;
//! - a column whose name looks like a misspelling of a missing input (`qdd_1`, `QDD1`, `qdd01`,
//!   `dqd1` for `qdd1`) is an error naming it and the input it resembles: a misspelt column
//!   would otherwise be read as zeros;
//! - `t`, the other joint columns of the robot (`tau<j>` in a table for `idm`) and the columns
//!   declared with `--carry` are carried to the output (or, for `simulate`, ignored) silently;
//! - any other column is carried (or ignored) with a warning naming it and the inputs.

use crate::common::{parse_list, CliResult, Names, NamesArg};
use robodyn::io::table::TableReader;
use std::io::Read;
use std::path::Path;

/// `--carry`: columns of an input table that are not inputs, carried to the output.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct CarryArg {
    /// Columns of the --input table that are not inputs, copied to the output in front of the
    /// results (comma separated; `t` always is). Another column that is not an input is copied
    /// with a warning; one that looks like a misspelt input (`qdd_1` for `qdd1`) is an error.
    #[arg(
        long,
        value_delimiter = ',',
        value_name = "COLUMNS",
        requires = "input"
    )]
    pub carry: Vec<String>,
}

/// One group of input columns: a quantity over the joints.
pub struct Group {
    /// `q`, `qd`, `qdd`, `tau`.
    pub prefix: String,
    /// Its column per joint.
    pub names: Vec<String>,
    /// Required (else it may be absent as a whole).
    pub required: bool,
    /// What an absent group means, in the note that says so ("they are taken as zero").
    pub absent: &'static str,
}

/// What a command reads from a table's header.
pub struct ColumnSpec<'a> {
    pub groups: Vec<Group>,
    /// Columns that mean something but are not read (`t`, other joint quantities): no warning.
    pub known: Vec<String>,
    /// Columns declared with `--carry`.
    pub declared: &'a [String],
    /// What happens to the other columns: "carried to the output" or "ignored".
    pub fate: &'static str,
    /// How `--carry` is spelt for this command, if it has it.
    pub carry_option: bool,
    /// Said after a missing-column error (the table follows the other `--names`).
    pub hint: Option<String>,
}

/// The columns of a header against a [`ColumnSpec`].
pub struct Columns {
    /// Per group, the column of each joint; `None` when the group is absent.
    pub groups: Vec<Option<Vec<usize>>>,
    /// The columns that are not inputs, in file order.
    pub others: Vec<usize>,
}

/// Lowercase, without separators and leading zeros of numbers: `QDD_01` -> `qdd1`.
fn normalized(s: &str) -> String {
    let chars: Vec<char> = s
        .chars()
        .filter(|c| !matches!(c, '_' | '-' | ' ' | '.' | '(' | ')' | '[' | ']'))
        .map(|c| c.to_ascii_lowercase())
        .collect();
    let mut out = String::new();
    for (k, &c) in chars.iter().enumerate() {
        let prev_digit =
            k > 0 && chars[k - 1].is_ascii_digit() && out.ends_with(|p: char| p.is_ascii_digit());
        let next_digit = chars.get(k + 1).is_some_and(char::is_ascii_digit);
        // a leading zero of a number (`qdd01`) goes; `0` itself (`q0`) and `10` stay
        if c == '0' && !prev_digit && next_digit {
            continue;
        }
        out.push(c);
    }
    out
}

/// Whether `column` looks like a misspelling of `name`.
fn resembles(column: &str, name: &str) -> bool {
    let (a, b) = (normalized(column), normalized(name));
    a == b || a.len() >= 2 && strsim::osa_distance(&a, &b) <= 1
}

/// The expected columns in a few words: `q<j>, qd<j>, qdd<j> for j in [1, 2, 3]`, or every
/// name when the joints are named.
fn expected(spec: &ColumnSpec) -> String {
    let labels = |g: &Group| -> Vec<String> {
        g.names
            .iter()
            .map(|n| n[g.prefix.len()..].to_string())
            .collect()
    };
    let numbered = spec.groups.iter().all(|g| {
        labels(g)
            .iter()
            .all(|l| !l.is_empty() && l.bytes().all(|b| b.is_ascii_digit()))
    });
    match spec.groups.first() {
        Some(g) if numbered => {
            let prefixes: Vec<String> = spec
                .groups
                .iter()
                .map(|g| format!("{}<j>", g.prefix))
                .collect();
            format!(
                "{} for j in [{}]",
                prefixes.join(", "),
                labels(g).join(", ")
            )
        }
        _ => {
            let all: Vec<&str> = spec
                .groups
                .iter()
                .flat_map(|g| g.names.iter().map(String::as_str))
                .collect();
            all.join(", ")
        }
    }
}

/// Classify the header's columns (the rule of the module documentation). Warnings and notes go
/// to standard error; errors name `file`.
pub fn classify(headers: &[String], spec: &ColumnSpec, file: &str) -> CliResult<Columns> {
    let find = |n: &str| headers.iter().position(|h| h == n);
    // the inputs: found, absent as a whole (an optional group), or missing
    let mut groups = Vec::new();
    let mut missing: Vec<&str> = Vec::new();
    let mut absent: Vec<&Group> = Vec::new();
    for g in &spec.groups {
        let found: Vec<Option<usize>> = g.names.iter().map(|n| find(n)).collect();
        if !g.required && found.iter().all(Option::is_none) {
            groups.push(None);
            absent.push(g);
            continue;
        }
        missing.extend(
            g.names
                .iter()
                .zip(&found)
                .filter(|(_, c)| c.is_none())
                .map(|(n, _)| n.as_str()),
        );
        groups.push(Some(found.into_iter().map(|c| c.unwrap_or(0)).collect()));
    }
    let not_read: Vec<&str> = absent
        .iter()
        .flat_map(|g| g.names.iter().map(String::as_str))
        .chain(missing.iter().copied())
        .collect();
    let (others, misspelt, unknown) = others(headers, spec, &not_read);
    if !misspelt.is_empty() {
        return Err(misspelt_error(&misspelt, spec, file).into());
    }
    if !missing.is_empty() {
        return Err(missing_error(&missing, spec, file).into());
    }
    if let Some(d) = spec.declared.iter().find(|d| find(d).is_none()) {
        return Err(format!("--carry {d}: {file} has no column `{d}`").into());
    }
    for g in absent {
        eprintln!(
            "robodyn: note: {file} has no {} columns ({}...): {}",
            g.prefix,
            g.names.first().map_or("", String::as_str),
            g.absent
        );
    }
    if !unknown.is_empty() {
        eprintln!(
            "robodyn: warning: {}",
            unknown_warning(&unknown, spec, file)
        );
    }
    Ok(Columns { groups, others })
}

/// The columns that are not inputs (indices), and among those not declared nor known, the
/// misspelt ones (`` `qdd_1` (did you mean `qdd1`?) ``, resembling an input in `not_read`) and
/// the unknown ones.
fn others(
    headers: &[String],
    spec: &ColumnSpec,
    not_read: &[&str],
) -> (Vec<usize>, Vec<String>, Vec<String>) {
    let inputs: std::collections::BTreeSet<&str> = spec
        .groups
        .iter()
        .flat_map(|g| g.names.iter().map(String::as_str))
        .collect();
    let (mut others, mut misspelt, mut unknown) = (Vec::new(), Vec::new(), Vec::new());
    for (c, h) in headers.iter().enumerate() {
        if inputs.contains(h.as_str()) {
            continue;
        }
        others.push(c);
        if spec.declared.contains(h) || spec.known.contains(h) {
            continue;
        }
        let exact = not_read.iter().find(|n| normalized(h) == normalized(n));
        match exact.or_else(|| not_read.iter().find(|n| resembles(h, n))) {
            Some(n) => misspelt.push(format!("`{h}` (did you mean `{n}`?)")),
            None => unknown.push(format!("`{h}`")),
        }
    }
    (others, misspelt, unknown)
}

fn misspelt_error(misspelt: &[String], spec: &ColumnSpec, file: &str) -> String {
    let s = plural(misspelt.len());
    format!(
        "{file}: column{s} {} look{} like misspelt input{s} and would be {} instead of read; \
         the inputs are {} (rename the column{s})",
        misspelt.join(", "),
        if misspelt.len() == 1 { "s" } else { "" },
        spec.fate,
        expected(spec),
    )
}

fn missing_error(missing: &[&str], spec: &ColumnSpec, file: &str) -> String {
    let optional: Vec<&str> = spec
        .groups
        .iter()
        .filter(|g| !g.required)
        .map(|g| g.prefix.as_str())
        .collect();
    let names: Vec<String> = missing.iter().map(|m| format!("`{m}`")).collect();
    let rule = if optional.is_empty() {
        String::new()
    } else {
        format!(
            "; the {} columns may be absent all together, not in part",
            optional.join("/")
        )
    };
    let hint = spec
        .hint
        .as_ref()
        .map_or_else(String::new, |h| format!("; {h}"));
    format!(
        "{file}: missing column{} {} (the inputs are {}{rule}){hint}",
        plural(missing.len()),
        names.join(", "),
        expected(spec),
    )
}

fn unknown_warning(unknown: &[String], spec: &ColumnSpec, file: &str) -> String {
    let s = plural(unknown.len());
    format!(
        "{file}: column{s} {} {} not input{s} of this command (the inputs are {}): {}{}",
        unknown.join(", "),
        if unknown.len() == 1 { "is" } else { "are" },
        expected(spec),
        spec.fate,
        if spec.carry_option {
            " (--carry with the column names says they are meant so, and silences this)"
        } else {
            ""
        }
    )
}

fn plural(n: usize) -> &'static str {
    if n == 1 {
        ""
    } else {
        "s"
    }
}

/// The joint columns of the robot that a command may meet without reading them: `q<j>`,
/// `qd<j>`, `qdd<j>`, `tau<j>` of every joint (`labels`: `<j>` as `--names` writes it), and `t`;
/// with a floating base, every base column `simulate` writes (state, forces, momenta).
pub fn known_columns(labels: &[String], floating: bool) -> Vec<String> {
    let mut known = vec!["t".to_string()];
    for prefix in ["q", "qd", "qdd", "tau"] {
        known.extend(labels.iter().map(|l| format!("{prefix}{l}")));
    }
    if floating {
        use robodyn::simulation::floating::{BASE_COLUMNS, MOMENTUM_COLUMNS};
        let base = BASE_COLUMNS.iter().flatten().chain(&MOMENTUM_COLUMNS);
        known.extend(base.filter(|c| !c.is_empty()).map(|c| c.to_string()));
        known.push("energy".to_string());
    }
    known
}

/// A chunk of states: the quantities of `count` states, row-major (`count` x n each), and their
/// carried columns (`count` x carried).
#[derive(Default)]
pub struct Chunk {
    pub count: usize,
    /// 1-based number of the chunk's first state.
    pub first: usize,
    pub x: [Vec<f64>; 3],
    pub carried: Vec<f64>,
}

impl Chunk {
    /// State `s` of the chunk (0-based): its three quantities.
    pub fn state(&self, s: usize, n: usize) -> [&[f64]; 3] {
        std::array::from_fn(|i| &self.x[i][s * n..(s + 1) * n])
    }

    /// The carried values of state `s`.
    pub fn carried(&self, s: usize, nc: usize) -> &[f64] {
        &self.carried[s * nc..(s + 1) * nc]
    }
}

/// Where the states come from.
enum Source {
    Table {
        reader: Box<TableReader<Box<dyn Read>>>,
        cols: Vec<Option<Vec<usize>>>,
        others: Vec<usize>,
        row: Vec<f64>,
    },
    /// One state from the command line, not read yet.
    Lists(Option<[Vec<f64>; 3]>),
    Done,
}

/// States over some joints from a table (`--input`) or the command line, read in chunks.
pub struct StateInput {
    source: Source,
    /// The table (for messages).
    file: String,
    /// Entries of each quantity (a floating base's first: nq, then nv).
    n: [usize; 3],
    carried_headers: Vec<String>,
    read: usize,
    command_line: bool,
}

/// What a state reader is asked for.
pub struct StateRequest<'a> {
    /// `--input`, if given (`-`: standard input).
    pub input: Option<&'a Path>,
    /// The three quantities, e.g. `["q", "qd", "qdd"]`; the first is required.
    pub prefixes: [&'a str; 3],
    /// The comma lists of the command line (`--q`, `--qd`, `--qdd`), without `--input`.
    pub lists: [Option<&'a str>; 3],
    pub coords: &'a robodyn::Coordinates,
    /// All movable joints of the robot's tree (their other columns are known, not warned about).
    pub tree: &'a robodyn::Coordinates,
    pub names: NamesArg,
    /// What the joints are, in messages ("movable joints", "actuated joints").
    pub what: &'a str,
    /// `--carry`.
    pub carry: &'a [String],
    /// A floating robot's base columns in front of each quantity's joint columns
    /// ([`base_columns`]); empty for a fixed base.
    pub base: [Vec<String>; 3],
}

/// The base columns of a quantity (`q`, `qd`, `qdd`, `tau`) of a floating robot, as `simulate`
/// writes them (`base_x` .. `base_qw`, `base_vx` .. `base_wz`, `base_ax` .. `base_dwz`,
/// `base_fx` .. `base_mz`); none for a fixed base.
pub fn base_columns(robot: &robodyn::Robot, prefix: &str) -> Vec<String> {
    let k = ["q", "qd", "qdd", "tau"].iter().position(|p| *p == prefix);
    match k {
        Some(k) if robot.is_floating() => robodyn::simulation::floating::BASE_COLUMNS[k]
            .iter()
            .filter(|c| !c.is_empty())
            .map(|c| c.to_string())
            .collect(),
        _ => Vec::new(),
    }
}

/// [`base_columns`] of the three quantities.
pub fn base_columns3(robot: &robodyn::Robot, prefixes: [&str; 3]) -> [Vec<String>; 3] {
    prefixes.map(|p| base_columns(robot, p))
}

impl StateInput {
    /// Open the states: check a table's header (the rule of the module documentation), or
    /// parse the command-line lists.
    pub fn open(r: &StateRequest) -> CliResult<StateInput> {
        let n: [usize; 3] = std::array::from_fn(|i| r.base[i].len() + r.coords.len());
        let Some(path) = r.input else {
            return Ok(StateInput {
                source: Source::Lists(Some(lists(r)?)),
                file: String::new(),
                n,
                carried_headers: Vec::new(),
                read: 0,
                command_line: true,
            });
        };
        let (input, file): (Box<dyn Read>, String) = if robodyn::io::is_stdio(path) {
            (Box::new(std::io::stdin()), "<stdin>".into())
        } else {
            let f = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
            (
                Box::new(std::io::BufReader::new(f)),
                path.display().to_string(),
            )
        };
        let reader = TableReader::new(input, &file)?;
        let spec = ColumnSpec {
            groups: (0..3)
                .map(|i| Group {
                    prefix: r.prefixes[i].to_string(),
                    names: [r.base[i].clone(), r.names.columns(r.prefixes[i], r.coords)].concat(),
                    required: i == 0,
                    absent: "they are taken as zero",
                })
                .collect(),
            known: known_columns(&r.names.columns("", r.tree), !r.base[0].is_empty()),
            declared: r.carry,
            fate: "carried to the output",
            carry_option: true,
            hint: other_naming(reader.headers(), r),
        };
        let c = classify(reader.headers(), &spec, &file)?;
        let carried_headers = c
            .others
            .iter()
            .map(|&k| reader.headers()[k].clone())
            .collect();
        Ok(StateInput {
            source: Source::Table {
                reader: Box::new(reader),
                cols: c.groups,
                others: c.others,
                row: Vec::new(),
            },
            file,
            n,
            carried_headers,
            read: 0,
            command_line: false,
        })
    }

    /// The columns carried from the table to the output, in front of the results.
    pub fn carried_headers(&self) -> &[String] {
        &self.carried_headers
    }

    /// The output's columns: the carried ones, then `results`. A carried column named like a
    /// result (a measured `tau1` in a table for `idm`) is an error: the output would have two.
    pub fn headers_with(&self, results: &[String]) -> CliResult<Vec<String>> {
        if let Some(h) = self.carried_headers.iter().find(|h| results.contains(h)) {
            return Err(format!(
                "{}: column `{h}` would be carried to the output next to the computed `{h}`: \
                 rename it in the table (e.g. `{h}_measured`)",
                self.file
            )
            .into());
        }
        Ok([&self.carried_headers[..], results].concat())
    }

    /// Whether the states come from the command line (one state: messages without a row).
    pub fn is_command_line(&self) -> bool {
        self.command_line
    }

    /// The states read so far.
    pub fn count(&self) -> usize {
        self.read
    }

    /// Read up to `max` states into `chunk` (cleared): `false` when there are no more.
    pub fn next_chunk(&mut self, max: usize, chunk: &mut Chunk) -> CliResult<bool> {
        chunk.count = 0;
        chunk.first = self.read + 1;
        chunk.x.iter_mut().for_each(Vec::clear);
        chunk.carried.clear();
        match &mut self.source {
            Source::Done => return Ok(false),
            Source::Lists(state) => {
                let s = state.take().expect("one state");
                for (x, v) in chunk.x.iter_mut().zip(s) {
                    x.extend(v);
                }
                chunk.count = 1;
                self.source = Source::Done;
            }
            Source::Table {
                reader,
                cols,
                others,
                row,
            } => {
                while chunk.count < max && reader.next_row(row)? {
                    for ((x, c), &n) in chunk.x.iter_mut().zip(cols.iter()).zip(&self.n) {
                        match c {
                            Some(c) => x.extend(c.iter().map(|&k| row[k])),
                            None => x.extend(std::iter::repeat_n(0.0, n)),
                        }
                    }
                    chunk.carried.extend(others.iter().map(|&k| row[k]));
                    chunk.count += 1;
                }
            }
        }
        self.read += chunk.count;
        Ok(chunk.count > 0)
    }
}

/// "the table names its columns after the joints: give --names joint" when every `q` column of
/// the other naming is in the header.
fn other_naming(headers: &[String], r: &StateRequest) -> Option<String> {
    let other = match r.names.names {
        Names::Frame => Names::Joint,
        Names::Joint => Names::Frame,
    };
    let names = NamesArg { names: other };
    let all = names
        .columns(r.prefixes[0], r.coords)
        .iter()
        .all(|c| headers.contains(c));
    all.then(|| {
        let (how, option) = match other {
            Names::Joint => ("after the joints", "--names joint"),
            Names::Frame => ("by frame number", "--names frame"),
        };
        format!("the table names its columns {how}: give {option}")
    })
}

/// The one state of the command-line lists: the first required, the others zeros by default.
/// A floating robot's lists hold the base entries first (nq for q, nv for the others).
fn lists(r: &StateRequest) -> CliResult<[Vec<f64>; 3]> {
    let p = r.prefixes;
    if r.lists[0].is_none() {
        return Err(format!(
            "give --input states.csv or --{} (with --{}, --{})",
            p[0], p[1], p[2]
        )
        .into());
    }
    let n: [usize; 3] = std::array::from_fn(|k| r.base[k].len() + r.coords.len());
    let mut s = n.map(|n| vec![0.0; n]);
    for k in 0..3 {
        if let Some(v) = r.lists[k] {
            let vals = parse_list(p[k], v)?;
            if vals.len() != n[k] {
                let base = match r.base[k].as_slice() {
                    [] => String::new(),
                    b => format!(
                        "{} base entries ({}, floating base) then ",
                        b.len(),
                        b.join(", ")
                    ),
                };
                return Err(format!(
                    "--{} has {} values, the robot has {}{} {} ({:?}): {} values",
                    p[k],
                    vals.len(),
                    base,
                    r.coords.len(),
                    r.what,
                    r.coords.frames(),
                    n[k]
                )
                .into());
            }
            s[k] = vals;
        }
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::{normalized, resembles};

    #[test]
    fn misspellings() {
        assert_eq!(normalized("QDD_01"), "qdd1");
        assert_eq!(normalized("q10"), "q10");
        assert_eq!(normalized("q_0"), "q0");
        for (c, n) in [
            ("qdd_1", "qdd1"),
            ("QDD1", "qdd1"),
            ("qdd01", "qdd1"),
            ("dqd1", "qdd1"),
        ] {
            assert!(resembles(c, n), "{c} {n}");
        }
        for (c, n) in [
            ("tau1", "qdd1"),
            ("t", "q1"),
            ("label", "qd1"),
            ("q12", "q3"),
        ] {
            assert!(!resembles(c, n), "{c} {n}");
        }
    }
}
