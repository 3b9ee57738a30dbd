//! Inverse dynamic model benchmarks: `rnea` with a reused `Data` (the kernel), the checked
//! `inverse_dynamics_into`, the allocating `inverse_dynamics`, and the Lagrangian route (hyper-dual AD, O(n^2)) as
//! baselines, on the SR400's equivalent tree (8 links) and a random 30-joint tree.
//!
//! Short run: `cargo bench -p robodyn --bench inverse_dynamics -- --warm-up-time 1 --measurement-time 3`

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use robodyn::algorithms::energy::lagrangian_torques;
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::{inverse_dynamics, inverse_dynamics_into};
use robodyn::{Data, Robot};
use robodyn_testing::{self as testing, random_state, random_tree, TreeOptions};
use std::hint::black_box;
use std::path::PathBuf;

fn robots() -> Vec<(&'static str, Robot)> {
    let sr400 = robodyn::io::load(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml"),
    )
    .expect("robots/sr400.toml loads");
    // All 30 joints movable (revolute or prismatic), branching, general frames, friction and
    // wrenches: the worst case of the generator.
    let opt = TreeOptions {
        p_fixed: 0.0,
        ..TreeOptions::default()
    };
    let tree30 = random_tree(&mut testing::rng(30), 30, &opt);
    vec![("sr400_tree", sr400), ("random_tree_30", tree30)]
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("inverse_dynamics");
    for (name, robot) in robots() {
        let n = robot.nl();
        let [q, qd, qdd] = random_state(&mut testing::rng(1), n);
        let mut ws = Data::new(&robot);
        let mut tau = vec![0.0; n];
        group.bench_with_input(BenchmarkId::new("rnea", name), &robot, |b, r| {
            b.iter(|| {
                rnea(
                    r.numeric(),
                    &mut ws,
                    black_box(&q),
                    black_box(&qd),
                    black_box(&qdd),
                    &mut tau,
                );
                black_box(&tau);
            })
        });
        // the checked in-place API over the movable joints (these robots have no fixed frame)
        assert_eq!(robot.dof(), n);
        group.bench_with_input(
            BenchmarkId::new("inverse_dynamics_into", name),
            &robot,
            |b, r| {
                b.iter(|| {
                    inverse_dynamics_into(
                        r,
                        &mut ws,
                        r.environment(),
                        black_box(&q),
                        black_box(&qd),
                        black_box(&qdd),
                        &mut tau,
                    )
                    .unwrap();
                    black_box(&tau);
                })
            },
        );
        group.bench_with_input(
            BenchmarkId::new("inverse_dynamics", name),
            &robot,
            |b, r| b.iter(|| inverse_dynamics(r, black_box(&q), black_box(&qd), black_box(&qdd))),
        );
        group.bench_with_input(BenchmarkId::new("lagrangian", name), &robot, |b, r| {
            b.iter(|| lagrangian_torques(r, black_box(&q), black_box(&qd), black_box(&qdd)))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
