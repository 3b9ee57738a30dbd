//! `robodyn identify ROBOT --data log.csv`: base parameters (and friction, rotor inertias,
//! offsets) identified from measured positions and torques, with their relative standard
//! deviations, the condition number and the per-joint errors; optionally a fit plot on a
//! validation segment and a physically consistent robot file.

use crate::common::{choices, parse_list, parse_value, CliResult, RobotArgs};
use robodyn::algorithms::regressor::RotorMode;
use robodyn::identification::data::{CsvLog, Effort, JointLabels, LogSource};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::parameters::ParameterOptions;
use robodyn::identification::predictions::{predict, write_csv_header, write_csv_row};
use robodyn::identification::{
    identify_from_statistics, identify_logs, report, statistics::statistics, EssentialOptions,
    Estimator, Identification, Options, Statistics,
};
use std::path::{Path, PathBuf};

#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Text for reading: processing, the parameter table (units, values, standard deviations,
    /// grouping equations), per-joint errors, warnings.
    Text,
    /// JSON: every value as a full double, with the processing and the validation.
    Json,
    /// CSV of the parameters: name, value, std, relative_std, equation, unit.
    Csv,
}

#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub robot: RobotArgs,
    /// Log (CSV): t, q<j>, tau<j> (or i<j> with --gains), optionally qd<j>, qdd<j>; j the frame
    /// number of each actuated joint, or `_<name>` with the joint's name; `-`: standard input.
    /// Repeated (`--data a.csv --data b.csv`): several logs of the robot, identified together
    /// (each processed on its own, one least-squares problem).
    #[arg(long, required_unless_present = "merge")]
    pub data: Vec<PathBuf>,
    /// Write the sufficient statistics of the logs (JSON) to this file instead of identifying:
    /// `identify --merge` identifies from the statistics of many logs, computed anywhere.
    #[arg(long, value_name = "FILE.json", conflicts_with_all = ["merge", "output", "plot", "write_robot", "strict"])]
    pub partial: Option<PathBuf>,
    /// Identify from statistics files written by `--partial` (of this robot, with the same
    /// parameter and processing options), merged: the numbers of `--data` with all their logs.
    #[arg(long, value_name = "FILE.json", num_args = 1.., conflicts_with_all = ["data", "plot"])]
    pub merge: Vec<PathBuf>,
    /// Estimator of the parameters.
    #[arg(long, default_value = "wls",
          value_parser = choices(&Estimator::ALL, Estimator::key, Estimator::describe))]
    pub estimator: Estimator,
    /// Identify under the physical-consistency constraints (pseudo-inertia PSD, friction and
    /// rotor inertia >= 0), solved as an SDP.
    #[arg(long)]
    pub consistent: bool,
    /// Which rotor inertias are parameters (as base-params).
    #[arg(long, default_value = "actuated", value_parser = choices(&RotorMode::ALL, RotorMode::name, RotorMode::describe))]
    pub rotor: RotorMode,
    /// Leave out the Coulomb and viscous friction.
    #[arg(long)]
    pub no_friction: bool,
    /// With a transmission, identify the motors' drive parameters only (without the joint-side
    /// inertia and friction of the joints a motor's terms do not span, e.g. the TX40's joint 6).
    #[arg(long)]
    pub no_joint_drives: bool,
    /// Add a constant torque offset per joint.
    #[arg(long)]
    pub offsets: bool,
    /// Also report the essential parameters.
    #[arg(long)]
    pub essential: bool,
    /// Essential parameters: drop parameters while the largest relative std is above this (%).
    #[arg(long, default_value_t = 10.0, value_parser = positive)]
    pub essential_max_std: f64,
    /// Essential parameters: ... and the relative error grows by less than this fraction.
    #[arg(long, default_value_t = 0.02, value_parser = non_negative)]
    pub essential_tolerance: f64,
    /// Joint-space bandwidth of the robot's dynamics (Hz): the filter and decimation defaults
    /// follow from it.
    #[arg(long, default_value_t = robodyn::identification::DEFAULT_BANDWIDTH, value_parser = positive)]
    pub bandwidth: f64,
    /// Cut-off of the zero-phase position low-pass (Hz; default 10 x bandwidth, at most 0.4 x
    /// the sample rate).
    #[arg(long, value_parser = positive)]
    pub cutoff: Option<f64>,
    /// Order of the position low-pass.
    #[arg(long, default_value_t = 4)]
    pub filter_order: usize,
    /// Decimation factor (default: the decimation low-pass, 0.8 x the new Nyquist frequency, at
    /// twice the position cut-off, or at 10 x bandwidth where the log gives qd, qdd).
    #[arg(long)]
    pub decimation: Option<usize>,
    /// Samples dropped at each end (default: the settling time of the position filter).
    #[arg(long)]
    pub border: Option<usize>,
    /// Validation segment as fractions of the log, FROM:TO (default 0.8:1), or `none`.
    #[arg(long, default_value = "0.8:1")]
    pub validation: String,
    /// Differentiate the filtered positions even when the log has qd, qdd.
    #[arg(long)]
    pub differentiate: bool,
    /// Drive gains (torque per ampere), one per motor, when the log has currents i<j>.
    #[arg(long, allow_hyphen_values = true)]
    pub gains: Option<String>,
    /// Leave out a joint's rows where |qd_j| is below this (rad/s or m/s; default 0.005 when qd
    /// is differentiated from the positions, 0 when the log gives qd).
    #[arg(long, value_parser = non_negative)]
    pub min_speed: Option<f64>,
    /// Dead band of the Coulomb friction's sign (rad/s or m/s): sign(qd) is 0 where |qd| is at
    /// most this (default 3e-3 when qd is differentiated from the positions, 0 when the log
    /// gives qd).
    #[arg(long, value_parser = non_negative)]
    pub coulomb_band: Option<f64>,
    /// IDIM-IV: iterations.
    #[arg(long, default_value_t = 8)]
    pub iv_iterations: usize,
    /// IDIM-IV: bandwidth of the tracking loop of the simulation (Hz; default bandwidth / 4).
    #[arg(long, value_parser = positive)]
    pub iv_bandwidth: Option<f64>,
    /// Seed of the numerical base-parameter method's random states.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Format of the report.
    #[arg(long, value_enum, default_value = "text")]
    pub format: Format,
    /// Write the report to a file instead of standard output.
    #[arg(long)]
    pub output: Option<PathBuf>,
    /// SVG plot of measured and predicted torques on the validation segment, one panel per
    /// joint.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Write the identified model's torques at every sample of the log (CSV `t,tau<j>...` at
    /// the log's rate, from the filtered positions as in the fit; the samples between the
    /// borders) to compare with the measured torques. With several `--data` logs, one file per
    /// log, in their order (`--predictions a.csv --predictions b.csv`).
    #[arg(long, value_name = "FILE.csv", conflicts_with_all = ["merge", "partial"])]
    pub predictions: Vec<PathBuf>,
    /// Write a physically consistent robot file (.toml) with the identified parameters.
    #[arg(long, value_name = "FILE.toml")]
    pub write_robot: Option<PathBuf>,
    /// Exit with an error (code 1) when the report has warnings.
    #[arg(long)]
    pub strict: bool,
    /// Identify the drive gains (torque per unit of current) with the parameters: the --data
    /// logs have motor currents i<j>; --reference fixes the scale.
    #[arg(long, requires = "reference",
          conflicts_with_all = ["gains", "partial", "merge", "plot", "write_robot", "consistent", "essential", "payload"])]
    pub estimate_gains: bool,
    /// With --estimate-gains: logs of the same robot fixing the gains' scale, either with joint
    /// torques tau<j>, or with currents i<j> and the known payload of --known-payload.
    #[arg(long, value_name = "LOG.csv", requires = "estimate_gains")]
    pub reference: Vec<PathBuf>,
    /// With --estimate-gains: the payload carried in the --reference logs of currents,
    /// LINK:XX,XY,XZ,YY,YZ,ZZ,MX,MY,MZ,M (about O_LINK in R_LINK; kg m^2, kg m, kg).
    #[arg(
        long,
        value_name = "LINK:XX,..,M",
        requires = "estimate_gains",
        allow_hyphen_values = true
    )]
    pub known_payload: Option<String>,
    /// Identify the payload carried on link LINK in the --data logs (its 10 standard
    /// parameters XX..M about O_LINK in R_LINK), the robot's parameters those of the robot file,
    /// or, with --before, identified from logs without the payload too.
    #[arg(long, value_name = "LINK",
          conflicts_with_all = ["gains", "partial", "merge", "plot", "write_robot", "consistent", "essential"])]
    pub payload: Option<usize>,
    /// With --payload: logs of the robot without the payload (before/after identification).
    #[arg(long, value_name = "LOG.csv", requires = "payload")]
    pub before: Vec<PathBuf>,
}

