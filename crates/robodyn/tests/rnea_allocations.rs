//! The per-call API allocates nothing once its `Data` is built (trees: inverse and direct
//! dynamics, A, H, the regressor; floating bases: the same over nv; closed chains: loop closure,
//! inverse and direct dynamics along a trajectory, once the branch tracker is on the branch): a
//! counting global allocator (counting only on the calling thread, so the test harness's own
//! threads do not interfere).

use nalgebra::DMatrix;
use robodyn::algorithms::inverse_dynamics::rnea;
use robodyn::{
    closed_direct_dynamics_into, closed_inverse_dynamics_into, direct_dynamics_into, h_vector_into,
    inertia_matrix_into, inverse_dynamics_into, loop_closure_into, regressor_into, ClosedChain,
    ClosedData, Data, Method,
};
use robodyn_testing::{
    self as testing, random_floating_state, random_floating_tree, random_state, random_tree,
    TreeOptions,
};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::PathBuf;

struct Counting;

thread_local! {
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    // try_with: the thread-local may already be gone while a thread shuts down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

fn counter_counts() {
    // The counter sees this thread's allocations: one Vec proves it counts.
    let before = allocations();
    let probe = vec![1u8; 16];
    assert_eq!(allocations(), before + 1, "the counting allocator counts");
    drop(probe);
}

fn robots() -> Vec<robodyn::Robot> {
    let sr400 = robodyn::io::load(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/sr400.toml"),
    )
    .unwrap();
    let mut rng = testing::rng(5);
    let mut robots = vec![sr400];
    // random trees with fixed frames (the public vectors scatter into the tree arrays)
    for n in [2, 13, 30] {
        robots.push(random_tree(&mut rng, n, &TreeOptions::default()));
    }
    robots
}

#[test]
fn rnea_allocates_nothing_after_the_workspace_is_built() {
    let mut rng = testing::rng(5);
    for robot in &robots() {
        let n = robot.nl();
        let states: Vec<_> = (0..20).map(|_| random_state(&mut rng, n)).collect();
        let mut ws = Data::new(robot);
        let mut tau = vec![0.0; n];
        counter_counts();
        let before = allocations();
        let mut checksum = 0.0;
        for _ in 0..50 {
            for s in &states {
                rnea(robot.numeric(), &mut ws, &s[0], &s[1], &s[2], &mut tau);
                checksum += tau[n - 1];
            }
        }
        let after = allocations();
        assert!(checksum.is_finite());
        assert_eq!(
            after - before,
            0,
            "{}: rnea allocated {} times in 1000 calls",
            robot.name(),
            after - before
        );
    }
}

#[test]
fn checked_tree_functions_allocate_nothing() {
    let mut rng = testing::rng(6);
    for robot in &robots() {
        let m = robot.dof();
        let nl = robot.nl();
        let states: Vec<_> = (0..10).map(|_| random_state(&mut rng, m)).collect();
        let mut data = Data::new(robot);
        let mut env = robot.environment().clone();
        let (mut tau, mut qdd, mut h) = (vec![0.0; m], vec![0.0; m], vec![0.0; m]);
        let mut a = DMatrix::zeros(m, m);
        let mut phi = DMatrix::zeros(m, 13 * nl);
        // the regressor's tree buffer is sized at its first call
        let s0 = &states[0];
        regressor_into(robot, &mut data, &env, &s0[0], &s0[1], &s0[2], &mut phi).unwrap();
        counter_counts();
        let before = allocations();
        let mut checksum = 0.0;
        for k in 0..20 {
            for s in &states {
                // a contact force that changes at every call: a field of the environment
                env.set_wrench_on_link(nl, [k as f64, 0.0, 1.0].into(), [0.0; 3].into())
                    .unwrap();
                inverse_dynamics_into(robot, &mut data, &env, &s[0], &s[1], &s[2], &mut tau)
                    .unwrap();
                for method in [Method::Composite, Method::ArticulatedBody] {
                    direct_dynamics_into(
                        robot, &mut data, &env, &s[0], &s[1], &tau, method, &mut qdd,
                    )
                    .unwrap();
                }
                inertia_matrix_into(robot, &mut data, &s[0], &mut a).unwrap();
                h_vector_into(robot, &mut data, &env, &s[0], &s[1], &mut h).unwrap();
                regressor_into(robot, &mut data, &env, &s[0], &s[1], &s[2], &mut phi).unwrap();
                checksum += qdd.iter().sum::<f64>() + a[(0, 0)] + h[0] + phi[(0, 0)];
            }
        }
        let after = allocations();
        assert!(checksum.is_finite());
        assert_eq!(
            after - before,
            0,
            "{}: the checked tree functions allocated {} times",
            robot.name(),
            after - before
        );
    }
}

/// Floating bases (issue 27): inverse dynamics, both direct methods, A and H over nv = 6 + N
/// allocate nothing after the `Data` is built (random trees with fixed frames, N = 2, 13, 30).
#[test]
fn floating_functions_allocate_nothing() {
    let mut rng = testing::rng(7);
    for n in [2, 13, 30] {
        let robot = random_floating_tree(&mut rng, n, &TreeOptions::default());
        let m = robot.dof();
        let nv = robot.nv();
        let states: Vec<_> = (0..10)
            .map(|_| random_floating_state(&mut rng, m))
            .collect();
        let mut data = Data::new(&robot);
        let env = robot.environment().clone();
        let (mut tau, mut qdd, mut h) = (vec![0.0; nv], vec![0.0; nv], vec![0.0; nv]);
        let mut a = DMatrix::zeros(nv, nv);
        counter_counts();
        let before = allocations();
        let mut checksum = 0.0;
        for _ in 0..20 {
            for s in &states {
                inverse_dynamics_into(&robot, &mut data, &env, &s[0], &s[1], &s[2], &mut tau)
                    .unwrap();
                for method in [Method::Composite, Method::ArticulatedBody] {
                    direct_dynamics_into(
                        &robot, &mut data, &env, &s[0], &s[1], &tau, method, &mut qdd,
                    )
                    .unwrap();
                }
                inertia_matrix_into(&robot, &mut data, &s[0], &mut a).unwrap();
                h_vector_into(&robot, &mut data, &env, &s[0], &s[1], &mut h).unwrap();
                checksum += qdd.iter().sum::<f64>() + a[(0, 0)] + h[0];
            }
        }
        let after = allocations();
        assert!(checksum.is_finite());
        assert_eq!(
            after - before,
            0,
            "{}: the floating functions allocated {} times",
            robot.name(),
            after - before
        );
    }
}

/// Closed chains in a control loop: q_a moves along a smooth trajectory (1 ms steps), each call
/// continues the branch tracker from the previous point. After the first calls (which size
/// nothing but start the tracker), nothing is allocated.
#[test]
fn closed_chain_steady_state_allocates_nothing() {
    for (file, amplitude) in [
        ("sr400.toml", 0.4),
        ("fivebar.toml", 0.1),
        ("twoloops.toml", 1.0),
    ] {
        let robot = robodyn::io::load(
            PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../../robots")
                .join(file),
        )
        .unwrap();
        let chain = ClosedChain::new(&robot).unwrap();
        let mut branch = chain.assembly_branch().unwrap();
        let q0 = branch.q_a().to_vec();
        let n = chain.dof();
        let mut data = ClosedData::new(&chain);
        let env = robot.environment();
        let (mut q, mut qd) = (q0.clone(), vec![0.0; n]);
        let qdd = vec![0.5; n];
        let (mut tau, mut acc, mut qp) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; chain.n_equations()]);
        let step = |k: usize, q: &mut Vec<f64>, qd: &mut Vec<f64>| {
            let t = k as f64 * 1e-3;
            for i in 0..n {
                let w = 1.0 + i as f64 * 0.3;
                q[i] = q0[i] + amplitude * (w * t).sin();
                qd[i] = amplitude * w * (w * t).cos();
            }
        };
        step(1, &mut q, &mut qd);
        closed_inverse_dynamics_into(&chain, &mut data, &mut branch, env, &q, &qd, &qdd, &mut tau)
            .unwrap();
        counter_counts();
        let before = allocations();
        let mut checksum = 0.0;
        for k in 2..1000 {
            step(k, &mut q, &mut qd);
            let c = closed_inverse_dynamics_into(
                &chain,
                &mut data,
                &mut branch,
                env,
                &q,
                &qd,
                &qdd,
                &mut tau,
            )
            .unwrap();
            closed_direct_dynamics_into(
                &chain,
                &mut data,
                &mut branch,
                env,
                &q,
                &qd,
                &tau,
                &mut acc,
            )
            .unwrap();
            loop_closure_into(&chain, &mut data, &mut branch, &q, &mut qp).unwrap();
            checksum += tau[0] + acc[0] + qp[0] + c.wp;
        }
        let after = allocations();
        assert!(checksum.is_finite());
        assert_eq!(
            after - before,
            0,
            "{file}: the closed-chain functions allocated {} times in 3000 calls",
            after - before
        );
    }
}

