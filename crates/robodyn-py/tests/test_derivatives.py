"""robot.idm_derivatives and robot.ddm_derivatives: shapes (one state, a batch of states as 3-D
arrays), agreement with central finite differences of robot.idm / robot.ddm(method="aba") on
the bundled trees, and with Pinocchio's computeRNEADerivatives / computeABADerivatives on real
URDFs (friction=False: Pinocchio has none) to 1e-10 relative. The Pinocchio part skips like
test_pinocchio.py."""

import numpy as np
import pytest

import robodyn

from conftest import TREES, robot_path
from pinocchio_ref import SKIP, Pin, find, pin

H = 1e-6


def central(f, x):
    n = len(x)
    cols = []
    for k in range(n):
        e = np.zeros(n)
        e[k] = H
        cols.append((f(x + e) - f(x - e)) / (2 * H))
    return np.stack(cols, axis=1)


def rel(a, b):
    return np.abs(a - b).max() / max(1.0, np.abs(b).max())


@pytest.mark.parametrize("name", TREES)
def test_derivatives_match_finite_differences(name, rng):
    robot = robodyn.load(robot_path(name))
    n = robot.nq
    q, qd, qdd = (rng.uniform(-1, 1, n) for _ in range(3))
    qd += np.where(qd >= 0, 0.1, -0.1)  # Coulomb friction smooth within the step
    dq, dqd, a = robot.idm_derivatives(q, qd, qdd)
    assert dq.shape == dqd.shape == a.shape == (n, n)
    assert rel(dq, central(lambda x: robot.idm(x, qd, qdd), q)) < 1e-6
    assert rel(dqd, central(lambda x: robot.idm(q, x, qdd), qd)) < 1e-6
    np.testing.assert_allclose(a, robot.inertia(q), rtol=0, atol=1e-12 * np.abs(a).max())
    tau = robot.idm(q, qd, qdd)
    try:
        robot.ddm(q, qd, tau)
    except robodyn.SingularConfiguration:  # a file of base parameters (tx40): A singular
        with pytest.raises(robodyn.SingularConfiguration):
            robot.ddm_derivatives(q, qd, tau)
        return
    xq, xqd, ainv = robot.ddm_derivatives(q, qd, tau)
    aba = lambda q_, qd_, t_: robot.ddm(q_, qd_, t_, method="aba")
    assert rel(xq, central(lambda x: aba(x, qd, tau), q)) < 1e-6
    assert rel(xqd, central(lambda x: aba(q, x, tau), qd)) < 1e-6
    assert rel(ainv @ a, np.eye(n)) < 1e-9


def test_batches_are_3d_and_match_single_states(rng):
    robot = robodyn.load(robot_path("rx90.toml"))
    n, rows = robot.nq, 50
    q, qd, qdd = (rng.uniform(-1, 1, (rows, n)) for _ in range(3))
    dq, dqd, a = robot.idm_derivatives(q, qd, qdd)
    assert dq.shape == dqd.shape == a.shape == (rows, n, n)
    assert dq.flags["C_CONTIGUOUS"]
    tau = robot.idm(q, qd, qdd)
    xq, xqd, ainv = robot.ddm_derivatives(q, v=qd, tau=tau)
    assert xq.shape == (rows, n, n)
    for r in [0, 17, rows - 1]:
        one = robot.idm_derivatives(q[r], qd[r], qdd[r])
        for x, y in zip((dq[r], dqd[r], a[r]), one):
            np.testing.assert_array_equal(x, y)
        one = robot.ddm_derivatives(q[r], qd[r], tau[r])
        for x, y in zip((xq[r], xqd[r], ainv[r]), one):
            np.testing.assert_array_equal(x, y)
    with pytest.raises(Exception, match="q"):
        robot.idm_derivatives(q[:, :3])


@pytest.mark.skipif(SKIP is not None, reason=str(SKIP))
@pytest.mark.parametrize("name", ["ur5_robot.urdf", "panda.urdf", "talos_reduced.urdf"])
def test_derivatives_match_pinocchio(name):
    path = find(name)
    robot = robodyn.load(path)
    p = Pin(path, robot.joint_names)
    rng = np.random.default_rng(28)
    n = robot.nq
    ix = np.ix_(p.iv, p.iv)
    sym = lambda m: np.triu(m) + np.triu(m, 1).T
    for _ in range(5):
        q, qd, qdd, tau = (rng.uniform(-1, 1, n) for _ in range(4))
        pq, pv, pa = p.q(q), p.v(qd), p.v(qdd)
        dq, dqd, a = robot.idm_derivatives(q, qd, qdd, friction=False)
        rq, rv, ra = pin.computeRNEADerivatives(p.model, p.data, pq, pv, pa)
        assert rel(dq, rq[ix]) < 1e-10
        assert rel(dqd, rv[ix]) < 1e-10
        assert rel(a, sym(ra)[ix]) < 1e-10
        xq, xqd, ainv = robot.ddm_derivatives(q, qd, tau, friction=False)
        pin.computeABADerivatives(p.model, p.data, pq, pv, p.v(tau))
        assert rel(xq, np.array(p.data.ddq_dq)[ix]) < 1e-10
        assert rel(xqd, np.array(p.data.ddq_dv)[ix]) < 1e-10
        assert rel(ainv, sym(np.array(p.data.Minv))[ix]) < 1e-10
