//! Batches of states spread over the cores (rayon). N states are row-major slices (state s holds
//! entries `s * n .. (s + 1) * n`), results in the same layout.
//!
//! [`for_each_row`] (and [`for_each_row2`] for two outputs) is the runner every batch goes
//! through — the tree functions below, the CLI's CSV commands and the Python package: it cuts
//! the rows into tasks of [`ROWS_PER_TASK`], makes one scratch (a [`Data`], or whatever the
//! evaluation needs) per task with a closure, and evaluates each row into its slice of the
//! output, so the work per state allocates nothing; rows are independent, so the result does
//! not depend on the number of threads, and the error reported is the lowest failing row's.
//!
//! The rayon pool decides the threads: the global pool (all cores, or `RAYON_NUM_THREADS`), or
//! a pool of the caller's (`rayon::ThreadPoolBuilder::new().num_threads(1).build()?.install(..)`).
//!
//! Closed chains are not batched here: their result depends on the branch tracker, which moves
//! from one state to the next along a contiguous run of states, so such a run is evaluated
//! sequentially (`closed_*_into` with one `Branch`).

use crate::algorithms::direct_dynamics::{direct_dynamics_into, Method};
use crate::algorithms::inverse_dynamics::inverse_dynamics_into;
use crate::algorithms::regressor::{regressor_into, wrench_torques_into, PARAMS_PER_LINK};
use crate::data::Data;
use crate::error::{Error, Result};
use crate::model::{Environment, Robot};
use nalgebra::DMatrix;
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Rows per rayon task: enough tasks to balance two to a few dozen cores on 10^4..10^6 rows,
/// rows enough that a task's scratch is made rarely and the task's overhead (well under a
/// microsecond) is lost in its work. A task's output block is contiguous, so two threads share
/// at most the cache line at a block's edge.
pub const ROWS_PER_TASK: usize = 128;

/// The number of threads a batch runs on here: the current rayon pool's (the caller's pool
/// inside `pool.install`, else the global pool: all cores or `RAYON_NUM_THREADS`).
pub fn threads() -> usize {
    rayon::current_num_threads()
}

/// Number of rows N of row-major `inputs` (name, slice) of `width` entries per row, all of the
/// same length, a multiple of `width`; [`Error::Dimension`] naming the first input that is not.
/// A width of 0 gives 0 rows.
pub fn count_rows(width: usize, inputs: &[(&str, &[f64])]) -> Result<usize> {
    let Some(&(first, v0)) = inputs.first() else {
        return Ok(0);
    };
    if width == 0 {
        return Ok(0);
    }
    let len = v0.len();
    for &(what, v) in inputs {
        if v.len() != len || v.len() % width != 0 {
            return Err(Error::dimension(
                what,
                len - len % width,
                v.len(),
                format!("N rows x {width} entries, row-major, as long as `{first}`"),
            ));
        }
    }
    Ok(len / width)
}

/// An output of `expected` entries (`layout` says which).
fn check_output(
    what: &str,
    out: &[f64],
    expected: usize,
    layout: impl Fn() -> String,
) -> Result<()> {
    if out.len() != expected {
        return Err(Error::dimension(what, expected, out.len(), layout()));
    }
    Ok(())
}

/// Evaluate `f(scratch, s, out_s)` for every row s in `0..rows` over the rayon pool, `out_s`
/// being row s of `out` (`rows` x `width`, row-major). `scratch()` is called once per task (at
/// most once per [`ROWS_PER_TASK`] rows): put there what the evaluation allocates (a
/// [`Data::new`]), so that `f` allocates nothing. The inputs are the closure's: row s of a
/// row-major N x n input is `&input[s * n..(s + 1) * n]` ([`count_rows`] checks their lengths).
///
/// Errors: [`Error::Dimension`] when `out` is not `rows * width` long; else the error of the
/// lowest row whose `f` failed, as [`Error::Row`] (1-based), whatever the number of threads
/// (rows after a known failure are skipped, rows before it are all evaluated). `out` is then
/// partly written.
///
/// ```
/// # use robodyn::{batch::for_each_row, inverse_dynamics_into, Data};
/// # let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../robots/rx90.toml");
/// # let robot = robodyn::io::load(std::path::Path::new(path))?;
/// let n = robot.dof();
/// let rows = 1000;
/// let (q, qd, qdd) = (vec![0.1; rows * n], vec![0.0; rows * n], vec![0.0; rows * n]);
/// let mut tau = vec![0.0; rows * n];
/// let r = |s: usize| s * n..(s + 1) * n;
/// for_each_row(rows, &mut tau, n, || Data::new(&robot), |data, s, tau_s| {
///     let env = robot.environment();
///     inverse_dynamics_into(&robot, data, env, &q[r(s)], &qd[r(s)], &qdd[r(s)], tau_s)
/// })?;
/// # Ok::<(), robodyn::Error>(())
/// ```
pub fn for_each_row<S, I, F>(
    rows: usize,
    out: &mut [f64],
    width: usize,
    scratch: I,
    f: F,
) -> Result<()>
where
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, usize, &mut [f64]) -> Result<()> + Sync + Send,
{
    for_each_row2(rows, (out, width), (&mut [], 0), scratch, |s, row, o, _| {
        f(s, row, o)
    })
}

