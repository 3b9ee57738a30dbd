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
    /// Robot file (.toml, .par or .urdf; `-` reads standard input, format recognized from the
    /// text).
    pub robot: PathBuf,
    /// Give or override a symbol value, e.g. `--set d3=0.6` or `--set D3=pi/8` (repeatable; the
    /// symbol must be one the file uses, the value a constant expression as for `--q`).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
}

/// The symbols a description uses or gives a value to.
pub fn known_symbols(
    desc: &robodyn::model::RobotDescription,
) -> std::collections::BTreeSet<String> {
    let mut known: std::collections::BTreeSet<String> = desc.symbols.keys().cloned().collect();
    let mut add = |e: &robodyn::Expr| {
        e.for_each_symbol(&mut |s| {
            known.insert(s.to_string());
        })
    };
    for f in &desc.frames {
        for e in f.geometric() {
            add(e);
        }
    }
    for l in &desc.links {
        l.params.iter().chain(&l.wrench).for_each(&mut add);
    }
    for v in [&desc.gravity, &desc.w0, &desc.wp0, &desc.v0, &desc.vp0] {
        v.iter().for_each(&mut add);
    }
    known
}

impl RobotArgs {
    /// The `--set` values (names not yet checked against a robot: see [`check_overrides`]).
    pub fn overrides(&self) -> CliResult<BTreeMap<String, f64>> {
        let mut m = BTreeMap::new();
        for s in &self.set {
            let (k, v) = s
                .split_once('=')
                .ok_or_else(|| format!("--set {s}: expected NAME=VALUE"))?;
            let k = k.trim();
            if k.is_empty() {
                return Err(format!("--set {s}: the symbol name is missing (NAME=VALUE)").into());
            }
            let x = parse_value(v).map_err(|e| format!("--set {s}: {e}"))?;
            m.insert(k.to_string(), x);
        }
        Ok(m)
    }

    /// Load the robot's description with the `--set` values (each must name a symbol the file
    /// uses); what the loader warns about (physical consistency with those values, the
    /// reader's notes) is printed on standard error.
    pub fn description(
        &self,
    ) -> CliResult<(robodyn::model::RobotDescription, robodyn::io::SourceMap)> {
        let (desc, map) = self.read()?;
        print_warnings(&map);
        Ok((desc, map))
    }

    /// [`RobotArgs::description`] without printing the warnings.
    fn read(&self) -> CliResult<(robodyn::model::RobotDescription, robodyn::io::SourceMap)> {
        let (mut desc, mut map) = robodyn::io::load_description_mapped(&self.robot)?;
        let o = self.overrides()?;
        check_overrides(&desc, &o)?;
        robodyn::io::set_symbols(&mut desc, &mut map, &o);
        Ok((desc, map))
    }

    /// Load and validate the robot (all symbols need values). A motor-joint transmission with
    /// nonzero motor drive parameters is refused: only `identify` and `excite` apply it. The
    /// loader's warnings are printed once the robot is valid (an invalid one is an error that
    /// says why).
    pub fn load(&self) -> CliResult<Robot> {
        let (desc, map) = self.read()?;
        let robot = Robot::new(desc).map_err(|e| map.locate(e))?;
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
        print_warnings(&map);
        Ok(robot)
    }
}

/// The loader's warnings, one `robodyn: warning: FILE:LINE: link 3: ...` line each.
pub fn print_warnings(map: &robodyn::io::SourceMap) {
    for w in &map.warnings {
        eprintln!("robodyn: warning: {w}");
    }
}

/// `--set` names must be symbols of the robot (a misspelt `d3` for `D3` would be ignored).
pub fn check_overrides(
    desc: &robodyn::model::RobotDescription,
    o: &BTreeMap<String, f64>,
) -> CliResult {
    let known = known_symbols(desc);
    for k in o.keys() {
        if !known.contains(k) {
            let list: Vec<&str> = known.iter().map(String::as_str).collect();
            return Err(format!(
                "--set {k}=...: the robot has no symbol `{k}` (its symbols: {})",
                if list.is_empty() {
                    "none".to_string()
                } else {
                    list.join(", ")
                }
            )
            .into());
        }
    }
    Ok(())
}

/// One value of the command line: a number or a constant expression (`pi/8`, `-1e-3`), finite.
/// The same parser serves `--set`, `--q` and every other list.
pub fn parse_value(t: &str) -> Result<f64, String> {
    let t = t.trim();
    let e = robodyn::Expr::parse(t).map_err(|e| format!("`{t}` is not a number: {e}"))?;
    let x = e
        .eval(&|_| None)
        .map_err(|e| format!("`{t}` is not a constant number: {e}"))?;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("`{t}` is not finite"))
    }
}

