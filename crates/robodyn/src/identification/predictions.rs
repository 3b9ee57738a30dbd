//! The identified model's torques at every sample of a log, for a user to compare with the raw
//! measurement (a plot, an error over any segment): the rows of W at each sample, from the
//! positions filtered and differentiated as for the fit (or the log's qd, qdd), times the
//! identified parameters, plus the torques of the external wrenches. The samples are those
//! between the borders the identification drops (the zero-phase filter's settling at each end
//! and the first and last sample of the central differences): the same samples, and so the
//! same numbers, as the validation segment's raw-torque error of the report.

use super::data::LogSource;
use super::model_access::ModelAccess;
use super::observation::{run_prediction_pass, PredictionSink};
use super::{processing, read_once, Identification, Options};
use crate::error::{Error, Result};
use std::io::Write;

/// The model's torques of one log, at the log's rate.
#[derive(Clone, Debug, PartialEq)]
pub struct Predictions {
    /// The log (its name).
    pub source: String,
    /// Frame numbers of the joints, the columns of `tau`.
    pub joints: Vec<usize>,
    /// Time of each sample (s, the log's).
    pub t: Vec<f64>,
    /// Torques, one row of N per sample (N m or N; joint side, as the log's `tau<j>`).
    pub tau: Vec<Vec<f64>>,
}

impl Predictions {
    /// CSV: a header `t,tau<j>...` (j the frame numbers), then one line per sample, every number
    /// in its shortest round-trip form (read back, the same doubles).
    pub fn write_csv(&self, out: &mut dyn Write) -> Result<()> {
        write_csv_header(out, &self.joints)?;
        for (t, tau) in self.t.iter().zip(&self.tau) {
            write_csv_row(out, *t, tau)?;
        }
        Ok(())
    }
}

/// The header line of the predictions' CSV.
pub fn write_csv_header(out: &mut dyn Write, joints: &[usize]) -> Result<()> {
    let mut line = String::from("t");
    for j in joints {
        line.push_str(&format!(",tau{j}"));
    }
    line.push('\n');
    out.write_all(line.as_bytes())
        .map_err(|e| Error::io("the predictions", e))
}

/// One line of the predictions' CSV.
pub fn write_csv_row(out: &mut dyn Write, t: f64, tau: &[f64]) -> Result<()> {
    let mut line = format!("{t:?}");
    for v in tau {
        line.push_str(&format!(",{v:?}"));
    }
    line.push('\n');
    out.write_all(line.as_bytes())
        .map_err(|e| Error::io("the predictions", e))
}

/// Send the model's torques of every sample of `log` (between the borders) to `sink` as (t,
/// tau): `id` is the identification of `access`'s robot with the options `opt` (the same
/// processing: filter, differences, Coulomb dead band). The log is read again (once, recorded
/// unless it is repeatable): a stream the identification consumed is an input error. Returns
/// the number of samples.
pub fn predict(
    access: &mut ModelAccess,
    id: &Identification,
    log: &dyn LogSource,
    opt: &Options,
    sink: &mut dyn FnMut(f64, &[f64]) -> Result<()>,
) -> Result<usize> {
    let mut model = id.model.clone();
    if model.joints != access.actuated_joints() || id.robot != access.name() {
        return Err(Error::Input(format!(
            "the identification is of {} (joints {:?}), not of {} (joints {:?})",
            id.robot,
            model.joints,
            access.name(),
            access.actuated_joints()
        )));
    }
    let (summary, recording) = read_once(log, model.joints_count())?;
    let source: &dyn LogSource = match &recording {
        Some(r) => r,
        None => log,
    };
    let (proc, _) = processing(&summary, opt)?;
    model.coulomb_band = proc.coulomb_band;
    let predict = PredictionSink { x: &id.x, sink };
    run_prediction_pass(source, &mut model, access, &proc, predict)
}

/// The model's torques of every sample of `log` (see [`predict`]), collected.
pub fn predictions(
    access: &mut ModelAccess,
    id: &Identification,
    log: &dyn LogSource,
    opt: &Options,
) -> Result<Predictions> {
    let (mut t, mut tau) = (Vec::new(), Vec::new());
    predict(access, id, log, opt, &mut |s, v| {
        t.push(s);
        tau.push(v.to_vec());
        Ok(())
    })?;
    Ok(Predictions {
        source: log.name(),
        joints: access.actuated_joints().to_vec(),
        t,
        tau,
    })
}
