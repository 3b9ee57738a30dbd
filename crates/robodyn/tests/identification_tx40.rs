//! Identification on real data: a Stäubli TX40 log (45,000 samples at 5 kHz, joint side,
//! coupled wrist), read in place from the project's shared data (`shared/data/tx40/`, found by
//! walking up from this crate). Without it the test is skipped visibly, or
//! fails where `ROBODYN_REQUIRE` requires the `shared` check (CI: `tests/common/harness.rs`).

use robodyn::identification::data::{CsvLog, JointLabels};
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::{identify, Options};
use robodyn::io::load_description;
use std::path::PathBuf;

fn data() -> Option<PathBuf> {
    crate::harness::shared(
        "data/tx40/tx40_joint.csv",
        "identification on the real TX40 log",
    )
}

/// The bundled TX40 (with its transmission) and its log (None, skipped visibly, without the
/// shared data).
fn tx40() -> Option<(ModelAccess, CsvLog)> {
    let path = data()?;
    let robot = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/tx40.toml");
    let acc = ModelAccess::new(load_description(&robot).unwrap()).unwrap();
    let labels = JointLabels {
        numbers: acc.actuated_joints().to_vec(),
        names: acc.joint_names(),
    };
    let log = CsvLog::open(&path, &labels).unwrap();
    Some((acc, log))
}

/// The README's command: WLS, constant offsets, validation on 60..80 % of the log. The real
/// robot's torques are explained to within the per-joint errors measured when this test was
/// written (6.0, 6.5, 8.6, 9.2, 11.4, 11.0 % with issue 31's defaults) with margin; the gravity
/// parameter of link 2, MXR2 = MX2 + 0.225 (M3 + M4 + M5 + M6), lies within 15 % of its value
/// from the URDF's (CAD) masses, 2.40 kg m: it comes out 2.12 with this segment held out and
/// 2.12 to 2.34 over the five held-out fifths of the log (2.18 to 2.49 with the earlier
/// defaults), a spread of +-5 % that a tighter bound on one run would not respect; friction and
/// rotor inertias are positive and well identified; the consistent robot is found.
#[test]
fn tx40_real_log() {
    let Some((mut acc, log)) = tx40() else { return };
    let mut opt = Options {
        validation: Some((0.6, 0.8)),
        standard: true,
        ..Options::default()
    };
    opt.parameters.offsets = true;
    let id = identify(&mut acc, &log, &opt).unwrap();
    let pr = &id.processing;
    assert_eq!(pr.samples, 45000);
    assert!((pr.sample_rate - 5000.0).abs() < 1e-6, "{}", pr.sample_rate);
    assert_eq!(pr.decimation, 20);
    eprintln!(
        "TX40: condition {:.2}, relative error {:.2} % (validation {:.2} %)",
        id.condition_number,
        100.0 * id.relative_error,
        100.0 * id.validation.as_ref().unwrap().relative_error
    );
    assert!(id.condition_number < 50.0);
    assert!(id.relative_error < 0.1);
    assert!(id.validation.as_ref().unwrap().relative_error < 0.15);
    for f in &id.per_joint {
        eprintln!("  joint {}: {:.2} %", f.joint, 100.0 * f.relative_error);
        assert!(
            f.relative_error < 0.2,
            "joint {}: {}",
            f.joint,
            f.relative_error
        );
    }
    let value = |name: &str| {
        let k = id.parameters.iter().position(|p| p.name == name).unwrap();
        (id.x[k], id.relative_std[k])
    };
    let urdf = id.model.values(&acc.standard_parameters());
    let k = id.parameters.iter().position(|p| p.name == "MXR2").unwrap();
    let (mx, _) = value("MXR2");
    eprintln!("MXR2 {mx:.4} (URDF masses {:.4})", urdf[k]);
    assert!((mx / urdf[k] - 1.0).abs() < 0.15);
    for j in 1..=6 {
        let (fv, fv_std) = value(&format!("FV{j}"));
        let (fs, fs_std) = value(&format!("FS{j}"));
        assert!(fv > 0.0 && fv_std < 10.0, "FV{j} {fv} ({fv_std} %)");
        assert!(fs > 0.0 && fs_std < 10.0, "FS{j} {fs} ({fs_std} %)");
    }
    for j in 3..=6 {
        let (ia, ia_std) = value(&format!("IA{j}"));
        assert!(ia > 0.0 && ia_std < 30.0, "IA{j} {ia} ({ia_std} %)");
    }
    let c = id.consistent.as_ref().unwrap();
    assert!(c.min_pseudo_inertia_eigenvalue > -1e-9 && c.min_inertia_eigenvalue > 0.0);
}

