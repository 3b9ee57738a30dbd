//! Identification's library API on hostile or changing input (issue 24, items 3, 7 and 10): a
//! log that changes between reads is read once, the options are checked before any reading,
//! gains must be one per motor. Logs are simulated SCARA runs (friction, rotor inertias),
//! wrapped in sources that misbehave the way files and pipes do.

use robodyn::identification::data::{Effort, LogSource, MemoryLog, RawSample};
use robodyn::identification::excitation::{simulated_log, FourierTrajectory};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::{identify, EssentialOptions, Estimator, Options};
use robodyn::io::load_description;
use robodyn::{Error, Result};
use std::cell::Cell;
use std::path::PathBuf;

fn scara() -> ModelAccess {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/scara.toml");
    ModelAccess::new(load_description(&path).unwrap()).unwrap()
}

/// 8 s of the SCARA tracking a Fourier trajectory, sampled at 250 Hz (noise-free: every row
/// satisfies the direct model).
fn scara_log(acc: &ModelAccess) -> MemoryLog {
    let start = acc.reference_actuated().unwrap();
    let harmonics = 4;
    let free: Vec<f64> = (0..start.len() * FourierTrajectory::free_per_joint(harmonics))
        .map(|k| 0.5 * ((k as f64) * 1.3 + 0.4).sin())
        .collect();
    let tr = FourierTrajectory::from_free(4.0, &start, harmonics, &free);
    simulated_log(acc, &tr, 8.0, 0.004, 5.0).unwrap()
}

/// A file still being written: each read returns the samples written so far, and the writer
/// adds 20 % between two reads. Counts its reads.
struct Growing {
    all: MemoryLog,
    reads: Cell<usize>,
}

impl Growing {
    fn visible(&self, read: usize) -> usize {
        let n = self.all.samples.len();
        (n * (5 + read) / 7).min(n)
    }
}

impl LogSource for Growing {
    fn name(&self) -> String {
        "growing.csv".into()
    }
    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        let read = self.reads.get();
        self.reads.set(read + 1);
        for s in &self.all.samples[..self.visible(read)] {
            visit(s.clone())?;
        }
        Ok(())
    }
}

/// 24.7: a log growing between the passes was read twice (the report said 500,000 samples and
/// the fit used 600,000, the validation rows off): it is read once, and the result is that of
/// the samples of that read, whose count the report states.
#[test]
fn a_growing_log_is_read_once() {
    let mut acc = scara();
    let all = scara_log(&acc);
    let growing = Growing {
        all: all.clone(),
        reads: Cell::new(0),
    };
    let opt = Options {
        estimator: Estimator::Ols,
        ..Options::default()
    };
    let id = identify(&mut acc, &growing, &opt).unwrap();
    assert_eq!(growing.reads.get(), 1, "the log was read more than once");
    let first = growing.visible(0);
    assert_eq!(id.processing.samples, first);
    let same = MemoryLog {
        name: "first read".into(),
        samples: all.samples[..first].to_vec(),
    };
    let reference = identify(&mut acc, &same, &opt).unwrap();
    assert_eq!(id.x, reference.x);
    assert_eq!(id.processing.fit_samples, reference.processing.fit_samples);
    assert_eq!(
        id.processing.validation_samples,
        reference.processing.validation_samples
    );
    // the IDIM-IV passes read the recording too
    let growing = Growing {
        all,
        reads: Cell::new(0),
    };
    let iv = Options {
        estimator: Estimator::Iv,
        iv_iterations: 2,
        ..Options::default()
    };
    // noise-free: WLS weights are infinite; the error comes after the log was read once
    let _ = identify(&mut acc, &growing, &iv);
    assert_eq!(growing.reads.get(), 1);
}

/// A log of motor currents (the same samples, read as currents).
struct Currents(MemoryLog);

impl LogSource for Currents {
    fn name(&self) -> String {
        "currents.csv".into()
    }
    fn read(&self, visit: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
        self.0.read(visit)
    }
    fn effort(&self) -> Effort {
        Effort::Current
    }
    fn repeatable(&self) -> bool {
        true
    }
}

