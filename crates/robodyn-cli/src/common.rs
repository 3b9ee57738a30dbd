//! Options and helpers shared by the commands: loading a robot, reading and writing state tables.

use clap::Args;
use robodyn::Robot;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

pub type CliResult<T = ()> = Result<T, Box<dyn std::error::Error>>;

/// The robot file and symbol overrides.
#[derive(Args, Debug, Clone)]
pub struct RobotArgs {
    /// Robot file (.toml, .par or .urdf).
    pub robot: PathBuf,
    /// Give or override a symbol value, e.g. `--set d3=0.6` (repeatable).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

impl RobotArgs {
    pub fn overrides(&self) -> CliResult<BTreeMap<String, f64>> {
        let mut m = BTreeMap::new();
        for s in &self.set {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| format!("--set {s}: expected NAME=VALUE"))?;
            let x: f64 = v
                .trim()
                .parse()
                .map_err(|_| format!("--set {s}: `{v}` is not a number"))?;
            if !x.is_finite() {
                return Err(format!("--set {s}: value is not finite").into());
            }
            m.insert(k.trim().to_string(), x);
        }
        Ok(m)
    }

    /// Load and validate the robot (all symbols need values). A motor-joint transmission with
    /// nonzero motor drive parameters is refused: only `identify` and `excite` apply it.
    pub fn load(&self) -> CliResult<Robot> {
        let robot = robodyn::io::load_with(&self.robot, &self.overrides()?)?;
        if let Some(t) = &robot.description().transmission {
            let k = robot.standard_parameters();
            let identity = t.matrix.iter().enumerate().all(|(r, row)| {
                row.iter()
                    .enumerate()
                    .all(|(c, &x)| x == if r == c { 1.0 } else { 0.0 })
            });
            let driven = t
                .joints
                .iter()
                .any(|&j| (10..13).any(|p| k[13 * (j - 1) + p] != 0.0));
            if !identity && driven {
                return Err(format!(
                    "{}: the robot has a motor-joint [transmission] and motor drive parameters \
                     (IA, FS, FV); this command does not apply transmissions (only `robodyn \
                     identify` and `robodyn excite` do), so it would read them as joint-side values",
                    self.robot.display()
                )
                .into());
            }
        }
        Ok(robot)
    }
}

/// Parse a comma-separated list of numbers (`--q 0.1,0.2,...`).
pub fn parse_list(name: &str, s: &str) -> CliResult<Vec<f64>> {
    s.split(',')
        .map(|t| {
            let t = t.trim();
            robodyn::Expr::parse(t)
                .ok()
                .and_then(|e| e.eval(&|_| None).ok())
                .ok_or_else(|| format!("--{name}: `{t}` is not a number").into())
        })
        .collect()
}

/// A table of named columns read from CSV.
pub struct Table {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<f64>>,
    pub file: String,
}

impl Table {
    pub fn read(path: &Path) -> CliResult<Table> {
        let file = path.display().to_string();
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_path(path)
            .map_err(|e| format!("{file}: {e}"))?;
        let headers: Vec<String> = rdr
            .headers()
            .map_err(|e| format!("{file}: {e}"))?
            .iter()
            .map(str::to_string)
            .collect();
        let mut rows = Vec::new();
        for (i, rec) in rdr.records().enumerate() {
            let rec = rec.map_err(|e| format!("{file}: {e}"))?;
            let line = rec.position().map(|p| p.line()).unwrap_or(i as u64 + 2);
            let mut row = Vec::with_capacity(rec.len());
            for (k, field) in rec.iter().enumerate() {
                let x: f64 = field.parse().map_err(|_| {
                    format!(
                        "{file}:{line}: column `{}`: `{field}` is not a number",
                        headers[k]
                    )
                })?;
                if !x.is_finite() {
                    return Err(format!(
                        "{file}:{line}: column `{}`: {x} is not finite",
                        headers[k]
                    )
                    .into());
                }
                row.push(x);
            }
            rows.push(row);
        }
        Ok(Table {
            headers,
            rows,
            file,
        })
    }

    /// Index of a column, or an error naming the file and the column.
    pub fn column(&self, name: &str) -> CliResult<usize> {
        self.headers
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| format!("{}: missing column `{name}`", self.file).into())
    }

    /// Index of a column if present.
    #[allow(dead_code)]
    pub fn find(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }
}

/// Output format of tables.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TableFormat {
    #[default]
    Csv,
    Json,
}

