//! Batches of states of a tree robot spread over the cores (rayon): N states in row-major
//! slices (state s holds entries `s * n .. (s + 1) * n`, n = [`Robot::dof`]), results in the same
//! layout. Each worker makes its own [`Data`] once and evaluates its rows with the
//! allocation-free `_into` functions, so the work per state allocates nothing; rows are
//! independent, so the result does not depend on the number of threads.
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

/// States per rayon task: enough to balance two to a few dozen cores on 10^4..10^6 states, few
/// enough that a task's `Data` is made rarely.
const ROWS_PER_TASK: usize = 128;

/// Number of states N of row-major inputs with `n` entries per state (all of the same length, a
/// multiple of n).
fn count_states(n: usize, inputs: [(&str, &[f64]); 3]) -> Result<usize> {
    let len = inputs[0].1.len();
    if n == 0 {
        return Ok(0);
    }
    for (what, v) in inputs {
        if v.len() != len || v.len() % n != 0 {
            return Err(Error::dimension(
                what,
                len - len % n,
                v.len(),
                format!(
                    "N states x {n} joints, row-major, as long as `{}`",
                    inputs[0].0
                ),
            ));
        }
    }
    Ok(len / n)
}

fn check_output(what: &str, out: &[f64], expected: usize, layout: String) -> Result<()> {
    if out.len() != expected {
        return Err(Error::dimension(what, expected, out.len(), layout));
    }
    Ok(())
}

/// One state's outputs: its row of the first output and of the second.
type Outs<'a> = (&'a mut [f64], &'a mut [f64]);

/// Evaluate `f(data, scratch, s, (out1_s, out2_s))` for the `rows` states over the rayon pool,
/// the outputs split into rows of `widths` entries; one `Data` (and `scratch`) per task. The
/// error of the lowest failing state is returned as [`Error::Row`] (1-based), whatever the
/// scheduling.
fn for_each_state<S: Send>(
    robot: &Robot,
    rows: usize,
    outs: Outs<'_>,
    widths: (usize, usize),
    scratch: impl Fn() -> S + Sync + Send,
    f: impl Fn(&mut Data, &mut S, usize, Outs<'_>) -> Result<()> + Sync + Send,
) -> Result<()> {
    let (w1, w2) = widths;
    // the outputs cut into the tasks' blocks of rows
    let tasks = rows.div_ceil(ROWS_PER_TASK);
    let mut blocks: Vec<Outs<'_>> = Vec::with_capacity(tasks);
    let (mut a, mut b) = outs;
    for t in 0..tasks {
        let k = ROWS_PER_TASK.min(rows - t * ROWS_PER_TASK);
        let (x, rest) = std::mem::take(&mut a).split_at_mut(k * w1);
        a = rest;
        let (y, rest) = std::mem::take(&mut b).split_at_mut(k * w2);
        b = rest;
        blocks.push((x, y));
    }
    let first_error = blocks
        .into_par_iter()
        .enumerate()
        .map_init(
            || (Data::new(robot), scratch()),
            |(data, s), (task, (x, y))| {
                let first = task * ROWS_PER_TASK;
                for i in 0..ROWS_PER_TASK.min(rows - first) {
                    let row = first + i;
                    let o = (&mut x[i * w1..(i + 1) * w1], &mut y[i * w2..(i + 1) * w2]);
                    f(data, s, row, o).map_err(|e| (row, Box::new(e)))?;
                }
                Ok(())
            },
        )
        .filter_map(|r: std::result::Result<(), (usize, Box<Error>)>| r.err())
        .min_by_key(|(row, _)| *row);
    match first_error {
        Some((row, e)) => Err((*e).in_row(row + 1)),
        None => Ok(()),
    }
}

/// Inverse dynamic model (eqs 10.3–10.12) of N states: `q`, `qd`, `qdd` and `tau` row-major,
/// N x n (n = [`Robot::dof`], movable joints in frame order), under `env`. Rows run in parallel
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
    let n = robot.dof();
    let rows = count_states(n, [("q", q), ("qd", qd), ("qdd", qdd)])?;
    check_output("tau", tau, rows * n, format!("{rows} states x {n} joints"))?;
    let r = |s: usize| s * n..(s + 1) * n;
    for_each_state(
        robot,
        rows,
        (tau, &mut []),
        (n, 0),
        || (),
        |data, _, s, (out, _)| {
            inverse_dynamics_into(robot, data, env, &q[r(s)], &qd[r(s)], &qdd[r(s)], out)
        },
    )
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
    let n = robot.dof();
    let rows = count_states(n, [("q", q), ("qd", qd), ("tau", tau)])?;
    check_output("qdd", qdd, rows * n, format!("{rows} states x {n} joints"))?;
    let r = |s: usize| s * n..(s + 1) * n;
    for_each_state(
        robot,
        rows,
        (qdd, &mut []),
        (n, 0),
        || (),
        |data, _, s, (out, _)| {
            direct_dynamics_into(
                robot,
                data,
                env,
                &q[r(s)],
                &qd[r(s)],
                &tau[r(s)],
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
    let rows = count_states(n, [("q", q), ("qd", qd), ("qdd", qdd)])?;
    check_output(
        "Phi",
        phi,
        rows * n * cols,
        format!("{rows} states x {n} joints rows, {cols} columns (13 per link), row-major"),
    )?;
    check_output(
        "tau_e",
        tau_e,
        rows * n,
        format!("{rows} states x {n} joints"),
    )?;
    let r = |s: usize| s * n..(s + 1) * n;
    for_each_state(
        robot,
        rows,
        (phi, tau_e),
        (n * cols, n),
        || DMatrix::zeros(n, cols),
        |data, p, s, (phi_s, tau_e_s)| {
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