/// A finite positive number (a constant expression as every value of the command line).
pub fn positive(s: &str) -> Result<f64, String> {
    let x = parse_value(s)?;
    if x > 0.0 {
        Ok(x)
    } else {
        Err(format!("{x}: a positive number expected"))
    }
}

/// A finite number >= 0.
fn non_negative(s: &str) -> Result<f64, String> {
    let x = parse_value(s)?;
    if x >= 0.0 {
        Ok(x)
    } else {
        Err(format!("{x}: a number >= 0 expected"))
    }
}

/// `--gains`: one per motor, and only for a log of motor currents.
fn check_gains(gains: Option<&[f64]>, log: &CsvLog, motors: usize) -> CliResult {
    match (gains, log.effort()) {
        (None, Effort::Current) => Err(format!(
            "{}: the log has motor currents (i<j>): give --gains (one per motor) to convert them \
             to torques",
            log.name()
        )
        .into()),
        (Some(_), Effort::Torque) => Err(format!(
            "{}: --gains given but the log has joint torques (tau<j>), not motor currents \
             (i<j>): the gains would scale the torques; leave --gains out",
            log.name()
        )
        .into()),
        (Some(g), _) if g.len() != motors => Err(format!(
            "--gains has {} values for {motors} motors: one per motor",
            g.len()
        )
        .into()),
        _ => Ok(()),
    }
}

