//! Closed-chain overhead (issue 18): for the Acma SR400 and the planar five-bar, the closed-chain
//! inverse dynamics (10.40), inertia matrix A_cl = G^T A_tr G (10.46), direct dynamics
//! (10.46–10.48) and loop closure, each next to the tree algorithm it builds on, timed on the
//! equivalent tree at the consistent state (group `closed_overhead_<robot>`, functions
//! `<model>/closed` and `<model>/tree`). The closed calls run as in a control loop: q_a moves by a
//! 1 ms step at about 1 rad/s between calls (back and forth), so every call re-closes the loops
//! from the previous point with the branch tracker. Then the closed-chain direct model as the
//! simulator evaluates it (`ClosedChainDynamics`) and 100 RK4 steps.
//!
//! `cargo bench -p robodyn --bench closed_chain -- closed_overhead`

use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::DMatrix;
use robodyn::simulation::{
    simulate, ClosedChainDynamics, Dynamics, Integrator, Recorder, SimOptions, TorqueInput,
};
use robodyn::{
    closed_direct_dynamics_into, closed_inertia_matrix_into, closed_inverse_dynamics_into,
    closed_state, direct_dynamics_into, inertia_matrix_into, inverse_dynamics_into,
    loop_closure_into, ClosedChain, ClosedData, Data, Method,
};
use std::hint::black_box;
use std::path::PathBuf;

/// (robot file, q_a, a guess of q_p at q_a or None for the file's assembly, qd_a, qdd_a, tau_a)
type Case = (
    &'static str,
    Vec<f64>,
    Option<Vec<f64>>,
    Vec<f64>,
    Vec<f64>,
    Vec<f64>,
);

fn cases() -> Vec<Case> {
    vec![
        (
            "sr400",
            vec![0.1, 0.3, 0.2, -0.4, 0.5, 1.2],
            Some(vec![2.4, -0.9]),
            vec![0.3, -0.2, 0.5, 0.1, -0.6, 0.4],
            vec![1.0, -0.5, 0.7, 2.0, -1.0, 0.3],
            vec![5.0, -100.0, 2.0, 1.0, 0.5, 30.0],
        ),
        (
            "fivebar",
            vec![0.1, -0.1],
            None,
            vec![0.5, -0.3],
            vec![1.0, 2.0],
            vec![0.2, -0.1],
        ),
    ]
}

fn overhead(c: &mut Criterion) {
    for (name, qa, guess, qd, qdd, tau) in cases() {
        let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../robots/{name}.toml"));
        let robot = robodyn::io::load(&p).expect("bundled robot");
        let cc = ClosedChain::new(&robot).expect("closed chain");
        let mut branch = match &guess {
            Some(g) => cc.branch_from(&qa, g).expect("closes"),
            None => {
                let mut b = cc.assembly_branch().expect("assembles");
                let mut d = ClosedData::new(&cc);
                let mut qp = vec![0.0; cc.n_equations()];
                loop_closure_into(&cc, &mut d, &mut b, &qa, &mut qp).expect("closes");
                b
            }
        };
        let n = cc.dof();
        // two points 1 ms apart along qd: the tracker moves between them at every call
        let qa2: Vec<f64> = qa.iter().zip(&qd).map(|(x, v)| x + 1e-3 * v).collect();
        let points = [qa.clone(), qa2];
        // the equivalent tree at the consistent state (10.29, 10.42)
        let s = closed_state(&cc, &mut branch.clone(), &qa, &qd, &qdd).expect("state");
        let (q_tr, qd_tr, qdd_tr) = (s.q.as_slice(), s.qd.as_slice(), s.qdd.as_slice());
        let nt = robot.dof();
        let env = robot.environment();
        let mut data = Data::new(&robot);
        let mut tau_tr = vec![0.0; nt];
        inverse_dynamics_into(&robot, &mut data, env, q_tr, qd_tr, qdd_tr, &mut tau_tr)
            .expect("tree idm");
        let mut cd = ClosedData::new(&cc);
        let mut out = vec![0.0; n];
        let mut out_tr = vec![0.0; nt];
        let (mut a_cl, mut a_tr) = (DMatrix::zeros(n, n), DMatrix::zeros(nt, nt));
        let mut qp = vec![0.0; cc.n_equations()];
        let mut k = 0usize;
        let mut g = c.benchmark_group(format!("closed_overhead_{name}"));
        g.bench_function("idm/closed", |b| {
            b.iter(|| {
                k += 1;
                let q = &points[k % 2];
                closed_inverse_dynamics_into(
                    &cc,
                    &mut cd,
                    &mut branch,
                    env,
                    black_box(q),
                    &qd,
                    &qdd,
                    &mut out,
                )
                .expect("idm");
                out[0]
            })
        });
        g.bench_function("idm/tree", |b| {
            b.iter(|| {
                inverse_dynamics_into(
                    &robot,
                    &mut data,
                    env,
                    black_box(q_tr),
                    qd_tr,
                    qdd_tr,
                    &mut out_tr,
                )
                .expect("idm");
                out_tr[0]
            })
        });
        g.bench_function("inertia/closed", |b| {
            b.iter(|| {
                k += 1;
                let q = &points[k % 2];
                closed_inertia_matrix_into(&cc, &mut cd, &mut branch, black_box(q), &mut a_cl)
                    .expect("A_cl");
                a_cl[(0, 0)]
            })
        });
        g.bench_function("inertia/tree", |b| {
            b.iter(|| {
                inertia_matrix_into(&robot, &mut data, black_box(q_tr), &mut a_tr).expect("A");
                a_tr[(0, 0)]
            })
        });
        g.bench_function("ddm/closed", |b| {
            b.iter(|| {
                k += 1;
                let q = &points[k % 2];
                closed_direct_dynamics_into(
                    &cc,
                    &mut cd,
                    &mut branch,
                    env,
                    black_box(q),
                    &qd,
                    &tau,
                    &mut out,
                )
                .expect("ddm");
                out[0]
            })
        });
        g.bench_function("ddm/tree", |b| {
            b.iter(|| {
                direct_dynamics_into(
                    &robot,
                    &mut data,
                    env,
                    black_box(q_tr),
                    qd_tr,
                    &tau_tr,
                    Method::Composite,
                    &mut out_tr,
                )
                .expect("ddm");
                out_tr[0]
            })
        });
        // the closure alone: q_p at q_a from the previous point (1 ms step), the tree
        // counterpart being nothing (q_tr is given): timed next to the tree's inverse dynamics
        g.bench_function("closure/closed", |b| {
            b.iter(|| {
                k += 1;
                let q = &points[k % 2];
                loop_closure_into(&cc, &mut cd, &mut branch, black_box(q), &mut qp)
                    .expect("closes");
                qp[0]
            })
        });
        g.finish();
    }
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

criterion_group!(benches, overhead, sr400_simulation);
criterion_main!(benches);
