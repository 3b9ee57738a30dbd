//! Generated customized inverse dynamic model (Rust, numeric values substituted) against the
//! numeric Newton–Euler `rnea` on the SR400 (equivalent tree) and the RX-90.

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::testing::{random_state, rng};
use robodyn::{Robot, Workspace};
use std::hint::black_box;

mod robots {
    include!("generated/robots.rs");
}
mod gen_sr400 {
    include!("generated/sr400_idm.rs");
}
mod gen_rx90 {
    include!("generated/rx90_idm.rs");
}

type GenFn = fn(&[f64], &[f64], &[f64], &[f64], &mut [f64]);

fn bench_robot(c: &mut Criterion, label: &str, robot: Robot, f: GenFn) {
    let n = robot.nl();
    let [q, qd, qdd] = random_state(&mut rng(1), n);
    let model = robot.numeric();
    let mut ws = Workspace::new(model);
    let mut tau = vec![0.0; n];
    let mut out = vec![0.0; n];
    // same numbers (movable joints only in `out`; both robots have no fixed tree frame)
    rnea(model, &mut ws, &q, &qd, &qdd, &mut tau);
    f(&q, &qd, &qdd, &[], &mut out);
    for (a, b) in tau.iter().zip(&out) {
        assert!(
            (a - b).abs() <= 1e-9 * (1.0 + a.abs()),
            "{label}: {a} vs {b}"
        );
    }
    let mut g = c.benchmark_group(label);
    g.bench_function("rnea", |b| {
        b.iter(|| {
            rnea(
                model,
                &mut ws,
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                &mut tau,
            );
            black_box(&tau);
        })
    });
    g.bench_function("generated", |b| {
        b.iter(|| {
            f(
                black_box(&q),
                black_box(&qd),
                black_box(&qdd),
                black_box(&[]),
                &mut out,
            );
            black_box(&out);
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    bench_robot(
        c,
        "idm_sr400",
        Robot::new(robots::sr400_description()).unwrap(),
        gen_sr400::sr400_idm,
    );
    bench_robot(
        c,
        "idm_rx90",
        Robot::new(robots::rx90_description()).unwrap(),
        gen_rx90::rx90_idm,
    );
}

criterion_group!(generated, benches);
criterion_main!(generated);