fn parse_validation(s: &str) -> CliResult<Option<(f64, f64)>> {
    if s == "none" {
        return Ok(None);
    }
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("--validation {s}: expected FROM:TO (fractions) or none"))?;
    let f = |v: &str| -> CliResult<f64> {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("--validation {s}: `{v}` is not a number").into())
    };
    Ok(Some((f(a)?, f(b)?)))
}

pub fn run(a: Args) -> CliResult {
    crate::output::check_distinct(&[
        ("--output", a.output.as_deref()),
        ("--plot", a.plot.as_deref()),
        ("--write-robot", a.write_robot.as_deref()),
        ("--partial", a.partial.as_deref()),
    ])?;
    check_predictions(&a)?;
    let desc = a.robot.description()?.0;
    let mut access = ModelAccess::new(desc)?;
    if a.estimate_gains || a.payload.is_some() {
        return joint::run(&a, &mut access);
    }
    let gains = a
        .gains
        .as_deref()
        .map(|g| parse_list("gains", g))
        .transpose()?;
    let opt = options(&a, gains.clone())?;
    let mut logs = Vec::new();
    let id = if a.merge.is_empty() {
        let labels = JointLabels {
            numbers: access.actuated_joints().to_vec(),
            names: access.joint_names(),
        };
        logs = a
            .data
            .iter()
            .map(|d| CsvLog::open(d, &labels))
            .collect::<Result<Vec<_>, _>>()?;
        for log in &logs {
            check_gains(gains.as_deref(), log, labels.numbers.len())?;
        }
        if let Some(p) = &a.partial {
            return write_partial(p, &mut access, &logs, &opt);
        }
        let refs: Vec<&dyn LogSource> = logs.iter().map(|l| l as &dyn LogSource).collect();
        identify_logs(&mut access, &refs, &opt)?
    } else {
        let parts = a
            .merge
            .iter()
            .map(|p| read_statistics(p))
            .collect::<CliResult<Vec<_>>>()?;
        identify_from_statistics(&mut access, &parts, &opt)?
    };
    let text = match a.format {
        Format::Text => report::to_text(&id),
        Format::Json => format!("{}\n", serde_json::to_string_pretty(&report::to_json(&id))?),
        Format::Csv => report::to_csv(&id),
    };
    let predictions = write_predictions(&a.predictions, &mut access, &id, (&logs, &opt))?;
    write_files(&a, &access, &id, &text, predictions)?;
    for p in [&a.plot, &a.write_robot]
        .into_iter()
        .flatten()
        .chain(&a.predictions)
    {
        eprintln!("wrote {}", p.display());
    }
    // the warnings once: in the report when it goes to standard output with them (text, JSON),
    // else on standard error
    let report_shows = a.output.as_deref().is_none_or(robodyn::io::is_stdio)
        && matches!(a.format, Format::Text | Format::Json);
    if !report_shows {
        for w in &id.warnings {
            eprintln!("robodyn: warning: {w}");
        }
    }
    for h in id.warnings.iter().filter_map(crate::hint::warning_hint) {
        eprintln!("robodyn: hint: {h}");
    }
    if a.strict && !id.warnings.is_empty() {
        return Err(format!(
            "--strict: the identification has {} warning(s)",
            id.warnings.len()
        )
        .into());
    }
    Ok(())
}