/// The consistent fit of the README's TX40 run by the interior-point solver equals Clarabel's
/// (feature `sdp`): identified vectors to 1e-6 relative, squared Mahalanobis distances to 1e-6
/// when Clarabel reports "Solved"; on this log it stops with "AlmostSolved" (reduced
/// accuracy): then the interior point's fit is at least as good and the vectors agree to 1e-2
/// (measured: squared distance 12.96546 against 12.97444, vectors 5e-3 apart).
#[cfg(feature = "sdp")]
#[test]
fn tx40_interior_point_and_clarabel_agree() {
    use robodyn::identification::consistency::Solver;
    let Some((mut acc, log)) = tx40() else { return };
    let mut run = |solver| {
        let mut opt = Options {
            consistent: true,
            standard: true,
            consistency_solver: solver,
            ..Options::default()
        };
        opt.parameters.offsets = true;
        identify(&mut acc, &log, &opt).unwrap()
    };
    // identify's whole run, timed only to print it (speed is measured by benchmarks)
    let timed = |run: &mut dyn FnMut(Solver) -> robodyn::identification::Identification, solver| {
        let t = std::time::Instant::now();
        let id = run(solver);
        (id, t.elapsed().as_secs_f64())
    };
    let (ipm, t_ipm) = timed(&mut run, Solver::InteriorPoint);
    let (cl, t_cl) = timed(&mut run, Solver::Clarabel);
    eprintln!("TX40 identify --consistent: {t_ipm:.3} s (interior point), {t_cl:.3} s (Clarabel)");
    let (a, b) = (ipm.consistent.unwrap(), cl.consistent.unwrap());
    let scale = cl.x.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let dx = ipm
        .x
        .iter()
        .zip(&cl.x)
        .map(|(x, y)| (x - y).abs() / y.abs().max(1e-3 * scale))
        .fold(0.0, f64::max);
    let dd = (a.distance2 - b.distance2).abs() / b.distance2.max(1.0);
    eprintln!(
        "TX40 consistent: distance^2 {:.6e} vs {:.6e}, max relative difference of x {dx:.1e}; \
         {} | {}",
        a.distance2, b.distance2, a.solver, b.solver
    );
    if b.solver.contains("Solved in") && !b.solver.contains("AlmostSolved") {
        assert!(dx < 1e-6, "x differs by {dx:e}");
        assert!(dd < 1e-6, "objective differs by {dd:e}");
    } else {
        // Clarabel stopped with reduced accuracy: the interior point's fit is no worse
        assert!(
            a.distance2 <= b.distance2 * (1.0 + 1e-6) + 1e-9,
            "worse fit"
        );
        assert!(dx < 1e-2, "x differs by {dx:e}");
    }
}

/// Issue 30, item 5: the last 20 % of the log, mostly at rest, predicted with the parameters
/// fitted on the first 80 %. With sign(qd) of the differentiated velocity, rounding noise at
/// rest flipped the Coulomb friction between -FS and +FS: the raw torques of the segment were
/// predicted with a relative error of 0.439 (a reference with a dead band of 1e-3 rad/s:
/// 0.233). The default processing (dead band 3e-3 rad/s where the velocities are estimated;
/// issue 31's cross-validated defaults) meets the reference's 0.233; the exact sign (band 0)
/// is still available and still flips the friction at rest (0.391 with the other defaults).
#[test]
fn tx40_coulomb_dead_band_at_rest() {
    let Some((mut acc, log)) = tx40() else { return };
    let raw_error = |band: Option<f64>, acc: &mut ModelAccess| {
        let mut opt = Options {
            validation: Some((0.8, 1.0)),
            coulomb_band: band,
            ..Options::default()
        };
        opt.parameters.offsets = true;
        let id = identify(acc, &log, &opt).unwrap();
        assert_eq!(
            id.processing.coulomb_band,
            band.unwrap_or(robodyn::identification::DEFAULT_COULOMB_BAND)
        );
        let v = id.validation.unwrap();
        eprintln!(
            "band {band:?}: raw-torque error on 0.8:1 {:.4} (decimated {:.4})",
            v.raw_relative_error, v.relative_error
        );
        v.raw_relative_error
    };
    let default = raw_error(None, &mut acc);
    let exact = raw_error(Some(0.0), &mut acc);
    assert!(default <= 0.233, "default dead band: {default}");
    // measured: 0.391 with the exact sign and the other defaults, 1.68 x the default's
    assert!(
        exact > 1.5 * default,
        "exact sign: {exact} (dead band {default})"
    );
}

