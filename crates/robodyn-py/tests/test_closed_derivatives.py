"""ClosedChain.idm_derivatives / ddm_derivatives: against central differences of the closed
models along the branch (ClosedChain.idm / ddm at q_a +- h e_k, each from a fresh chain so the
tracker re-closes the loops from the assembly; h = 1e-4, truncation ~1e-9, bound 2e-6
relative), A against the closed inertia matrix route (ddm's linearity in tau), Ainv A_cl = I,
and the batch shape (N, n, n)."""

import numpy as np
import pytest

import robodyn
from conftest import robot_path

H = 1e-4


def state(chain, third):
    qa0 = np.array(chain.branch["q_a"])
    n = chain.nq
    k = np.arange(n)
    return qa0 + 0.1 * (k + 1), 0.5 - 0.3 * k, third * (1.0 - 0.7 * k)


def central(robot, f, x, which):
    n = len(x[0])
    m = np.zeros((n, n))
    for k in range(n):
        vals = []
        for s in (H, -H):
            y = [np.array(v, dtype=float) for v in x]
            y[which][k] += s
            vals.append(f(robodyn.ClosedChain(robot), *y))
        m[:, k] = (vals[0] - vals[1]) / (2 * H)
    return m


def rel(m, e):
    return np.abs(m - e).max() / max(np.abs(e).max(), 1.0)


@pytest.mark.parametrize("name", ["fivebar.toml", "spatial_loop.toml", "twoloops.toml"])
def test_closed_derivatives_match_finite_differences_along_the_branch(name):
    robot = robodyn.load(robot_path(name))
    chain = robodyn.ClosedChain(robot)
    x = state(chain, 2.0)
    dq, dqd, a = chain.idm_derivatives(*x)
    n = chain.nq
    assert dq.shape == dqd.shape == a.shape == (n, n)
    idm = lambda c, *y: c.idm(*y)  # noqa: E731
    assert rel(dq, central(robot, idm, x, 0)) < 2e-6
    assert rel(dqd, central(robot, idm, x, 1)) < 2e-6
    # A_cl: ddm is affine in tau with slope A_cl^-1
    tau = chain.idm(*x)
    ddm = lambda c, *y: c.ddm(*y)  # noqa: E731
    xd = (x[0], x[1], tau)
    ainv_fd = central(robot, ddm, xd, 2)
    assert np.abs(ainv_fd @ a - np.eye(n)).max() < 1e-6
    ddq, ddqd, ainv = chain.ddm_derivatives(*xd)
    assert np.abs(ainv @ a - np.eye(n)).max() < 1e-10
    assert rel(ddq, central(robot, ddm, xd, 0)) < 2e-6
    assert rel(ddqd, central(robot, ddm, xd, 1)) < 2e-6
    assert rel(ddq, -ainv @ dq) < 1e-9


def test_closed_derivatives_of_a_batch_follow_the_branch():
    robot = robodyn.load(robot_path("fivebar.toml"))
    chain = robodyn.ClosedChain(robot)
    q, qd, qdd = state(chain, 1.0)
    s = np.linspace(0.0, 0.2, 5)[:, None]
    qs, qds, qdds = q + s, np.tile(qd, (5, 1)), np.tile(qdd, (5, 1))
    dq, dqd, a = chain.idm_derivatives(qs, qds, qdds)
    assert dq.shape == (5, 2, 2) and a.shape == (5, 2, 2)
    for i in range(5):
        one = robodyn.ClosedChain(robot).idm_derivatives(qs[i], qds[i], qdds[i])
        assert rel(dq[i], one[0]) < 1e-9
    with pytest.raises(Exception):
        chain.idm_derivatives(np.zeros(3))