/// `--predictions`: one file per `--data` log, each a file (read again), none standard output,
/// distinct from the other outputs; checked before any work.
fn check_predictions(a: &Args) -> CliResult {
    if a.predictions.is_empty() {
        return Ok(());
    }
    if a.predictions.len() != a.data.len() {
        return Err(format!(
            "--predictions given {} time(s) for {} --data log(s): one predictions file per log,              in the order of the logs",
            a.predictions.len(),
            a.data.len()
        )
        .into());
    }
    if let Some(p) = a.predictions.iter().find(|p| robodyn::io::is_stdio(p)) {
        return Err(format!(
            "--predictions {}: a file name expected (the report may go to standard output)",
            p.display()
        )
        .into());
    }
    if a.data.iter().any(|d| robodyn::io::is_stdio(d)) {
        return Err("--predictions reads the log again: give the log as a file, not as                     standard input (--data -)"
            .into());
    }
    // a predictions file must not replace a log
    for d in &a.data {
        for p in &a.predictions {
            crate::output::check_distinct(&[("--data", Some(d)), ("--predictions", Some(p))])?;
        }
    }
    let mut named: Vec<(String, Option<&Path>)> = a
        .predictions
        .iter()
        .enumerate()
        .map(|(k, p)| (format!("--predictions ({})", k + 1), Some(p.as_path())))
        .collect();
    named.extend([
        ("--output".to_string(), a.output.as_deref()),
        ("--plot".to_string(), a.plot.as_deref()),
        ("--write-robot".to_string(), a.write_robot.as_deref()),
    ]);
    let refs: Vec<(&str, Option<&Path>)> = named.iter().map(|(n, p)| (n.as_str(), *p)).collect();
    crate::output::check_distinct(&refs)
}

/// The predictions of each log written to its file (temporary files, put in place with the
/// other outputs).
fn write_predictions(
    paths: &[PathBuf],
    access: &mut ModelAccess,
    id: &Identification,
    (logs, opt): (&[CsvLog], &Options),
) -> CliResult<Vec<crate::output::Output>> {
    let mut files = Vec::with_capacity(paths.len());
    for (path, log) in paths.iter().zip(logs) {
        let mut out = crate::output::Output::create(Some(path))?;
        let w = out.writer();
        write_csv_header(w, access.actuated_joints())?;
        predict(access, id, log, opt, &mut |t, tau| write_csv_row(w, t, tau))?;
        files.push(out);
    }
    Ok(files)
}

