//! A(q) by composite links and the two direct dynamic models, on random trees of 6 and 30 joints.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use nalgebra::DMatrix;
use robodyn::algorithms::direct_dynamics::{ddm_aba, ddm_composite};
use robodyn::algorithms::inertia_matrix::composite_inertia_matrix;
use robodyn::{direct_dynamics_into, Data, Method};
use robodyn_testing::{random_state, random_tree, rng, TreeOptions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("direct_dynamics");
    for n in [6usize, 30] {
        let mut r = rng(7 + n as u64);
        let robot = random_tree(&mut r, n, &TreeOptions::default());
        let model = robot.numeric();
        let [q, qd, tau] = random_state(&mut r, n);
        let mut ws = Data::new(&robot);
        let env = robot.environment();
        let mut a = DMatrix::zeros(n, n);
        g.bench_with_input(BenchmarkId::new("inertia_matrix", n), &n, |b, _| {
            b.iter(|| composite_inertia_matrix(model, &mut ws, black_box(&q), &mut a))
        });
        let mut qdd = vec![0.0; n];
        g.bench_with_input(BenchmarkId::new("composite_ltdl", n), &n, |b, _| {
            b.iter(|| {
                ddm_composite(model, &mut ws, env, black_box(&q), &qd, &tau, &mut qdd).unwrap()
            })
        });
        g.bench_with_input(BenchmarkId::new("articulated_body", n), &n, |b, _| {
            b.iter(|| ddm_aba(model, &mut ws, env, black_box(&q), &qd, &tau, &mut qdd).unwrap())
        });
        // the checked API over the movable joints (input checks, scatter/gather)
        let m = robot.dof();
        let [qm, qdm, taum] = [&q, &qd, &tau].map(|v| v[..m].to_vec());
        let mut qddm = vec![0.0; m];
        g.bench_with_input(
            BenchmarkId::new("direct_dynamics_into_aba", n),
            &n,
            |b, _| {
                b.iter(|| {
                    direct_dynamics_into(
                        &robot,
                        &mut ws,
                        env,
                        black_box(&qm),
                        &qdm,
                        &taum,
                        Method::ArticulatedBody,
                        &mut qddm,
                    )
                    .unwrap()
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
