//! Batch inverse dynamics (`robodyn::batch`) of 100,000 UR5 states on 1 thread and on 2 threads
//! (the issue-18 goal: at least 1.8x the single-core throughput on this 2-core machine).
//!
//! The UR5 URDF comes from example-robot-data (`pip install example-robot-data`; found through
//! `python3`) or `ROBODYN_UR5=path/ur5_robot.urdf`; without it the bundled rx90.urdf (6 joints
//! too) stands in, said on stderr.
//!
//! `cargo bench -p robodyn --bench batch -- --warm-up-time 2 --measurement-time 10`

use criterion::{criterion_group, criterion_main, Criterion};
use rand::Rng;
use robodyn::{inverse_dynamics_batch, Robot};
use std::hint::black_box;
use std::path::PathBuf;
use std::process::Command;

const STATES: usize = 100_000;

fn ur5() -> (String, Robot) {
    let from_python = || {
        let out = Command::new("python3")
            .args([
                "-c",
                "import cmeel, os; print(os.path.join(os.path.dirname(os.path.dirname(\
                 cmeel.__file__)), 'cmeel.prefix', 'share', 'example-robot-data', 'robots', \
                 'ur_description', 'urdf', 'ur5_robot.urdf'))",
            ])
            .output()
            .ok()?;
        let p = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
        p.is_file().then_some(p)
    };
    let path = std::env::var_os("ROBODYN_UR5")
        .map(PathBuf::from)
        .or_else(from_python);
    match path {
        Some(p) => ("ur5".into(), robodyn::io::load(&p).expect("UR5 URDF loads")),
        None => {
            eprintln!("batch bench: UR5 URDF not found, timing the bundled rx90.urdf instead");
            let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/rx90.urdf");
            (
                "rx90".into(),
                robodyn::io::load(&p).expect("rx90.urdf loads"),
            )
        }
    }
}

fn bench(c: &mut Criterion) {
    let (name, robot) = ur5();
    let n = robot.dof();
    let mut r = robodyn_testing::rng(1);
    let mut v = |s: f64| {
        (0..STATES * n)
            .map(|_| r.random_range(-s..s))
            .collect::<Vec<f64>>()
    };
    let (q, qd, qdd) = (v(3.0), v(2.0), v(5.0));
    let mut tau = vec![0.0; STATES * n];
    let env = robot.environment();
    let mut group = c.benchmark_group(format!("batch_idm_{name}_100k"));
    group.sample_size(20);
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        group.bench_function(format!("threads_{threads}"), |b| {
            b.iter(|| {
                pool.install(|| {
                    inverse_dynamics_batch(&robot, env, black_box(&q), &qd, &qdd, &mut tau)
                })
                .unwrap();
                black_box(&tau);
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