/// [`for_each_row`] with two outputs, each given with its width: `f(scratch, s, out1_s,
/// out2_s)` for `out1 = (slice of rows x w1, w1)` and `out2 = (slice of rows x w2, w2)`, both
/// row-major (e.g. the regressor and the wrench torques of [`regressor_batch`]).
pub fn for_each_row2<S, I, F>(
    rows: usize,
    out1: (&mut [f64], usize),
    out2: (&mut [f64], usize),
    scratch: I,
    f: F,
) -> Result<()>
where
    I: Fn() -> S + Sync + Send,
    F: Fn(&mut S, usize, &mut [f64], &mut [f64]) -> Result<()> + Sync + Send,
{
    let ((mut a, w1), (mut b, w2)) = (out1, out2);
    let layout = |w: usize| move || format!("{rows} rows x {w} entries, row-major");
    check_output("output", a, rows * w1, layout(w1))?;
    check_output("second output", b, rows * w2, layout(w2))?;
    // the outputs cut into the tasks' contiguous blocks of rows
    let tasks = rows.div_ceil(ROWS_PER_TASK);
    let mut blocks: Vec<(&mut [f64], &mut [f64])> = Vec::with_capacity(tasks);
    for t in 0..tasks {
        let k = ROWS_PER_TASK.min(rows - t * ROWS_PER_TASK);
        let (x, rest) = std::mem::take(&mut a).split_at_mut(k * w1);
        a = rest;
        let (y, rest) = std::mem::take(&mut b).split_at_mut(k * w2);
        b = rest;
        blocks.push((x, y));
    }
    // the lowest failing row known so far: later tasks need not run
    let failed = AtomicUsize::new(usize::MAX);
    let first_error = blocks
        .into_par_iter()
        .enumerate()
        .map_init(&scratch, |s, (task, (x, y))| {
            let first = task * ROWS_PER_TASK;
            if first > failed.load(Ordering::Relaxed) {
                return Ok(());
            }
            for i in 0..ROWS_PER_TASK.min(rows - first) {
                let row = first + i;
                let o1 = &mut x[i * w1..(i + 1) * w1];
                f(s, row, o1, &mut y[i * w2..(i + 1) * w2]).map_err(|e| {
                    failed.fetch_min(row, Ordering::Relaxed);
                    (row, Box::new(e))
                })?;
            }
            Ok(())
        })
        .filter_map(|r: std::result::Result<(), (usize, Box<Error>)>| r.err())
        .min_by_key(|(row, _)| *row);
    match first_error {
        Some((row, e)) => Err((*e).in_row(row + 1)),
        None => Ok(()),
    }
}

/// A joint-vector output of N states: N x n (n = nv on a floating base).
fn check_states(what: &str, out: &[f64], rows: usize, n: usize) -> Result<()> {
    check_output(what, out, rows * n, || {
        format!("{rows} states x {n} entries")
    })
}

/// Inverse dynamic model (eqs 10.3–10.12) of N states: `q`, `qd`, `qdd` and `tau` row-major,
/// N x n (n = [`Robot::dof`], movable joints in frame order; a floating base's q has
/// nq = 7 + n entries per state, the others nv = 6 + n), under `env`. Rows run in parallel
/// on the rayon pool, allocation-free per state.
///
/// Errors: [`Error::Dimension`] for slices of different or wrong lengths; the first state whose
/// evaluation fails (e.g. a NaN) as [`Error::Row`].
pub fn inverse_dynamics_batch(
    robot: &Robot,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    tau: &mut [f64],
) -> Result<()> {
    let rows = count_state_rows(robot, q, &[("qd", qd), ("qdd", qdd)])?;
    let (nq, nv) = (robot.nq(), robot.nv());
    check_states("tau", tau, rows, nv)?;
    let r = |s: usize| s * nq..(s + 1) * nq;
    let v = |s: usize| s * nv..(s + 1) * nv;
    for_each_row(
        rows,
        tau,
        nv,
        || Data::new(robot),
        |data, s, out| {
            inverse_dynamics_into(robot, data, env, &q[r(s)], &qd[v(s)], &qdd[v(s)], out)
        },
    )
}