/// `--partial`: the statistics of the logs, merged, written as JSON (all or nothing).
fn write_partial(
    path: &Path,
    access: &mut ModelAccess,
    logs: &[CsvLog],
    opt: &Options,
) -> CliResult {
    let parts = logs
        .iter()
        .map(|log| statistics(access, log, opt))
        .collect::<Result<Vec<_>, _>>()?;
    let stats = Statistics::merged(&parts)?;
    crate::output::write_text(Some(path), &format!("{}\n", stats.to_json()))?;
    eprintln!(
        "wrote {}: the statistics of {} ({} rows of the fit)",
        path.display(),
        robodyn::identification::statistics::sources(&stats.logs),
        stats.rows()
    );
    Ok(())
}

/// A statistics file of `--merge`.
fn read_statistics(path: &Path) -> CliResult<Statistics> {
    let text =
        std::fs::read_to_string(path).map_err(|e| format!("--merge {}: {e}", path.display()))?;
    Ok(Statistics::from_json(&text, &path.display().to_string())?)
}

/// The identification's options of the command line.
fn options(a: &Args, gains: Option<Vec<f64>>) -> CliResult<Options> {
    Ok(Options {
        parameters: ParameterOptions {
            rotors: a.rotor,
            friction: !a.no_friction,
            offsets: a.offsets,
            joint_drives: !a.no_joint_drives,
            seed: a.seed,
        },
        estimator: a.estimator,
        consistent: a.consistent,
        standard: a.write_robot.is_some(),
        consistency_solver: Default::default(),
        essential: a.essential.then_some(EssentialOptions {
            max_relative_std: a.essential_max_std,
            tolerance: a.essential_tolerance,
        }),
        bandwidth: a.bandwidth,
        cutoff: a.cutoff,
        filter_order: a.filter_order,
        decimation: a.decimation,
        border: a.border,
        validation: parse_validation(&a.validation)?,
        use_log_derivatives: !a.differentiate,
        gains,
        min_speed: a.min_speed,
        coulomb_band: a.coulomb_band,
        iv_iterations: a.iv_iterations,
        iv_bandwidth: a.iv_bandwidth,
        keep_validation_rows: a.plot.is_some(),
    })
}

/// The report, the fit plot and the identified robot file: all or nothing, the files put in
/// place once all are written.
fn write_files(
    a: &Args,
    access: &ModelAccess,
    id: &Identification,
    text: &str,
    predictions: Vec<crate::output::Output>,
) -> CliResult {
    let mut files = vec![crate::output::Output::create(a.output.as_deref())?];
    files.extend(predictions);
    files[0].write_all(text.as_bytes())?;
    if let Some(p) = &a.plot {
        let mut plot = crate::output::Output::create(Some(p))?;
        plot.write_by_path(|tmp| report::plot_fit(tmp, id))?;
        files.push(plot);
    }
    if let Some(p) = &a.write_robot {
        let mut desc = access.description_with(&id.standard_parameters())?;
        desc.name = format!("{} (identified)", desc.name);
        desc.notes.push(format!(
            "Identified by robodyn identify from {} ({}): physically consistent standard \
             parameters (pseudo-inertia PSD per link, drive parameters >= 0), the constrained \
             least-squares fit, at squared Mahalanobis distance {:.3} from the unconstrained \
             estimate.",
            robodyn::identification::statistics::sources(&id.logs),
            id.estimator,
            id.consistent.as_ref().map_or(0.0, |c| c.distance2)
        ));
        let mut robot = crate::output::Output::create(Some(p))?;
        let format = robodyn::io::Format::from_path(p)?;
        let text = robodyn::io::description_text(&desc, format)?;
        robot.write_all(text.as_bytes())?;
        files.push(robot);
    }
    crate::output::commit_all(files)
}

/// `--estimate-gains` and `--payload`: the joint problems of the drive gains and of a payload.
mod joint {
    use super::{options, Args, Format};
    use crate::common::{parse_list, CliResult};
    use robodyn::identification::data::{CsvLog, Effort, JointLabels, LogSource};
    use robodyn::identification::gains::{identify_gains, GainIdentification, GainReference};
    use robodyn::identification::model_access::ModelAccess;
    use robodyn::identification::payload::{
        identify_payload, Estimate, PayloadIdentification, PayloadLogs,
    };
    use robodyn::model::param::unit;
    use std::fmt::Write;
    use std::path::PathBuf;

