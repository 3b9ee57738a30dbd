//! Generated customized inverse dynamic model (Rust, numeric values substituted) against the
//! numeric Newton–Euler `rnea` on the SR400 (equivalent tree) and the RX-90; and the generated
//! closed-chain model of the five-bar (G depending on q) against the numeric route on the same
//! closed state: `closed_inverse_dynamics_into` on the branch tracker (closure at the tracker's
//! point, W, G, Psi, `rnea`, G^T Gamma_tr).

use criterion::{criterion_group, criterion_main, Criterion};
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::{
    closed_inverse_dynamics, closed_inverse_dynamics_into, ClosedChain, ClosedData, Data, Robot,
};
use robodyn_testing::{random_state, rng};
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
mod gen_fivebar {
    include!("generated/fivebar_closed.rs");
}

type GenFn = fn(&[f64], &[f64], &[f64], &mut [f64]);

fn bench_robot(c: &mut Criterion, label: &str, robot: Robot, f: GenFn) {
    let n = robot.nl();
    let [q, qd, qdd] = random_state(&mut rng(1), n);
    let model = robot.numeric();
    let mut ws = Data::from_model(model);
    let mut tau = vec![0.0; n];
    let mut out = vec![0.0; n];
    // same numbers (movable joints only in `out`; both robots have no fixed tree frame)
    rnea(model, &mut ws, &q, &qd, &qdd, &mut tau);
    f(&q, &qd, &qdd, &mut out);
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
    bench_generated(&mut g, f, [&q, &qd, &qdd], &mut out);
    g.finish();
}

/// The "generated" member of a group: `f(q, qd, qdd, out)` (numeric values baked in).
fn bench_generated(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    f: GenFn,
    [q, qd, qdd]: [&[f64]; 3],
    out: &mut [f64],
) {
    g.bench_function("generated", |b| {
        b.iter(|| {
            f(black_box(q), black_box(qd), black_box(qdd), out);
            black_box(&*out);
        })
    });
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

/// Five-bar closed-chain model on a closed state near the assembly.
fn bench_closed(c: &mut Criterion) {
    let robot = Robot::new(robots::fivebar_description()).unwrap();
    let cc = ClosedChain::new(&robot).unwrap();
    let mut branch = cc.assembly_branch().unwrap();
    let qa: Vec<f64> = branch.q_a().iter().map(|x| x + 0.1).collect();
    let (qda, qdda) = ([0.7, -0.4], [1.5, 2.0]);
    let idm = closed_inverse_dynamics(&cc, &mut branch, &qa, &qda, &qdda).unwrap();
    let st = &idm.state;
    let v = |x: &nalgebra::DVector<f64>| -> Vec<f64> { x.iter().copied().collect() };
    let (q, qd, qdd) = (v(&st.q), v(&st.qd), v(&st.qdd));
    let mut out = vec![0.0; cc.dof()];
    gen_fivebar::fivebar_closed(&q, &qd, &qdd, &mut out);
    for (a, b) in idm.gamma_cl.iter().zip(&out) {
        assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "{a} vs {b}");
    }
    let mut data = ClosedData::new(&cc);
    let env = robot.environment();
    let mut tau = vec![0.0; cc.dof()];
    let mut g = c.benchmark_group("closed_fivebar");
    // the numeric route on the branch (closure at the tracker's point, W, G, Psi, rnea, G^T)
    g.bench_function("numeric", |b| {
        b.iter(|| {
            closed_inverse_dynamics_into(
                &cc,
                &mut data,
                &mut branch,
                env,
                black_box(&qa),
                &qda,
                &qdda,
                &mut tau,
            )
            .unwrap();
            black_box(&tau);
        })
    });
    bench_generated(
        &mut g,
        gen_fivebar::fivebar_closed,
        [&q, &qd, &qdd],
        &mut out,
    );
    g.finish();
}

criterion_group!(generated, benches, bench_closed);
criterion_main!(generated);
