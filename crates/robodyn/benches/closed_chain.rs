//! Closed-chain inverse and direct dynamic models of the Acma SR400 (10.40, 10.46–10.48),
//! including the loop closure on the branch tracker (at the tracker's point: "warm"), the
//! allocation-free `_into` forms, and the closed-chain direct model as the simulator evaluates
//! it (`ClosedChainDynamics`).

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::simulation::{
    simulate, ClosedChainDynamics, Dynamics, Integrator, Recorder, SimOptions, TorqueInput,
};
use robodyn::{
    closed_direct_dynamics, closed_direct_dynamics_into, closed_inverse_dynamics,
    closed_inverse_dynamics_into, loop_closure_into, ClosedChain, ClosedData,
};
use std::hint::black_box;
use std::path::PathBuf;

fn sr400(c: &mut Criterion) {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml");
    let robot = robodyn::io::load(&p).expect("bundled SR400");
    let cc = ClosedChain::new(&robot).expect("closed chain");
    let qa = [0.1, 0.3, 0.2, -0.4, 0.5, 1.2];
    let qd = [0.3, -0.2, 0.5, 0.1, -0.6, 0.4];
    let qdd = [1.0, -0.5, 0.7, 2.0, -1.0, 0.3];
    let tau = [5.0, -100.0, 2.0, 1.0, 0.5, 30.0];
    let mut branch = cc.branch_from(&qa, &[2.4, -0.9]).expect("closes");
    c.bench_function("sr400 closed-chain idm (warm closure)", |b| {
        b.iter(|| {
            closed_inverse_dynamics(&cc, &mut branch, black_box(&qa), &qd, &qdd)
                .expect("idm")
                .gamma_cl
        })
    });
    c.bench_function("sr400 closed-chain ddm (warm closure)", |b| {
        b.iter(|| {
            closed_direct_dynamics(&cc, &mut branch, black_box(&qa), &qd, &tau)
                .expect("ddm")
                .qdd_a
        })
    });
    let mut data = ClosedData::new(&cc);
    let env = robot.environment();
    let mut out = [0.0; 6];
    c.bench_function("sr400 closed-chain idm_into (warm closure)", |b| {
        b.iter(|| {
            closed_inverse_dynamics_into(
                &cc,
                &mut data,
                &mut branch,
                env,
                black_box(&qa),
                &qd,
                &qdd,
                &mut out,
            )
            .expect("idm");
            out[0]
        })
    });
    c.bench_function("sr400 closed-chain ddm_into (warm closure)", |b| {
        b.iter(|| {
            closed_direct_dynamics_into(
                &cc,
                &mut data,
                &mut branch,
                env,
                black_box(&qa),
                &qd,
                &tau,
                &mut out,
            )
            .expect("ddm");
            out[0]
        })
    });
    // the tracker moving back and forth by 0.2 rad on every actuated joint: continuation
    let far = qa.map(|x| x + 0.2);
    let mut qp = [0.0; 2];
    let mut k = 0usize;
    c.bench_function("sr400 loop closure, tracker moved 0.2 rad", |b| {
        b.iter(|| {
            k += 1;
            let target = if k.is_multiple_of(2) { &qa } else { &far };
            loop_closure_into(&cc, &mut data, &mut branch, black_box(target), &mut qp)
                .expect("closes");
            qp[0]
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
    let cc = ClosedChain::new(&robot).expect("closed chain");
    let q0 = [0.1, 0.3, 0.2, -0.4, 0.5, 1.2];
    let start = cc.branch_from(&q0, &[2.4, -0.9]).expect("closes");
    let mut sys = ClosedChainDynamics::new(cc.clone(), start.clone());
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
                let mut sys = ClosedChainDynamics::new(cc.clone(), start.clone());
                let mut rec = Recorder::default();
                simulate(&mut sys, &input, &q0, &qd, &opts, &mut rec, &mut |_| {}).expect("runs");
                rec.rows.len()
            })
        },
    );
}

criterion_group!(benches, sr400, sr400_simulation);
criterion_main!(benches);
