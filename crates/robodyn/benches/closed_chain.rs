//! Closed-chain inverse and direct dynamic models of the Acma SR400 (10.40, 10.46–10.48),
//! including the loop closure (warm start from the previous solution, as in a trajectory), and
//! the closed-chain direct model as the simulator evaluates it (`ClosedChainDynamics`).

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::algorithms::closed_chain::ClosedChain;
use robodyn::simulation::{
    simulate, ClosedChainDynamics, Dynamics, Integrator, Recorder, SimOptions, TorqueInput,
};
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

/// One evaluation of the simulator's right-hand side: loops re-solved from the previous
/// solution at a q_a that moved by a 1 ms step at ~1 rad/s (as between two RK stages), then
/// A_cl, H_cl and qdd_a (10.46–10.48); and 100 RK4 steps of 1 ms (400 evaluations + 101 rows
/// with energy and closure residual).
fn sr400_simulation(c: &mut Criterion) {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml");
    let robot = robodyn::io::load(&p).expect("bundled SR400");
    let mut sys = ClosedChainDynamics::new(&robot).expect("closed chain");
    let q0 = [0.1, 0.3, 0.2, -0.4, 0.5, 1.2];
    let qd = [0.3, -0.2, 0.5, 0.1, -0.6, 0.4];
    let tau = [5.0, -100.0, 2.0, 1.0, 0.5, 30.0];
    let mut qdd = [0.0; 6];
    let mut q = q0;
    let mut k = 0usize;
    sys.accel(0.0, &q, &qd, &tau, &mut qdd).expect("accel");
    c.bench_function(
        "sr400 closed-chain direct model per simulation step (warm closure)",
        |b| {
            b.iter(|| {
                // back and forth along a short path so that every call moves q_a by 1 ms x qd
                k += 1;
                let s = if (k / 50).is_multiple_of(2) {
                    1e-3
                } else {
                    -1e-3
                };
                for (x, v) in q.iter_mut().zip(&qd) {
                    *x += s * v;
                }
                sys.accel(0.0, black_box(&q), &qd, &tau, &mut qdd)
                    .expect("accel");
                qdd[0]
            })
        },
    );
    let opts = SimOptions {
        duration: 0.1,
        integrator: Integrator::Rk4 { dt: 1e-3 },
        output_dt: 1e-3,
        max_steps: None,
    };
    let input = TorqueInput::Constant(vec![0.0; 6]);
    c.bench_function(
        "sr400 closed-chain simulation, 100 RK4 steps of 1 ms",
        |b| {
            b.iter(|| {
                let mut sys = ClosedChainDynamics::new(&robot).expect("closed chain");
                let mut rec = Recorder::default();
                simulate(&mut sys, &input, &q0, &qd, &opts, &mut rec, &mut |_| {}).expect("runs");
                rec.rows.len()
            })
        },
    );
}

criterion_group!(benches, sr400, sr400_simulation);
criterion_main!(benches);