/// The raw log read by its own route (the CSV text split by hand): t and tau1..tau6.
fn raw_torques(path: &std::path::Path) -> (Vec<f64>, Vec<[f64; 6]>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| h.trim() == name).unwrap();
    let t_col = col("t");
    let tau_cols: Vec<usize> = (1..=6).map(|j| col(&format!("tau{j}"))).collect();
    let (mut t, mut tau) = (Vec::new(), Vec::new());
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let v: Vec<f64> = line.split(',').map(|x| x.trim().parse().unwrap()).collect();
        t.push(v[t_col]);
        tau.push(std::array::from_fn(|k| v[tau_cols[k]]));
    }
    (t, tau)
}

/// Global and per-joint ||tau_measured - tau_predicted|| / ||tau_measured|| over the samples
/// of the predictions in [from, to) (fractions of the log's duration), matched to the log's
/// samples by their time.
fn held_out_errors(
    (t, tau): (&[f64], &[[f64; 6]]),
    p: &robodyn::identification::predictions::Predictions,
    (from, to): (f64, f64),
) -> (f64, Vec<f64>, usize) {
    let d = t[t.len() - 1] - t[0];
    let (lo, hi) = (
        t[0] + from * d,
        if to >= 1.0 {
            f64::INFINITY
        } else {
            t[0] + to * d
        },
    );
    let (mut err, mut norm) = ([0.0f64; 6], [0.0f64; 6]);
    let mut count = 0;
    let mut i = 0;
    for (tp, pred) in p.t.iter().zip(&p.tau) {
        while t[i] < *tp {
            i += 1;
        }
        assert_eq!(t[i], *tp, "a predicted sample at a time of the log");
        if *tp < lo || *tp >= hi {
            continue;
        }
        count += 1;
        for k in 0..6 {
            err[k] += (tau[i][k] - pred[k]).powi(2);
            norm[k] += tau[i][k].powi(2);
        }
    }
    let global = (err.iter().sum::<f64>() / norm.iter().sum::<f64>()).sqrt();
    let joints = (0..6).map(|k| (err[k] / norm[k]).sqrt()).collect();
    (global, joints, count)
}

/// Issue 31, item 5: the predictions of the default run (WLS, offsets) at every sample of the
/// log, compared with the raw 5 kHz torques read by another route, give the held-out errors of
/// the report (the validation's raw-torque errors, from the least-squares factors) to 1e-9,
/// for both held-out segments; every predicted value is finite, one per sample between the
/// borders. The errors meet issue 31's targets (a reference implementation's): global at most
/// 0.173 on 0.6:0.8 and 0.233 on 0.8:1, each joint on 0.6:0.8 within 1.05 x the reference's.
#[test]
fn tx40_predictions_reproduce_held_out_errors() {
    let Some((mut acc, log)) = tx40() else { return };
    let raw = raw_torques(&data().unwrap());
    let reference_joints = [0.187, 0.154, 0.175, 0.107, 0.394, 0.221];
    for (segment, target) in [((0.6, 0.8), 0.173), ((0.8, 1.0), 0.233)] {
        let mut opt = Options {
            validation: Some(segment),
            ..Options::default()
        };
        opt.parameters.offsets = true;
        let id = identify(&mut acc, &log, &opt).unwrap();
        let p =
            robodyn::identification::predictions::predictions(&mut acc, &id, &log, &opt).unwrap();
        let border = id.processing.border;
        // central differences lose one sample at each end, the borders `border` more
        assert_eq!(p.t.len(), 45000 - 2 - 2 * border);
        assert!(p.tau.iter().flatten().all(|v| v.is_finite()));
        let (global, joints, count) = held_out_errors((&raw.0, &raw.1), &p, segment);
        let v = id.validation.as_ref().unwrap();
        eprintln!(
            "held out {segment:?}: {count} samples, raw-torque error {global:.4} (report {:.4}), \
             joints {}",
            v.raw_relative_error,
            joints
                .iter()
                .map(|e| format!("{e:.3}"))
                .collect::<Vec<_>>()
                .join(" ")
        );
        assert!((global - v.raw_relative_error).abs() < 1e-9);
        for (e, f) in joints.iter().zip(&v.raw_per_joint) {
            assert!((e - f.relative_error).abs() < 1e-9);
        }
        assert!(global <= target, "{segment:?}: {global} > {target}");
        if segment == (0.6, 0.8) {
            for (j, (e, r)) in joints.iter().zip(reference_joints).enumerate() {
                assert!(*e <= 1.05 * r, "joint {}: {e} > 1.05 x {r}", j + 1);
            }
        }
    }
}
