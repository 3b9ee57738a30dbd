"""Closed chains on the bundled robots: torques against the CLI (`robodyn idm`, the same rows
from the robot's assembly), ddm inverts idm, loop closure against finite differences (W), the
tracker's branch, batches following one branch, errors and warnings."""

import csv
import os
import shutil
import subprocess

import numpy as np
import pytest

import robodyn
from conftest import CLOSED, ROOT, cli, robot_path


def trajectory(chain, rows=12):
    """A path from the assembly's actuated values (small steps: reachable on the branch)."""
    qa0 = np.array(chain.branch["q_a"])
    s = np.linspace(0.0, 1.0, rows)[:, None]
    n = chain.nq
    qa = qa0 + 0.2 * np.sin(np.arange(1, n + 1) + 3 * s) * s
    qd = np.cos(np.arange(n) + s)
    qdd = np.sin(2 * np.arange(n) + s)
    return qa, qd, qdd


@pytest.mark.parametrize("name", CLOSED)
def test_closed_idm_matches_the_cli(name, tmp_path):
    robot = robodyn.load(robot_path(name))
    chain = robodyn.ClosedChain(robot)
    qa, qd, qdd = trajectory(chain)
    tau = chain.idm(qa, qd, qdd)
    assert tau.shape == qa.shape
    assert np.abs(tau).max() > 1e-3
    frames = chain.joint_frames
    inp = tmp_path / "states.csv"
    with open(inp, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow([f"{p}{j}" for p in ["q", "qd", "qdd"] for j in frames])
        for r in range(len(qa)):
            w.writerow([repr(float(x)) for x in np.concatenate([qa[r], qd[r], qdd[r]])])
    out = tmp_path / "tau.csv"
    subprocess.run(cli() + ["idm", str(robot_path(name)), "--input", str(inp), "--output", str(out)], check=True, cwd=ROOT)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    theirs = np.array([[float(r[f"tau{j}"]) for j in frames] for r in rows])
    np.testing.assert_allclose(tau, theirs, rtol=0, atol=1e-10 * max(1.0, np.abs(theirs).max()))


@pytest.mark.parametrize("name", CLOSED)
def test_closed_ddm_inverts_idm_and_batches_follow_the_branch(name):
    chain = robodyn.ClosedChain(robodyn.load(robot_path(name)))
    qa, qd, qdd = trajectory(chain)
    tau = chain.idm(qa, qd, qdd)
    chain.reset()
    back = chain.ddm(qa, qd, tau)
    np.testing.assert_allclose(back, qdd, atol=1e-7 * max(1.0, np.abs(qdd).max()))
    # one state at a time along the same path = the batch
    chain.reset()
    for r in range(len(qa)):
        np.testing.assert_allclose(chain.idm(qa[r], qd[r], qdd[r]), tau[r], rtol=0, atol=1e-9 * max(1.0, np.abs(tau).max()))
    np.testing.assert_allclose(chain.branch["q_a"], qa[-1])


@pytest.mark.parametrize("name", CLOSED)
def test_loop_closure_jacobian_by_finite_differences(name):
    chain = robodyn.ClosedChain(robodyn.load(robot_path(name)))
    qa = np.array(chain.branch["q_a"]) + 0.05
    sol = chain.closure(qa)
    w = sol["W"]
    assert w.shape == (chain.n_equations, chain.nq)
    assert sol["residual"] < 1e-10
    np.testing.assert_allclose(chain.solve_loops(qa), sol["q_p"], atol=1e-12)
    # central differences: truncation ~ h^2, the loop solver's tolerance / h: h = 1e-4 balances
    # both near 1e-8 (h = 1e-6 left 1e-6 of solver noise on the five-bar)
    h = 1e-4
    for k in range(chain.nq):
        e = np.zeros(chain.nq)
        e[k] = h
        plus = chain.solve_loops(qa + e)
        minus = chain.solve_loops(qa - e)
        np.testing.assert_allclose((plus - minus) / (2 * h), w[:, k], atol=1e-6)
    batch = chain.solve_loops(np.array([qa, qa + 0.01, qa + 0.02]))
    assert batch.shape == (3, chain.n_equations)


def test_closed_regressor_times_parameters_is_idm():
    robot = robodyn.load(robot_path("sr400.toml"))
    chain = robodyn.ClosedChain(robot)
    qa, qd, qdd = trajectory(chain, rows=4)
    tau = chain.idm(qa, qd, qdd)
    chain.reset()
    phi = chain.regressor(qa, qd, qdd)
    assert phi.shape == (4 * chain.nq, 13 * robot.nl)
    np.testing.assert_allclose(phi @ np.array(robot.standard_parameters), tau.reshape(-1), atol=1e-8 * np.abs(tau).max())


def test_closed_simulation_keeps_the_loops_closed():
    chain = robodyn.ClosedChain(robodyn.load(robot_path("fourbar.toml")))
    # from rest, the four-bar's Coulomb friction sticks: the adaptive integrator refuses (step
    # limit) instead of crawling; fixed-step RK4 runs through it
    with pytest.raises(robodyn.NumericalError, match="integration steps"):
        chain.simulate(0.3, output_dt=0.05, max_steps=2000)
    traj = chain.simulate(0.3, output_dt=0.05, dt=1e-3)
    assert traj["q"].shape == (7, 1)
    assert np.all(traj["closure_residual"] < 1e-9)
    assert np.isfinite(traj["energy"]).all()


def test_tree_methods_refused_on_a_tree_chain():
    with pytest.raises(robodyn.Error):
        robodyn.ClosedChain(robodyn.load(robot_path("rx90.toml")))


def test_singular_start_and_branch_lost():
    chain = robodyn.ClosedChain(robodyn.load(robot_path("fourbar.toml")))
    start = np.array(chain.branch["q_a"])
    # a failing row of a batch is named (1-based); the rows before it were evaluated
    rows = np.array([[start[0]], [start[0] + 0.01], [np.nan]])
    with pytest.raises(robodyn.NotFiniteError) as e:
        chain.idm(rows)
    assert e.value.row == 3
    # the tracker stays at its last good point: evaluations continue from there
    chain.reset()
    np.testing.assert_allclose(chain.branch["q_a"], start)


@pytest.mark.parametrize("name", ["sr400.toml", "fivebar.toml", "spatial_loop.toml"])
def test_closed_drift_is_the_derivative_of_the_actuated_jacobian(name):
    """drift(q_a, qd_a) = d/dt J_a(q_a + t qd_a) qd_a at t = 0, by central differences of
    ClosedChain.jacobian (h = 1e-4: truncation ~h^2 |J'''| ~ 1e-8, the loop solver's
    tolerance / h ~ 1e-8); a missing term of the drift changes it by O(|qd|^2) ~ 0.1."""
    robot = robodyn.load(robot_path(name))
    chain = robodyn.ClosedChain(robot)
    qa = np.array(chain.branch["q_a"]) + 0.1
    qd = 0.8 * np.cos(np.arange(chain.nq) + 1.0)
    h = 1e-4
    frames = [f for f in robot.frame_names if f not in ("0",)][:4] + [robot.frame_names[-1]]
    for frame in frames:
        for ref in ("world", "local", "local_world_aligned"):
            d = chain.drift(qa, qd, frame, ref)
            assert d.shape == (6,)
            jp = chain.jacobian(qa + h * qd, frame, ref)
            jm = chain.jacobian(qa - h * qd, frame, ref)
            fd = (jp - jm) / (2 * h) @ qd
            np.testing.assert_allclose(d, fd, rtol=0, atol=1e-6 * max(1.0, np.abs(fd).max()),
                                       err_msg=f"{name} {frame} {ref}")
    batch = chain.drift(np.array([qa, qa + 0.01]), np.array([qd, qd]), frames[-1])
    assert batch.shape == (2, 6)
