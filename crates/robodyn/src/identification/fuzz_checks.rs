//! The properties the identification fuzz targets (`fuzz/`: `log`, `options`) check on every
//! input, shared with the test that replays the inputs they found
//! (`tests/fuzz_regressions.rs`). Each function panics when a property fails, which is what a
//! fuzzer reports; an error returned by the library is a correct answer to bad input.

use super::data::{record, CsvLog, JointLabels, LogSource, MemoryLog, MAX_MAGNITUDE};
use super::excitation::{simulated_log, FourierTrajectory};
use super::model_access::ModelAccess;
use super::parameters::ParameterOptions;
use super::{identify, EssentialOptions, Estimator, Identification, Options, Rotors};
use crate::model::RobotDescription;
use std::sync::OnceLock;

/// A planar arm with two revolute joints (frames 1 and 2, names `a` and `b`), gravity in its
/// plane, friction and rotor inertias: the robot of the fuzzed logs (`t, q1, q2, tau1, tau2`,
/// optionally `qd<j>`, `qdd<j>`, or currents `i<j>`).
const ROBOT: &str = r#"
name = "fuzz 2R"
gravity = [0, -9.81, 0]
[[frame]]
j = 1
name = "a"
ant = 0
[[frame]]
j = 2
name = "b"
ant = 1
d = 0.4
[[link]]
j = 1
XX = 0.01
YY = 0.2
ZZ = 0.21
MX = 0.6
M = 3
IA = 0.1
FS = 0.5
FV = 1
[[link]]
j = 2
XX = 0.005
YY = 0.08
ZZ = 0.085
MX = 0.3
M = 1.5
IA = 0.05
FS = 0.3
FV = 0.5
"#;

fn robot() -> &'static RobotDescription {
    static DESC: OnceLock<RobotDescription> = OnceLock::new();
    DESC.get_or_init(|| {
        crate::io::toml_format::parse_description(ROBOT, Some("fuzz.toml"))
            .expect("the fuzz robot")
            .0
    })
}

fn access() -> ModelAccess {
    ModelAccess::new(robot().clone()).expect("the fuzz robot")
}

/// A log of the robot: 3 s at 200 Hz of PD tracking of a Fourier trajectory, with qd, qdd.
fn clean_log() -> &'static MemoryLog {
    static LOG: OnceLock<MemoryLog> = OnceLock::new();
    LOG.get_or_init(|| {
        let acc = access();
        let free: Vec<f64> = (0..2 * FourierTrajectory::free_per_joint(4))
            .map(|k| 0.6 * ((k as f64) * 1.9 + 0.3).sin())
            .collect();
        let tr = FourierTrajectory::from_free(3.0, &[0.0, 0.0], 4, &free);
        simulated_log(&acc, &tr, 3.0, 0.005, 5.0).expect("the fuzz log")
    })
}

/// What an accepted identification must satisfy: finite estimates, standard deviations and
/// errors, one fit per joint, the samples read once.
fn check_identification(id: &Identification, samples: usize) {
    assert!(id.x.iter().all(|x| x.is_finite()), "estimate {:?}", id.x);
    assert!(
        id.std.iter().all(|s| s.is_finite() && *s >= 0.0),
        "std {:?}",
        id.std
    );
    assert!(id.relative_error.is_finite(), "relative error");
    assert!(id.condition_number.is_finite() && id.condition_number >= 1.0 - 1e-9);
    assert_eq!(id.per_joint.len(), 2);
    assert_eq!(id.processing.samples, samples);
    if let Some(v) = &id.validation {
        assert!(v.relative_error.is_finite() && v.raw_relative_error.is_finite());
    }
}

/// A log of any bytes for the 2R robot: the reader accepts it or refuses it with an error (never
/// panics, never holds a line longer than the bound); an accepted log, recorded, has the
/// summary's count of samples, each with two finite positions and torques of bounded magnitude
/// at increasing times; identification (OLS, and WLS on odd-length inputs) on it succeeds with
/// finite numbers or returns an error.
pub fn check_log(data: &[u8]) {
    let labels = JointLabels {
        numbers: vec![1, 2],
        names: vec!["a".into(), "b".into()],
    };
    let Ok(log) = CsvLog::from_reader("fuzz.csv", std::io::Cursor::new(data.to_vec()), &labels)
    else {
        return;
    };
    let Ok((summary, recording)) = record(&log, 2) else {
        return;
    };
    assert!(summary.samples >= 2 && summary.dt.is_finite() && summary.dt > 0.0);
    let mut count = 0;
    let mut last = f64::NEG_INFINITY;
    recording
        .read(&mut |s| {
            count += 1;
            assert!(s.t > last, "time {} after {last}", s.t);
            last = s.t;
            assert_eq!((s.q.len(), s.y.len()), (2, 2));
            assert_eq!(s.qd.is_some(), summary.has_derivatives);
            let values = s.q.iter().chain(&s.y).chain(s.qd.iter().flatten());
            assert!(values
                .chain(s.qdd.iter().flatten())
                .all(|v| v.is_finite() && v.abs() <= MAX_MAGNITUDE));
            Ok(())
        })
        .expect("a recording reads back");
    assert_eq!(count, summary.samples);
    let opt = Options {
        estimator: if data.len().is_multiple_of(2) {
            Estimator::Ols
        } else {
            Estimator::Wls
        },
        gains: (log.effort() == super::data::Effort::Current).then(|| vec![2.0, 0.5]),
        ..Options::default()
    };
    if let Ok(id) = identify(&mut access(), &recording, &opt) {
        check_identification(&id, summary.samples);
    }
}