/// 24.3 and 24.5 in the library: gains one per motor (fewer panicked in the pass, more were
/// truncated), and only for currents.
#[test]
fn gains_are_checked() {
    let mut acc = scara();
    let log = scara_log(&acc);
    let currents = Currents(log.clone());
    let with = |g: &[f64]| Options {
        estimator: Estimator::Ols,
        gains: Some(g.to_vec()),
        ..Options::default()
    };
    for g in [&[1.0, 2.0][..], &[1.0; 5][..]] {
        match identify(&mut acc, &currents, &with(g)) {
            Err(Error::Input(m)) => assert!(
                m.contains(&format!("{} drive gains for 4 motors", g.len())),
                "{m}"
            ),
            other => panic!("{} gains: {:?}", g.len(), other.map(|id| id.x)),
        }
    }
    match identify(&mut acc, &log, &with(&[2.0; 4])) {
        Err(Error::Input(m)) => assert!(m.contains("not motor currents"), "{m}"),
        other => panic!("gains on torques: {:?}", other.map(|id| id.x)),
    }
    // gains 2 on currents that are the torques: every parameter doubled
    let ols = Options {
        estimator: Estimator::Ols,
        ..Options::default()
    };
    let plain = identify(&mut acc, &log, &ols).unwrap();
    let doubled = identify(&mut acc, &currents, &with(&[2.0; 4])).unwrap();
    for (a, b) in doubled.x.iter().zip(&plain.x) {
        assert!(
            (a - 2.0 * b).abs() <= 1e-8 * b.abs().max(1e-3),
            "{a} vs 2 x {b}"
        );
    }
}

/// 24.10 in the library: every number of the options is checked before the log is read (a
/// log whose read fails shows which comes first).
#[test]
fn options_are_checked_before_reading() {
    struct Unreadable;
    impl LogSource for Unreadable {
        fn name(&self) -> String {
            "unreadable".into()
        }
        fn read(&self, _: &mut dyn FnMut(RawSample) -> Result<()>) -> Result<()> {
            Err(Error::Input("read".into()))
        }
    }
    let mut acc = scara();
    let base = Options::default();
    let cases: Vec<(Options, &str)> = vec![
        (
            Options {
                iv_bandwidth: Some(0.0),
                ..base.clone()
            },
            "IDIM-IV tracking loop",
        ),
        (
            Options {
                iv_bandwidth: Some(f64::NAN),
                ..base.clone()
            },
            "IDIM-IV tracking loop",
        ),
        (
            Options {
                min_speed: Some(f64::NAN),
                ..base.clone()
            },
            "minimum speed",
        ),
        (
            Options {
                essential: Some(EssentialOptions {
                    max_relative_std: f64::NAN,
                    tolerance: 0.02,
                }),
                ..base.clone()
            },
            "essential parameters are dropped",
        ),
        (
            Options {
                essential: Some(EssentialOptions {
                    max_relative_std: 10.0,
                    tolerance: f64::NAN,
                }),
                ..base.clone()
            },
            "growth of the relative error",
        ),
        (
            Options {
                coulomb_band: Some(-1.0),
                ..base.clone()
            },
            "dead band",
        ),
        (
            Options {
                gains: Some(vec![1.0, f64::INFINITY]),
                ..base.clone()
            },
            "drive gain 2 of 2",
        ),
        (
            Options {
                iv_iterations: 0,
                ..base.clone()
            },
            "IDIM-IV iterations",
        ),
    ];
    for (opt, what) in cases {
        match identify(&mut acc, &Unreadable, &opt) {
            Err(Error::Input(m)) => assert!(m.contains(what), "{what}: {m}"),
            other => panic!("{what}: {:?}", other.map(|id| id.x)),
        }
    }
}

/// 24.2 (sizes before allocations): the validation rows kept for the plot grew with the log
/// (N (p + 1) numbers per decimated sample: 57 GB for 100 M samples of a 6-joint robot without
/// decimation); at most `MAX_KEPT_ROWS` are kept, evenly spaced over the segment.
#[test]
fn validation_rows_for_the_plot_are_bounded() {
    use robodyn::identification::observation::MAX_KEPT_ROWS;
    let mut acc = scara();
    let one = scara_log(&acc);
    let dt = one.samples[1].t - one.samples[0].t;
    // 25 copies end to end: 50,025 samples
    let samples: Vec<RawSample> = (0..25)
        .flat_map(|_| one.samples.iter())
        .enumerate()
        .map(|(k, s)| RawSample {
            t: k as f64 * dt,
            ..s.clone()
        })
        .collect();
    let count = samples.len();
    let long = MemoryLog {
        name: "long".into(),
        samples,
    };
    let opt = Options {
        estimator: Estimator::Ols,
        decimation: Some(1),
        validation: Some((0.1, 1.0)),
        keep_validation_rows: true,
        ..Options::default()
    };
    let id = identify(&mut acc, &long, &opt).unwrap();
    let kept = id.validation_rows.t.len();
    let segment = id.processing.validation_samples;
    eprintln!("{count} samples, {segment} in the validation segment, {kept} kept for the plot");
    assert!(segment > 2 * MAX_KEPT_ROWS, "{segment}");
    assert!(
        (MAX_KEPT_ROWS / 2..=MAX_KEPT_ROWS).contains(&kept),
        "{kept}"
    );
    // evenly spaced over the whole segment
    let span = id.validation_rows.t[kept - 1] - id.validation_rows.t[0];
    assert!(span > 0.99 * 0.9 * (count - 1) as f64 * dt, "{span}");
    assert_eq!(id.predicted_validation().len(), kept);
}