/// Long moves of the branch tracker (whole turns of the four-bar's crank dropped after a
/// checked turn) allocate nothing either: their buffers are in `ClosedData`.
#[test]
fn closed_chain_long_moves_allocate_nothing() {
    let robot = robodyn::io::load(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../robots/fourbar.toml"),
    )
    .unwrap();
    let chain = ClosedChain::new(&robot).unwrap();
    let mut branch = chain.assembly_branch().unwrap();
    let mut data = ClosedData::new(&chain);
    let mut tau = [0.0];
    let env = robot.environment();
    closed_inverse_dynamics_into(
        &chain,
        &mut data,
        &mut branch,
        env,
        &[1e6],
        &[1.0],
        &[0.0],
        &mut tau,
    )
    .unwrap();
    counter_counts();
    let before = allocations();
    for q1 in [-3e7, 1e300, 0.5, 4e9, -1e12] {
        closed_inverse_dynamics_into(
            &chain,
            &mut data,
            &mut branch,
            env,
            &[q1],
            &[1.0],
            &[0.0],
            &mut tau,
        )
        .unwrap();
    }
    assert_eq!(allocations() - before, 0, "long moves allocated");
    assert!(tau[0].is_finite());
}

/// The batch row runner allocates nothing per row: on every thread, between the end of one row
/// and the start of the next, the only allocations are a new task's scratch (one `Data` per
/// task of `ROWS_PER_TASK` rows), so at most one row in a task's worth sees any.
#[test]
fn batch_runner_allocates_nothing_per_row() {
    use robodyn::batch::{for_each_row, ROWS_PER_TASK};
    use std::sync::atomic::{AtomicUsize, Ordering};
    thread_local! {
        static LAST_ROW_END: Cell<Option<usize>> = const { Cell::new(None) };
    }
    let robot = random_tree(&mut testing::rng(7), 9, &TreeOptions::default());
    let n = robot.dof();
    let rows = 40 * ROWS_PER_TASK;
    let mut rng = testing::rng(8);
    let states: Vec<f64> = (0..rows)
        .flat_map(|_| random_state(&mut rng, n).concat())
        .collect();
    let env = robot.environment();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let rows_after_allocation = AtomicUsize::new(0);
        let mut tau = vec![0.0; rows * n];
        pool.install(|| {
            for_each_row(
                rows,
                &mut tau,
                n,
                || Data::new(&robot),
                |data, s, out| {
                    let now = allocations();
                    if LAST_ROW_END.get().is_some_and(|end| end != now) {
                        rows_after_allocation.fetch_add(1, Ordering::Relaxed);
                    }
                    let x = &states[s * 3 * n..(s + 1) * 3 * n];
                    inverse_dynamics_into(
                        &robot,
                        data,
                        env,
                        &x[..n],
                        &x[n..2 * n],
                        &x[2 * n..],
                        out,
                    )?;
                    LAST_ROW_END.set(Some(allocations()));
                    Ok(())
                },
            )
        })
        .unwrap();
        let seen = rows_after_allocation.into_inner();
        assert!(
            seen <= rows / ROWS_PER_TASK,
            "{threads} threads: {seen} of {rows} rows followed an allocation (tasks: {})",
            rows / ROWS_PER_TASK
        );
    }
}

