//! Closed-chain inverse and direct dynamic models of the Acma SR400 (10.40, 10.46–10.48),
//! including the loop closure (warm start from the previous solution, as in a trajectory).

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::algorithms::closed_chain::ClosedChain;
use std::hint::black_box;
use std::path::PathBuf;

fn sr400(c: &mut Criterion) {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml");
    let robot = robodyn::io::load(&p).expect("bundled SR400");
    let cc = ClosedChain::new(&robot).expect("closed chain");
    let mut ws = cc.workspace();
    let qa = [0.1, 0.3, 0.2, -0.4, 0.5, 1.2];
    let qd = [0.3, -0.2, 0.5, 0.1, -0.6, 0.4];
    let qdd = [1.0, -0.5, 0.7, 2.0, -1.0, 0.3];
    let tau = [5.0, -100.0, 2.0, 1.0, 0.5, 30.0];
    let guess = cc
        .solve_positions(&mut ws, &qa, Some(&[2.4, -0.9]))
        .expect("closes")
        .q_p;
    c.bench_function("sr400 closed-chain idm (warm closure)", |b| {
        b.iter(|| {
            cc.inverse_dynamics(&mut ws, black_box(&qa), &qd, &qdd, Some(&guess))
                .expect("idm")
                .gamma_cl
        })
    });
    c.bench_function("sr400 closed-chain ddm (warm closure)", |b| {
        b.iter(|| {
            cc.direct_dynamics(&mut ws, black_box(&qa), &qd, &tau, Some(&guess))
                .expect("ddm")
                .qdd_a
        })
    });
    let lc = cc.closure();
    let mut lws = lc.workspace();
    let far = [2.4 + 0.2, -0.9 - 0.2];
    c.bench_function("sr400 loop closure (guess 0.2 rad off)", |b| {
        b.iter(|| {
            lc.solve(&mut lws, black_box(&qa), Some(&far))
                .expect("closes")
                .q_p
        })
    });
}

criterion_group!(benches, sr400);
criterion_main!(benches);
