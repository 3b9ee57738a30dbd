//! Options and helpers shared by the commands: loading a robot, reading and writing state tables.

use crate::output::Output;
pub use crate::output::{check_finite, write_table, write_text, TableFormat, TableWriter};
use clap::Args;
use robodyn::Robot;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

pub type CliResult<T = ()> = Result<T, Box<dyn std::error::Error>>;

/// The robot file and symbol overrides.
#[derive(Args, Debug, Clone)]
pub struct RobotArgs {
    /// Robot file (.toml, .par or .urdf; `-` reads standard input, format recognized from the
    /// text).
    pub robot: PathBuf,
    /// Give or override a symbol value, e.g. `--set d3=0.6` or `--set D3=pi/8`, or a standard
    /// parameter the file writes as a number, e.g. `--set M3=12` (mass of link 3 of a URDF robot)
    /// or `--set FS2=0.5` (repeatable; the name must be a symbol or a standard parameter of the
    /// robot, the value a constant expression as for `--q`).
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Make a URDF's root link the floating base (link 0 of a free-flyer root, Pinocchio's
    /// `JointModelFreeFlyer`): states then have nq = 7 + N positions (base position, quaternion
    /// x y z w, joints) and nv = 6 + N velocities. A .toml or .par file says it itself
    /// (`base = "floating"`, `is_floating = 1`).
    #[arg(long)]
    pub floating: bool,
}

impl RobotArgs {
    /// The `--set` values (names not yet checked against a robot: see [`Self::description`]).
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

    /// Load the robot's description with the `--set` values (the library's rule,
    /// `robodyn::io::set_values`: each names a symbol or a standard parameter of the robot);
    /// what the loader warns about (physical consistency with those values, the reader's notes)
    /// is printed on standard error.
    pub fn description(
        &self,
    ) -> CliResult<(robodyn::model::RobotDescription, robodyn::io::SourceMap)> {
        let (desc, map) = self.read()?;
        print_warnings(&map);
        Ok((desc, map))
    }

    /// [`RobotArgs::description`] without printing the warnings.
    fn read(&self) -> CliResult<(robodyn::model::RobotDescription, robodyn::io::SourceMap)> {
        let options = if self.floating {
            robodyn::io::LoadOptions::floating()
        } else {
            robodyn::io::LoadOptions::default()
        };
        let (mut desc, mut map) =
            robodyn::io::load_description_with_options(&self.robot, &BTreeMap::new(), &options)?;
        let o = self.overrides()?;
        robodyn::io::set_values_mapped(&mut desc, &mut map, &o)
            .map_err(|e| format!("--set: {e}"))?;
        Ok((desc, map))
    }

    /// Load and validate the robot (all symbols need values). The loader's warnings are
    /// printed once the robot is valid (an invalid one is an error that says why). A motor-joint
    /// `[transmission]` is part of the library's models (idm, ddm, inertia, simulate add the
    /// motors' reflected inertia and friction); [`transmission_note`] says so on stderr.
    pub fn load(&self) -> CliResult<Robot> {
        let (desc, map) = self.read()?;
        let robot = Robot::new(desc).map_err(|e| map.locate(e))?;
        print_warnings(&map);
        Ok(robot)
    }
}

/// With a motor-joint transmission whose motors have drive parameters: which side the torques
/// of `command` are on, one `robodyn: note:` line on stderr (the tables' columns stay `tau<j>`).
pub fn transmission_note(robot: &Robot, command: &str) {
    if robot.motor_drives().is_some_and(|d| !d.is_inert()) {
        eprintln!(
            "robodyn: note: {command}: {} has a motor-joint [transmission]: torques tau<j> are \
             joint-side (tau = R^T tau_motor); the model includes the motors' reflected rotor \
             inertia and friction, R^T (IA m_dd + FV m_d + FS sign(m_d)) with m = R q (IA, FS, \
             FV in motor units; A(q) has R^T IA R)",
            robot.name()
        );
    }
}

/// Refuse a robot whose transmission's motors have drive parameters in a command that does not
/// apply transmissions (`what`: the command), rather than read them as joint-side values.
pub fn refuse_motor_drives(robot: &Robot, path: &std::path::Path, what: &str) -> CliResult {
    robot
        .require_no_motor_drives(what)
        .map_err(|e| format!("{}: {e}", path.display()).into())
}

