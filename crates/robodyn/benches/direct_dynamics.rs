//! A(q) by composite links and the two direct dynamic models, on random trees of 6 and 30 joints.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::DMatrix;
use robodyn::algorithms::direct_dynamics::{ddm_aba, ddm_composite, DirectWorkspace};
use robodyn::algorithms::inertia_matrix::{inertia_matrix_into, InertiaWorkspace};
use robodyn::testing::{random_state, random_tree, rng, TreeOptions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("direct_dynamics");
    for n in [6usize, 30] {
        let mut r = rng(7 + n as u64);
        let robot = random_tree(&mut r, n, &TreeOptions::default());
        let model = robot.numeric();
        let [q, qd, tau] = random_state(&mut r, n);
        let mut iws = InertiaData::from_model(model);
        let mut a = DMatrix::zeros(n, n);
        g.bench_with_input(BenchmarkId::new("inertia_matrix", n), &n, |b, _| {
            b.iter(|| inertia_matrix_into(model, &mut iws, black_box(&q), &mut a))
        });
        let mut ws = DirectData::from_model(model);
        let mut qdd = vec![0.0; n];
        g.bench_with_input(BenchmarkId::new("composite_ltdl", n), &n, |b, _| {
            b.iter(|| ddm_composite(model, &mut ws, black_box(&q), &qd, &tau, &mut qdd).unwrap())
        });
        g.bench_with_input(BenchmarkId::new("articulated_body", n), &n, |b, _| {
            b.iter(|| ddm_aba(model, &mut ws, black_box(&q), &qd, &tau, &mut qdd).unwrap())
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
