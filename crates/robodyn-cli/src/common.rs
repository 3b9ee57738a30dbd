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
    /// Read a state table (the library's reader: a repeated column, a short row or a field
    /// that is not a finite number is an error with its line).
    pub fn read(path: &Path) -> CliResult<Table> {
        let t = robodyn::io::table::Table::read(path)?;
        Ok(Table {
            headers: t.headers,
            rows: t.rows,
            file: t.file,
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

    /// Write rows with extra JSON fields per row.
    pub fn write_with(
        &self,
        headers: &[String],
        rows: &[Vec<f64>],
        json_extra: &[serde_json::Map<String, serde_json::Value>],
    ) -> CliResult {
        write_table_with(
            self.output.as_deref(),
            self.format,
            headers,
            rows,
            json_extra,
        )
    }
}

/// Write rows of named columns as CSV or JSON (a list of objects) to a file or stdout.
pub fn write_table(
    path: Option<&Path>,
    format: TableFormat,
    headers: &[String],
    rows: &[Vec<f64>],
) -> CliResult {
    write_table_with(path, format, headers, rows, &[])
}

/// [`write_table`] with extra fields per row in JSON output (e.g. a closed chain's
/// conditioning); CSV output leaves them out.
pub fn write_table_with(
    path: Option<&Path>,
    format: TableFormat,
    headers: &[String],
    rows: &[Vec<f64>],
    json_extra: &[serde_json::Map<String, serde_json::Value>],
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
                .enumerate()
                .map(|(k, r)| {
                    let mut o: serde_json::Map<String, serde_json::Value> = headers
                        .iter()
                        .zip(r)
                        .map(|(h, x)| (h.clone(), serde_json::json!(x)))
                        .collect();
                    if let Some(e) = json_extra.get(k) {
                        o.extend(e.clone());
                    }
                    o
                })
                .collect();
            serde_json::to_writer_pretty(&mut out, &v)?;
            writeln!(out)?;
        }
    }
    Ok(())
}

/// How joint columns are named.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Names {
    /// By frame number: `q3`, `tau3` (the default for .toml and .par robots).
    #[default]
    Frame,
    /// By joint name: `q_shoulder_pan_joint` (URDF joint names; `j<frame>` when the file
    /// gives none).
    Joint,
}

/// Column naming option shared by the commands that read or write joint columns.
#[derive(Args, Debug, Clone, Copy)]
pub struct NamesArg {
    /// Name joint columns by frame number (`q3`) or by joint name (`q_shoulder_pan_joint`).
    #[arg(long, value_enum, default_value = "frame")]
    pub names: Names,
}

impl NamesArg {
    /// Column name of entry k of a joint vector: `<prefix><frame>` or `<prefix>_<name>`.
    pub fn column(&self, prefix: &str, coords: &robodyn::Coordinates, k: usize) -> String {
        match self.names {
            Names::Frame => format!("{prefix}{}", coords.frame(k)),
            Names::Joint => format!("{prefix}_{}", coords.name(k)),
        }
    }

    /// Column names of a joint vector.
    pub fn columns(&self, prefix: &str, coords: &robodyn::Coordinates) -> Vec<String> {
        (0..coords.len())
            .map(|k| self.column(prefix, coords, k))
            .collect()
    }
}

/// One state per row: three per-joint columns (e.g. `q qd qdd` or `q qd tau`) over `coords`.
pub type States = Vec<[Vec<f64>; 3]>;

/// Read states over `coords` from a CSV file (`input`, columns named by `names`) or from the
/// comma lists of the command line (`lists`, the first one required, the others default to
/// zeros). `what` names the joints in messages ("movable joints", "actuated joints").
pub fn read_joint_states(
    input: Option<&Path>,
    prefixes: [&str; 3],
    lists: [Option<&str>; 3],
    coords: &robodyn::Coordinates,
    names: NamesArg,
    what: &str,
) -> CliResult<States> {
    let n = coords.len();
    if let Some(path) = input {
        let t = Table::read(path)?;
        let cols: Vec<[usize; 3]> = (0..n)
            .map(|k| {
                Ok([
                    t.column(&names.column(prefixes[0], coords, k))?,
                    t.column(&names.column(prefixes[1], coords, k))?,
                    t.column(&names.column(prefixes[2], coords, k))?,
                ])
            })
            .collect::<CliResult<_>>()?;
        return Ok(t
            .rows
            .iter()
            .map(|r| std::array::from_fn(|i| cols.iter().map(|c| r[c[i]]).collect()))
            .collect());
    }
    if lists[0].is_none() {
        return Err(format!(
            "give --input states.csv or --{} (with --{}, --{})",
            prefixes[0], prefixes[1], prefixes[2]
        )
        .into());
    }
    let mut s = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for k in 0..3 {
        if let Some(v) = lists[k] {
            let vals = parse_list(prefixes[k], v)?;
            if vals.len() != n {
                return Err(format!(
                    "--{} has {} values, the robot has {n} {what} ({:?})",
                    prefixes[k],
                    vals.len(),
                    coords.frames()
                )
                .into());
            }
            s[k] = vals;
        }
    }
    Ok(vec![s])
}

/// The branch tracker of a closed chain: from `--guess` (q_p at the first q_a) when given, else
/// the robot's assembly.
pub fn start_branch(
    chain: &robodyn::ClosedChain,
    first_qa: &[f64],
    guess: Option<&str>,
) -> CliResult<robodyn::Branch> {
    Ok(match guess {
        Some(g) => chain.branch_from(first_qa, &parse_list("guess", g)?)?,
        None => chain.assembly_branch()?,
    })
}

/// Say on stderr that a closed-chain row is near a singularity.
pub fn warn_conditioning(
    chain: &robodyn::ClosedChain,
    row: usize,
    rows: usize,
    c: &robodyn::Conditioning,
) {
    if c.warning {
        let which = if rows > 1 {
            format!("row {row}: ")
        } else {
            String::new()
        };
        eprintln!(
            "robodyn: warning: {which}near a singular configuration: {}; the result is \
             sensitive to its inputs",
            c.describe(chain.limits())
        );
    }
}

/// JSON fields of a closed chain's conditioning: `rcond_wp`, `rcond_a_cl`, `singularity_warning`.
pub fn conditioning_json(c: &robodyn::Conditioning) -> serde_json::Map<String, serde_json::Value> {
    let mut o = serde_json::Map::new();
    o.insert("rcond_wp".into(), serde_json::json!(c.wp));
    if let Some(a) = c.a_cl {
        o.insert("rcond_a_cl".into(), serde_json::json!(a));
    }
    o.insert("singularity_warning".into(), serde_json::json!(c.warning));
    o
}

/// Column `i` (q, qd, qdd or tau) of the states as one row-major N x n slice: the layout of the
/// library's batch functions (`robodyn::batch`).
pub fn state_column(states: &[[Vec<f64>; 3]], i: usize) -> Vec<f64> {
    states.iter().flat_map(|s| s[i].iter().copied()).collect()
}

/// The `count` rows of n entries of a row-major result.
pub fn result_rows(flat: &[f64], n: usize, count: usize) -> Vec<Vec<f64>> {
    (0..count)
        .map(|s| flat[s * n..(s + 1) * n].to_vec())
        .collect()
}