/// The number of states of row-major inputs: `q` of nq entries per state, each of `vs` of nv
/// (a fixed base: n = [`Robot::dof`] each; a floating one: nq = 7 + n, nv = 6 + n).
fn count_state_rows(robot: &Robot, q: &[f64], vs: &[(&str, &[f64])]) -> Result<usize> {
    if !robot.is_floating() {
        let all: Vec<(&str, &[f64])> = std::iter::once(("q", q))
            .chain(vs.iter().copied())
            .collect();
        return count_rows(robot.dof(), &all);
    }
    let rows = count_rows(robot.nq(), &[("q", q)])?;
    for &(what, v) in vs {
        if v.len() != rows * robot.nv() {
            return Err(Error::dimension(
                what,
                rows * robot.nv(),
                v.len(),
                format!(
                    "{rows} rows x nv = {} entries, row-major, as many rows as `q` (nq = {})",
                    robot.nv(),
                    robot.nq()
                ),
            ));
        }
    }
    Ok(rows)
}

/// Direct dynamic model of N states by `method`: `q`, `qd`, `tau` and `qdd` row-major, N x n,
/// under `env`. Rows run in parallel, allocation-free per state. Errors as
/// [`inverse_dynamics_batch`], and [`Error::Singular`] (in its row) for a singular state.
#[allow(clippy::too_many_arguments)]
pub fn direct_dynamics_batch(
    robot: &Robot,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    tau: &[f64],
    method: Method,
    qdd: &mut [f64],
) -> Result<()> {
    let rows = count_state_rows(robot, q, &[("qd", qd), ("tau", tau)])?;
    let (nq, nv) = (robot.nq(), robot.nv());
    check_states("qdd", qdd, rows, nv)?;
    let r = |s: usize| s * nq..(s + 1) * nq;
    let v = |s: usize| s * nv..(s + 1) * nv;
    for_each_row(
        rows,
        qdd,
        nv,
        || Data::new(robot),
        |data, s, out| {
            direct_dynamics_into(
                robot,
                data,
                env,
                &q[r(s)],
                &qd[v(s)],
                &tau[v(s)],
                method,
                out,
            )
        },
    )
}

/// Regressor of N states (§10.2.4): `phi` is the row-major stack of the N regressors
/// (N n rows of 13 NL columns: rows s n .. (s + 1) n are state s's Phi) and `tau_e` the N x n
/// torques of the external wrenches of `env`, so that state s's torques are
/// Phi_s K + tau_e,s. Rows run in parallel, allocation-free per state (a task's column-major
/// Phi buffer is made once per task).
#[allow(clippy::too_many_arguments)]
pub fn regressor_batch(
    robot: &Robot,
    env: &Environment,
    q: &[f64],
    qd: &[f64],
    qdd: &[f64],
    phi: &mut [f64],
    tau_e: &mut [f64],
) -> Result<()> {
    let n = robot.dof();
    let cols = PARAMS_PER_LINK * robot.nl();
    let rows = count_rows(n, &[("q", q), ("qd", qd), ("qdd", qdd)])?;
    check_output("Phi", phi, rows * n * cols, || {
        format!("{rows} states x {n} joints rows, {cols} columns (13 per link), row-major")
    })?;
    check_states("tau_e", tau_e, rows, n)?;
    let r = |s: usize| s * n..(s + 1) * n;
    for_each_row2(
        rows,
        (phi, n * cols),
        (tau_e, n),
        || (Data::new(robot), DMatrix::zeros(n, cols)),
        |(data, p), s, phi_s, tau_e_s| {
            regressor_into(robot, data, env, &q[r(s)], &qd[r(s)], &qdd[r(s)], p)?;
            wrench_torques_into(robot, data, env, &q[r(s)], tau_e_s)?;
            for (k, row) in phi_s.chunks_mut(cols).enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    *x = p[(k, c)];
                }
            }
            Ok(())
        },
    )
}