/// Bytes read as the fields of [`Options`] (then zeros when they run out).
struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        let k = N.min(self.0.len());
        out[..k].copy_from_slice(&self.0[..k]);
        self.0 = &self.0[k..];
        out
    }
    fn byte(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn flag(&mut self) -> bool {
        self.byte() & 1 == 1
    }
    /// A number: any bit pattern, a small fraction, a special value or a moderate one.
    fn float(&mut self) -> f64 {
        const SPECIAL: [f64; 10] = [
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e-300,
            1e300,
            f64::MIN_POSITIVE,
            1.0,
            -1.0,
        ];
        match self.byte() % 4 {
            0 => f64::from_bits(u64::from_le_bytes(self.take())),
            1 => f64::from(i16::from_le_bytes(self.take())) / 64.0,
            2 => SPECIAL[usize::from(self.byte()) % SPECIAL.len()],
            _ => f64::from(u16::from_le_bytes(self.take())) / 1000.0,
        }
    }
    fn maybe_float(&mut self) -> Option<f64> {
        if self.flag() {
            Some(self.float())
        } else {
            None
        }
    }
    fn count(&mut self) -> usize {
        usize::from(u16::from_le_bytes(self.take()))
    }
}

/// Options decoded from any bytes (every field, any value).
fn options(data: &[u8]) -> Options {
    let mut b = Bytes(data);
    Options {
        parameters: ParameterOptions {
            rotors: [Rotors::Actuated, Rotors::All, Rotors::None][usize::from(b.byte() % 3)],
            friction: b.flag(),
            offsets: b.flag(),
            seed: u64::from(b.byte()),
            ..ParameterOptions::default()
        },
        estimator: [Estimator::Ols, Estimator::Wls, Estimator::Iv][usize::from(b.byte() % 3)],
        consistent: false,
        consistency_solver: Default::default(),
        standard: false,
        essential: b.flag().then(|| EssentialOptions {
            max_relative_std: b.float(),
            tolerance: b.float(),
        }),
        bandwidth: b.float(),
        cutoff: b.maybe_float(),
        filter_order: usize::from(b.byte() % 16),
        decimation: b.flag().then(|| b.count()),
        border: b.flag().then(|| b.count() * 16),
        validation: b.flag().then(|| (b.float(), b.float())),
        use_log_derivatives: b.flag(),
        gains: b
            .flag()
            .then(|| (0..b.byte() % 4).map(|_| b.float()).collect()),
        min_speed: b.maybe_float(),
        // IDIM-IV passes simulate the log: a few are enough to reach every branch
        iv_iterations: usize::from(b.byte() % 4),
        iv_bandwidth: b.maybe_float(),
        keep_validation_rows: b.flag(),
        coulomb_band: b.maybe_float(),
    }
}

/// Options of any values on a valid log of the 2R robot: their validation accepts or refuses
/// them (never panics), and identification with accepted options succeeds with finite numbers
/// or returns an error. Options refused by the validation are refused by identification too,
/// before the log is read.
pub fn check_options(data: &[u8]) {
    let opt = options(data);
    let log = clean_log();
    let valid = opt.validate();
    let result = identify(&mut access(), log, &opt);
    match (valid, result) {
        (Ok(()), Ok(id)) => check_identification(&id, log.samples.len()),
        (Ok(()), Err(_)) => {}
        (Err(e), Ok(_)) => panic!("options refused ({e}) but identification ran"),
        (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The checks pass on the clean log, as text, and on options that run every estimator.
    #[test]
    fn checks_run_on_valid_inputs() {
        let log = clean_log();
        let mut text = String::from("t,q1,q2,qd1,qd2,qdd1,qdd2,tau1,tau2\n");
        for s in &log.samples {
            let qd = s.qd.as_ref().unwrap();
            let qdd = s.qdd.as_ref().unwrap();
            text.push_str(&format!(
                "{},{},{},{},{},{},{},{},{}\n",
                s.t, s.q[0], s.q[1], qd[0], qd[1], qdd[0], qdd[1], s.y[0], s.y[1]
            ));
        }
        check_log(text.as_bytes());
        let labels = JointLabels {
            numbers: vec![1, 2],
            names: vec!["a".into(), "b".into()],
        };
        let parsed =
            CsvLog::from_reader("t", std::io::Cursor::new(text.into_bytes()), &labels).unwrap();
        let id = identify(
            &mut access(),
            &parsed,
            &Options {
                estimator: Estimator::Ols,
                ..Options::default()
            },
        )
        .unwrap();
        assert!(id.relative_error < 1e-8, "{}", id.relative_error);
        for estimator in 0..3u8 {
            // actuated rotors, friction, no offsets, seed 1, the estimator, no essential
            // parameters, bandwidth 10 (u16 / 1000), default cut-off, order 4, defaults,
            // the log's derivatives, no gains, min speed 0, 2 IV iterations, defaults
            let mut bytes = vec![0, 1, 0, 1, estimator, 0, 3];
            bytes.extend(10000u16.to_le_bytes());
            bytes.extend([0, 4, 0, 0, 0, 1, 0, 1, 2, 0, 2, 0, 0, 0]);
            let opt = options(&bytes);
            assert_eq!(opt.bandwidth, 10.0);
            assert_eq!((opt.filter_order, opt.iv_iterations), (4, 2));
            assert_eq!(opt.min_speed, Some(0.0));
            opt.validate().unwrap();
            check_options(&bytes);
        }
    }
}