    pub fn run(a: &Args, access: &mut ModelAccess) -> CliResult {
        if a.format == Format::Csv {
            return Err(
                "--estimate-gains and --payload report as text or JSON (--format csv \
                        is for the parameter table of identify)"
                    .into(),
            );
        }
        let opt = options(a, None)?;
        let labels = JointLabels {
            numbers: access.actuated_joints().to_vec(),
            names: access.joint_names(),
        };
        let open = |paths: &[PathBuf]| -> CliResult<Vec<CsvLog>> {
            Ok(paths
                .iter()
                .map(|d| CsvLog::open(d, &labels))
                .collect::<Result<Vec<_>, _>>()?)
        };
        let data = open(&a.data)?;
        let text = if a.estimate_gains {
            let reference = open(&a.reference)?;
            let id = gains(a, access, (&refs(&data), refs(&reference)), &opt)?;
            match a.format {
                Format::Json => gains_json(&id),
                _ => gains_text(&id),
            }
        } else {
            let link = a.payload.expect("--payload");
            let before = open(&a.before)?;
            let logs = if before.is_empty() {
                PayloadLogs::Known(refs(&data))
            } else {
                PayloadLogs::BeforeAfter {
                    before: refs(&before),
                    after: refs(&data),
                }
            };
            let id = identify_payload(access, link, &logs, &opt)?;
            match a.format {
                Format::Json => payload_json(&id),
                _ => payload_text(&id, !before.is_empty()),
            }
        };
        crate::output::write_text(a.output.as_deref(), &text)
    }

    fn refs(logs: &[CsvLog]) -> Vec<&dyn LogSource> {
        logs.iter().map(|l| l as &dyn LogSource).collect()
    }

    fn gains(
        a: &Args,
        access: &mut ModelAccess,
        (data, reference): (&[&dyn LogSource], Vec<&dyn LogSource>),
        opt: &robodyn::identification::Options,
    ) -> CliResult<GainIdentification> {
        for log in data {
            if log.effort() != Effort::Current {
                return Err(format!(
                    "{}: --estimate-gains needs logs of motor currents (i<j> columns) as --data",
                    log.name()
                )
                .into());
            }
        }
        let currents = reference.iter().all(|l| l.effort() == Effort::Current);
        let reference = match (&a.known_payload, currents) {
            (Some(p), true) => {
                let (link, values) = p.split_once(':').ok_or_else(|| {
                    format!("--known-payload {p}: LINK:XX,XY,XZ,YY,YZ,ZZ,MX,MY,MZ,M expected")
                })?;
                let link: usize = link
                    .trim()
                    .parse()
                    .map_err(|_| format!("--known-payload {p}: `{link}` is not a link number"))?;
                let v = parse_list("known-payload", values)?;
                let parameters: [f64; 10] = v.try_into().map_err(|v: Vec<f64>| {
                    format!(
                        "--known-payload {p}: {} values, 10 expected (XX,XY,XZ,YY,YZ,ZZ,MX,MY,MZ,M)",
                        v.len()
                    )
                })?;
                GainReference::Payload {
                    link,
                    parameters,
                    logs: reference,
                }
            }
            (None, false) if reference.iter().all(|l| l.effort() == Effort::Torque) => {
                GainReference::Torques(reference)
            }
            (None, _) => {
                return Err(
                    "--reference: logs of joint torques (tau<j>) expected, or logs of \
                            currents with --known-payload"
                        .into(),
                )
            }
            (Some(_), false) => {
                return Err(
                    "--known-payload: the --reference logs must have currents (i<j>), \
                            carrying that payload"
                        .into(),
                )
            }
        };
        Ok(identify_gains(access, data, &reference, opt)?)
    }

    fn rel(v: f64, s: f64) -> String {
        if v == 0.0 {
            "inf".into()
        } else {
            format!("{:.2}", 100.0 * s / v.abs())
        }
    }