/// The derivatives of the inverse, direct and regressor models allocate nothing once their
/// data and outputs are made (robodyn::algorithms::derivatives).
#[test]
fn derivatives_allocate_nothing() {
    use robodyn::algorithms::derivatives::{
        direct_dynamics_derivatives_into, inverse_dynamics_derivatives_into,
        regressor_derivatives_into, DdmDerivatives, DerivativesData, IdmDerivatives,
        RegressorDerivatives, RegressorDerivativesData,
    };
    let mut rng = testing::rng(7);
    for robot in &robots() {
        let m = robot.dof();
        let states: Vec<_> = (0..5).map(|_| random_state(&mut rng, m)).collect();
        let env = robot.environment();
        let mut data = DerivativesData::new(robot);
        let (mut idm, mut ddm) = (IdmDerivatives::new(robot), DdmDerivatives::new(robot));
        let mut rdata = RegressorDerivativesData::new(robot).unwrap();
        let mut reg = RegressorDerivatives::new(robot);
        counter_counts();
        let before = allocations();
        let mut checksum = 0.0;
        for s in &states {
            let (q, qd, x) = (&s[0], &s[1], &s[2]);
            inverse_dynamics_derivatives_into(robot, &mut data, env, q, qd, x, &mut idm).unwrap();
            // a tree whose A is singular (sr400's cut links) reports it without allocating
            if direct_dynamics_derivatives_into(robot, &mut data, env, q, qd, x, &mut ddm).is_ok() {
                checksum += ddm.ainv[(0, 0)];
            }
            regressor_derivatives_into(robot, &mut rdata, env, q, qd, x, &mut reg).unwrap();
            checksum += idm.dtau_dq[(0, 0)] + reg.dphi_dq[0][(0, 0)];
        }
        let after = allocations();
        assert!(checksum.is_finite());
        assert_eq!(after - before, 0, "{}: derivatives allocated", robot.name());
    }
}