/// The loader's warnings, one `robodyn: warning: FILE:LINE: link 3: ...` line each.
pub fn print_warnings(map: &robodyn::io::SourceMap) {
    for w in &map.warnings {
        eprintln!("robodyn: warning: {w}");
    }
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

/// Parse a comma-separated list of numbers (`--q 0.1,0.2,...`), each by [`parse_value`]. An
/// empty entry (`1,,2`, a trailing or leading comma) is an error saying where.
pub fn parse_list(name: &str, s: &str) -> CliResult<Vec<f64>> {
    let parts: Vec<&str> = s.split(',').collect();
    let count = parts.len();
    parts
        .iter()
        .enumerate()
        .map(|(k, t)| {
            if t.trim().is_empty() {
                let place = match k {
                    0 if count == 1 => "no value given".to_string(),
                    0 => "a comma before the first value".to_string(),
                    k if k + 1 == count => format!("a trailing comma after value {k}"),
                    k => format!("no value between commas {k} and {}", k + 1),
                };
                return Err(format!(
                    "--{name} {s}: {place} (give one number per joint, separated by commas)"
                )
                .into());
            }
            parse_value(t).map_err(|e| format!("--{name}: {e}").into())
        })
        .collect()
}

/// `--output` and `--format` of the commands that write a table.
#[derive(Args, Debug, Clone)]
pub struct TableOutput {
    /// Output file (default or `-`: standard output), written all or nothing.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// Table format: csv (a header of column names, one row per line) or json (a list of
    /// objects keyed by column name).
    #[arg(long, value_enum, default_value = "csv")]
    pub format: TableFormat,
}

impl TableOutput {
    /// A table writer on `--output` with these columns.
    pub fn writer(&self, headers: Vec<String>) -> CliResult<TableWriter> {
        TableWriter::new(
            Output::create(self.output.as_deref())?,
            self.format,
            headers,
        )
    }
}

pub use robodyn::report::number::format_number;

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

/// The value parser of an option whose values are a library enum's (`--lang`, `--rotor`): the
/// enum's own list `all`, each value's `name` on the command line and its `help`, so that the
/// command line has no second list of the values.
pub fn choices<T: Copy + Send + Sync + 'static>(
    all: &'static [T],
    name: fn(T) -> &'static str,
    help: fn(T) -> &'static str,
) -> impl clap::builder::TypedValueParser<Value = T> {
    let values = all
        .iter()
        .map(|&v| clap::builder::PossibleValue::new(name(v)).help(help(v)));
    use clap::builder::TypedValueParser as _;
    clap::builder::PossibleValuesParser::new(values).map(move |s| {
        *all.iter()
            .find(|&&v| name(v) == s)
            .expect("clap accepts only the listed names")
    })
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

/// Say on stderr that a closed-chain state (`row` of a table, none for the command line's) is
/// near a singularity.
pub fn warn_conditioning(
    chain: &robodyn::ClosedChain,
    row: Option<usize>,
    c: &robodyn::Conditioning,
) {
    if c.warning {
        let which = row.map_or_else(String::new, |r| format!("row {r}: "));
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

/// A library error of row `row` of a chunk of states as the error of the table's row: the
/// chunk starts at state `first` (1-based).
pub fn in_table(e: robodyn::Error, first: usize) -> robodyn::Error {
    match e {
        robodyn::Error::Row { row, source } => robodyn::Error::Row {
            row: row + first - 1,
            source,
        },
        e => e,
    }
}

/// How many states a chunk of a table holds when each state gives `values` numbers: about 2
/// million numbers (16 MB) per chunk, whatever the table's length.
pub fn chunk_states(values: usize) -> usize {
    (CHUNK_VALUES / values.max(1)).max(1)
}

const CHUNK_VALUES: usize = 1 << 21;

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

    /// The time since the previous phase ended was `phase` (added to its total: a table read,
    /// evaluated and written in chunks goes through the phases once per chunk).
    pub fn lap(&mut self, phase: &'static str) {
        if self.on {
            let now = std::time::Instant::now();
            match self.done.iter_mut().find(|(p, _)| *p == phase) {
                Some((_, d)) => *d += now - self.last,
                None => self.done.push((phase, now - self.last)),
            }
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
