//! Identification of 100,000 samples of a 6-joint robot (the RX-90, 52 base parameters with
//! friction and rotor inertias): the log given with qd, qdd (parallel decimation and the
//! streamed triangular factors) and with positions only (zero-phase filtering and central
//! differences as well). Baseline measured in the same run: the regressor rows alone at every
//! sample (the part no implementation avoids).

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::identification::data::{MemoryLog, RawSample};
use robodyn::identification::excitation::FourierTrajectory;
use robodyn::identification::model_access::ModelAccess;
use robodyn::identification::parameters::{ParameterModel, ParameterOptions};
use robodyn::identification::{identify, Estimator, Options};
use robodyn::io::load_description;

const SAMPLES: usize = 100_000;

fn bench(c: &mut Criterion) {
    let path = std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../robots/rx90.toml"
    ));
    let mut acc = ModelAccess::new(load_description(path).unwrap()).unwrap();
    let n = acc.actuated_joints().len();
    let free: Vec<f64> = (0..n * 8)
        .map(|k| 0.8 * ((k * 37 % 17) as f64 / 8.0 - 1.0))
        .collect();
    let tr = FourierTrajectory::from_free(10.0, &vec![0.0; n], 5, &free);
    // 1 kHz for 100 s; torques by the inverse dynamic model
    let samples: Vec<RawSample> = (0..SAMPLES)
        .map(|k| {
            let t = k as f64 * 1e-3;
            let [q, qd, qdd] = tr.eval(t);
            let y = acc.inverse_dynamics(&q, &qd, &qdd).unwrap();
            RawSample {
                t,
                q,
                y,
                qd: Some(qd),
                qdd: Some(qdd),
            }
        })
        .collect();
    let with_derivatives = MemoryLog {
        name: "100k samples".into(),
        samples,
    };
    let positions_only = MemoryLog {
        name: "100k samples, positions".into(),
        samples: with_derivatives
            .samples
            .iter()
            .map(|s| RawSample {
                qd: None,
                qdd: None,
                ..s.clone()
            })
            .collect(),
    };
    let opt = Options {
        estimator: Estimator::Wls,
        ..Options::default()
    };
    let mut g = c.benchmark_group("identification");
    g.sample_size(10);
    let mut params = ParameterModel::build(&mut acc, &ParameterOptions::default()).unwrap();
    let p = params.count();
    g.bench_function("baseline_regressor_rows_100k", |b| {
        let mut rows = vec![0.0; n * p];
        let mut te = vec![0.0; n];
        b.iter(|| {
            for s in &with_derivatives.samples {
                params
                    .rows(
                        &mut acc,
                        &s.q,
                        s.qd.as_ref().unwrap(),
                        s.qdd.as_ref().unwrap(),
                        &mut rows,
                        &mut te,
                    )
                    .unwrap();
            }
            rows[0]
        })
    });
    g.bench_function("identify_100k_given_qd_qdd", |b| {
        b.iter(|| identify(&mut acc, &with_derivatives, &opt).unwrap().x[0])
    });
    g.bench_function("identify_100k_positions_filtered", |b| {
        b.iter(|| identify(&mut acc, &positions_only, &opt).unwrap().x[0])
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