    fn gains_text(id: &GainIdentification) -> String {
        let mut s = format!(
            "Drive gains of {} identified with its parameters ({}), scale from {}\n\n",
            id.robot, id.estimator, id.reference
        );
        let _ = writeln!(
            s,
            "{:<8} {:<14} {:>14} {:>11} {:>9}",
            "gain", "joint", "value", "std", "rel.std %"
        );
        for k in 0..id.gains.len() {
            let _ = writeln!(
                s,
                "{:<8} {:<14} {:>14.6e} {:>11.3e} {:>9}",
                format!("g{}", id.joints[k]),
                id.joint_names[k],
                id.gains[k],
                id.gains_std[k],
                rel(id.gains[k], id.gains_std[k])
            );
        }
        let _ = writeln!(
            s,
            "\n(torque per unit of current: N m or N per unit of the i<j> columns)\n\
             condition number {:.4e} (unit columns); residual RMS {:.4e} over {} rows; \
             std inflation for the decimation {:.3}\n\nparameters:",
            id.condition_number, id.residual_rms, id.rows, id.std_inflation
        );
        let _ = writeln!(
            s,
            "{:<10} {:>14} {:>11} {:>9}  equation",
            "parameter", "value", "std", "rel.std %"
        );
        for (k, p) in id.parameters.iter().enumerate() {
            let _ = writeln!(
                s,
                "{:<10} {:>14.6e} {:>11.3e} {:>9}  {}",
                p.name,
                id.x[k],
                id.std[k],
                rel(id.x[k], id.std[k]),
                p.equation
            );
        }
        s
    }

    fn gains_json(id: &GainIdentification) -> String {
        format!(
            "{}\n",
            serde_json::to_string_pretty(&id.to_json()).expect("json")
        )
    }

    fn estimate_line(s: &mut String, e: &Estimate, unit: &str) {
        let _ = match (e.value, e.std) {
            (Some(v), Some(sd)) => writeln!(
                s,
                "{:<10} {:<8} {:>14.6e} {:>11.3e} {:>9}",
                e.name,
                unit,
                v,
                sd,
                rel(v, sd)
            ),
            _ => writeln!(
                s,
                "{:<10} {:<8} {:>14} {:>11} {:>9}",
                e.name, unit, "not identifiable", "-", "-"
            ),
        };
    }

    fn payload_text(id: &PayloadIdentification, before_after: bool) -> String {
        let mut s = format!(
            "Payload on link {} of {} ({}; {}): its standard parameters about O_{} in R_{}\n\n",
            id.link,
            id.robot,
            id.estimator,
            if before_after {
                "identified with the robot's parameters from logs before and after"
            } else {
                "the robot's parameters those of the robot file"
            },
            id.link,
            id.link
        );
        let _ = writeln!(
            s,
            "{:<10} {:<8} {:>14} {:>11} {:>9}",
            "parameter", "unit", "value", "std", "rel.std %"
        );
        for (k, e) in id.payload.iter().enumerate() {
            estimate_line(&mut s, e, unit(k, false));
        }
        let _ = writeln!(
            s,
            "\nidentifiable: {} of 10 combinations change the torques at all (rank of the \
             link's columns in the base parameters), {} of 10 determined by these logs \
             (relative singular-value tolerance {:e})",
            id.structural_rank, id.rank, id.tolerance
        );
        for c in &id.structural_null {
            let _ = writeln!(s, "  never in the torques: {c}");
        }
        if id.rank < 10 {
            for c in &id.undetermined {
                let _ = writeln!(s, "  not determined: {c}");
            }
        }
        let _ = writeln!(
            s,
            "condition number {:.4e} (unit columns); relative error {:.4e} over {} rows",
            id.condition_number, id.relative_error, id.rows
        );
        if !id.others.is_empty() {
            let _ = writeln!(s, "\nalso identified:");
            for e in &id.others {
                estimate_line(&mut s, e, "");
            }
        }
        s
    }

    fn payload_json(id: &PayloadIdentification) -> String {
        format!(
            "{}\n",
            serde_json::to_string_pretty(&id.to_json()).expect("json")
        )
    }
}