/// Parse a comma-separated list of numbers (`--q 0.1,0.2,...`), each by [`parse_value`].
pub fn parse_list(name: &str, s: &str) -> CliResult<Vec<f64>> {
    s.split(',')
        .map(|t| parse_value(t).map_err(|e| format!("--{name}: {e}").into()))
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
    /// that is not a finite number is an error with its line); `-` is standard input.
    pub fn read(path: &Path) -> CliResult<Table> {
        let t = if robodyn::io::is_stdio(path) {
            let mut b = Vec::new();
            std::io::Read::read_to_end(&mut std::io::stdin().lock(), &mut b)
                .map_err(|e| format!("<stdin>: {e}"))?;
            robodyn::io::table::Table::parse(&b, "<stdin>")?
        } else {
            robodyn::io::table::Table::read(path)?
        };
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
    pub fn find(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }
}

/// Output format of tables.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum TableFormat {
    /// CSV with a header line, one row per state (numbers in the shortest form that reads back).
    #[default]
    Csv,
    /// JSON: an array of objects, one per row, keyed by column name.
    Json,
}

/// Where and how a command writes its table (`--output`, `--format`).
#[derive(Args, Debug, Clone)]
pub struct TableOutput {
    /// Output file (default or `-`: standard output).
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Format of the output table.
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
    check_finite(headers, rows)?;
    let mut out = create_output(path)?;
    match format {
        TableFormat::Csv => {
            writeln!(out, "{}", headers.join(","))?;
            // each number written in place (no string per number or per line)
            for r in rows {
                for (k, &x) in r.iter().enumerate() {
                    if k > 0 {
                        out.write_all(b",")?;
                    }
                    write!(out, "{}", Number(x))?;
                }
                out.write_all(b"\n")?;
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
    out.flush()?;
    Ok(())
}

pub use robodyn::simulation::format_number;
use robodyn::simulation::output::Number;

/// A result that is not a finite number is an error, never printed (a velocity of 1e200 or a
/// gravity of 1e308 overflows the model).
pub fn check_finite(headers: &[String], rows: &[Vec<f64>]) -> CliResult {
    for (k, r) in rows.iter().enumerate() {
        if let Some((c, x)) = r.iter().enumerate().find(|(_, x)| !x.is_finite()) {
            return Err(format!(
                "{}{} = {x}: the result is not a finite number (an input, a symbol value or the \
                 gravity is too large for the model's arithmetic); nothing was written",
                if rows.len() > 1 {
                    format!("row {}: ", k + 1)
                } else {
                    String::new()
                },
                headers.get(c).map_or("a value", String::as_str)
            )
            .into());
        }
    }
    Ok(())
}

/// An output file, or standard output for `None` or `-`.
pub fn create_output(path: Option<&Path>) -> CliResult<Box<dyn Write>> {
    Ok(match path {
        Some(p) if !robodyn::io::is_stdio(p) => Box::new(std::io::BufWriter::new(
            std::fs::File::create(p).map_err(|e| format!("{}: {e}", p.display()))?,
        )),
        _ => Box::new(std::io::BufWriter::new(std::io::stdout().lock())),
    })
}

/// Write text to a file, or to standard output for `None` or `-`.
pub fn write_text(path: Option<&Path>, text: &str) -> CliResult {
    match path {
        Some(p) if !robodyn::io::is_stdio(p) => {
            std::fs::write(p, text).map_err(|e| format!("{}: {e}", p.display()).into())
        }
        _ => print_out(text),
    }
}

/// Write text to standard output (a closed pipe is an error [`is_broken_pipe`] recognizes).
pub fn print_out(text: &str) -> CliResult {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())?;
    out.flush()?;
    Ok(())
}

/// Whether an error is a write to a closed pipe (`robodyn ... | head -1`): the command then
/// ends quietly.
pub fn is_broken_pipe(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut cur = Some(e);
    while let Some(e) = cur {
        if let Some(io) = e.downcast_ref::<std::io::Error>() {
            if io.kind() == std::io::ErrorKind::BrokenPipe {
                return true;
            }
        }
        if let Some(robodyn::Error::Io { source, .. }) = e.downcast_ref::<robodyn::Error>() {
            if source.kind() == std::io::ErrorKind::BrokenPipe {
                return true;
            }
        }
        cur = e.source();
    }
    false
}

/// How joint columns are named.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Names {
    /// By frame number: `q3`, `tau3` (the default, for every robot format).
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

/// The columns of an `--input` table that are not inputs (`t`, labels...), carried through to
/// the output in front of the results.
#[derive(Default)]
pub struct Carried {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<f64>>,
}

impl Carried {
    /// The output's headers and rows: the carried columns, then `headers`/`rows`.
    pub fn prepend(&self, headers: &[String], rows: Vec<Vec<f64>>) -> (Vec<String>, Vec<Vec<f64>>) {
        if self.headers.is_empty() {
            return (headers.to_vec(), rows);
        }
        let h = self.headers.iter().chain(headers).cloned().collect();
        let r = rows
            .into_iter()
            .zip(&self.rows)
            .map(|(r, c)| c.iter().copied().chain(r).collect())
            .collect();
        (h, r)
    }
}

/// Read states over `coords` from a CSV file (`input`, `-` for standard input, columns named by
/// `names`) or from the comma lists of the command line (`lists`). In both, the first quantity
/// (`q`) is required and the others default to zeros when absent (all their columns absent); the
/// missing columns are reported together. `what` names the joints in messages ("movable
/// joints", "actuated joints").
pub fn read_joint_states(
    input: Option<&Path>,
    prefixes: [&str; 3],
    lists: [Option<&str>; 3],
    coords: &robodyn::Coordinates,
    names: NamesArg,
    what: &str,
) -> CliResult<(States, Carried)> {
    let n = coords.len();
    if let Some(path) = input {
        let t = Table::read(path)?;
        let mut cols: [Vec<Option<usize>>; 3] = Default::default();
        let mut missing = Vec::new();
        for (i, prefix) in prefixes.iter().enumerate() {
            let wanted: Vec<String> = (0..n).map(|k| names.column(prefix, coords, k)).collect();
            cols[i] = wanted.iter().map(|w| t.find(w)).collect();
            // q is required; qd, qdd (tau) may be absent altogether (zeros), not in part
            if i == 0 || cols[i].iter().any(Option::is_some) {
                missing.extend(
                    wanted
                        .iter()
                        .zip(&cols[i])
                        .filter(|(_, c)| c.is_none())
                        .map(|(w, _)| format!("`{w}`")),
                );
            }
        }
        if !missing.is_empty() {
            return Err(format!(
                "{}: missing column{} {} (the {what} are {:?}; {} columns default to zero only \
                 when all of them are absent)",
                t.file,
                if missing.len() > 1 { "s" } else { "" },
                missing.join(", "),
                coords.frames(),
                prefixes[1..].join("/")
            )
            .into());
        }
        let used: std::collections::BTreeSet<usize> =
            cols.iter().flatten().flatten().copied().collect();
        let kept: Vec<usize> = (0..t.headers.len()).filter(|c| !used.contains(c)).collect();
        let carried = Carried {
            headers: kept.iter().map(|&c| t.headers[c].clone()).collect(),
            rows: t
                .rows
                .iter()
                .map(|r| kept.iter().map(|&c| r[c]).collect())
                .collect(),
        };
        let states = t
            .rows
            .iter()
            .map(|r| {
                std::array::from_fn(|i| cols[i].iter().map(|c| c.map_or(0.0, |c| r[c])).collect())
            })
            .collect();
        return Ok((states, carried));
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
    Ok((vec![s], Carried::default()))
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

/// `--timings` of the commands that evaluate a model on a state table.
#[derive(Args, Debug, Clone, Copy)]
pub struct TimingsArg {
    /// Print on stderr how long each phase took: loading the robot, reading and parsing the
    /// input, the model, formatting and writing the output.
    #[arg(long)]
    pub timings: bool,
}

/// Wall-clock time of a command's phases, printed on stderr by [`Phases::report`] when
/// `--timings` is given.
pub struct Phases {
    on: bool,
    start: std::time::Instant,
    last: std::time::Instant,
    done: Vec<(&'static str, std::time::Duration)>,
}

impl Phases {
    /// Start timing (now).
    pub fn start(arg: TimingsArg) -> Phases {
        let now = std::time::Instant::now();
        Phases {
            on: arg.timings,
            start: now,
            last: now,
            done: Vec::new(),
        }
    }

    /// The time since the previous phase ended was `phase`.
    pub fn lap(&mut self, phase: &'static str) {
        if self.on {
            let now = std::time::Instant::now();
            self.done.push((phase, now - self.last));
            self.last = now;
        }
    }

    /// `robodyn: timings (N rows, T threads): robot 1.2 ms, read 150.0 ms, ...` on stderr.
    pub fn report(&self, rows: usize) {
        if !self.on {
            return;
        }
        let ms = |d: std::time::Duration| format!("{:.1} ms", d.as_secs_f64() * 1e3);
        let parts: Vec<String> = self
            .done
            .iter()
            .map(|(p, d)| format!("{p} {}", ms(*d)))
            .collect();
        eprintln!(
            "robodyn: timings ({rows} rows, {} threads): {}, total {}",
            robodyn::batch::threads(),
            parts.join(", "),
            ms(self.start.elapsed())
        );
    }
}