/// Where and how a command writes its table (`--output`, `--format`).
#[derive(Args, Debug, Clone)]
pub struct TableOutput {
    /// Output file (default: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

impl TableOutput {
    /// Write rows of named columns.
    pub fn write(&self, headers: &[String], rows: &[Vec<f64>]) -> CliResult {
        write_table(self.output.as_deref(), self.format, headers, rows)
    }
}

/// Write rows of named columns as CSV or JSON (a list of objects) to a file or stdout.
pub fn write_table(
    path: Option<&Path>,
    format: TableFormat,
    headers: &[String],
    rows: &[Vec<f64>],
) -> CliResult {
    let mut out: Box<dyn Write> = match path {
        Some(p) => Box::new(std::io::BufWriter::new(
            std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()))?,
        )),
        None => Box::new(std::io::stdout().lock()),
    };
    match format {
        TableFormat::Csv => {
            writeln!(out, "{}", headers.join(","))?;
            for r in rows {
                let line: Vec<String> = r.iter().map(|x| format!("{x:.12e}")).collect();
                writeln!(out, "{}", line.join(","))?;
            }
        }
        TableFormat::Json => {
            let v: Vec<serde_json::Map<String, serde_json::Value>> = rows
                .iter()
                .map(|r| {
                    headers
                        .iter()
                        .zip(r)
                        .map(|(h, x)| (h.clone(), serde_json::json!(x)))
                        .collect()
                })
                .collect();
            serde_json::to_writer_pretty(&mut out, &v)?;
            writeln!(out)?;
        }
    }
    Ok(())
}

/// One state per row: three per-joint columns (e.g. `q qd qdd` or `q qd tau`), for `joints` in
/// that order, with a label naming its origin for error messages.
pub type LabelledStates = Vec<(String, [Vec<f64>; 3])>;

/// Read states of `joints` from a CSV file (`input`, columns `<name><j>`) or from the comma lists
/// of the command line (`lists`, the first one required, the others default to zeros). `what`
/// names the joints in messages ("movable tree joints", "actuated joints (closed chain)").
pub fn read_joint_states(
    input: Option<&Path>,
    names: [&str; 3],
    lists: [Option<&str>; 3],
    joints: &[usize],
    what: &str,
) -> CliResult<LabelledStates> {
    let n = joints.len();
    if let Some(path) = input {
        let t = Table::read(path)?;
        let cols: Vec<[usize; 3]> = joints
            .iter()
            .map(|j| {
                Ok([
                    t.column(&format!("{}{j}", names[0]))?,
                    t.column(&format!("{}{j}", names[1]))?,
                    t.column(&format!("{}{j}", names[2]))?,
                ])
            })
            .collect::<CliResult<_>>()?;
        return Ok(t
            .rows
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let s = std::array::from_fn(|i| cols.iter().map(|c| r[c[i]]).collect());
                (format!("{}: data row {}", t.file, k + 1), s)
            })
            .collect());
    }
    if lists[0].is_none() {
        return Err(format!(
            "give --input states.csv or --{} (with --{}, --{})",
            names[0], names[1], names[2]
        )
        .into());
    }
    let mut s = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for k in 0..3 {
        if let Some(v) = lists[k] {
            let vals = parse_list(names[k], v)?;
            if vals.len() != n {
                return Err(format!(
                    "--{} has {} values, the robot has {n} {what} ({joints:?})",
                    names[k],
                    vals.len()
                )
                .into());
            }
            s[k] = vals;
        }
    }
    Ok(vec![("the given state".to_string(), s)])
}

/// Spread values of `joints` into a vector of NL entries (index j-1), zeros elsewhere.
pub fn scatter(joints: &[usize], nl: usize, values: &[f64]) -> Vec<f64> {
    let mut v = vec![0.0; nl];
    for (j, x) in joints.iter().zip(values) {
        v[j - 1] = *x;
    }
    v
}

/// Continuation steps between consecutive rows of a closed-chain table.
const CONTINUATION_STEPS: usize = 8;

/// Closed chains: evaluate a model row after row, each row's loop closure continued from the
/// previous row's solution (the first from `guess`, else from the robot's assembly configuration).
/// `eval(ws, q_a, x, y, q_p)` gets the row's three columns and the solved q_p.
pub fn closed_chain_rows(
    cc: &robodyn::algorithms::closed_chain::ClosedChain,
    states: &LabelledStates,
    guess: Option<&str>,
    mut eval: impl FnMut(
        &mut robodyn::algorithms::closed_chain::ClosedChainWorkspace,
        &[f64],
        &[f64],
        &[f64],
        &[f64],
    ) -> robodyn::Result<Vec<f64>>,
) -> CliResult<Vec<Vec<f64>>> {
    let guess = guess.map(|g| parse_list("guess", g)).transpose()?;
    let mut ws = cc.workspace();
    let mut rows = Vec::with_capacity(states.len());
    let mut previous: Option<(Vec<f64>, Vec<f64>)> = None;
    for (what, [q, x, y]) in states {
        // continuation from the previous row keeps the assembly branch even when consecutive
        // rows are far apart (a plain Newton solve from the previous q_p may jump branches)
        let s = match &previous {
            None => cc.solve_from_reference(&mut ws, q, guess.as_deref()),
            Some((qa0, qp0)) => {
                cc.closure()
                    .solve_continuation(&mut ws.closure, q, qa0, qp0, CONTINUATION_STEPS)
            }
        }
        .map_err(|e| format!("{what}: {e}"))?;
        rows.push(eval(&mut ws, q, x, y, &s.q_p).map_err(|e| format!("{what}: {e}"))?);
        previous = Some((q.clone(), s.q_p));
    }
    Ok(rows)
}
