"""Cross-check against Pinocchio's Python API on real URDFs (example-robot-data): idm (rnea),
inertia (crba) and ddm (aba) agree to 1e-10 (relative to the largest entry). Pinocchio ignores
URDF damping and friction; robodyn applies them as Fv qd + Fs sign(qd), added here.

Needs `pip install pin example-robot-data`; skipped without them unless
ROBODYN_REQUIRE names them (tests/pinocchio_ref.py; CI sets it)."""

import numpy as np
import pytest

import robodyn

from pinocchio_ref import SKIP, Pin, find, pin

if SKIP is not None:  # pragma: no cover - depends on the machine
    pytest.skip(SKIP, allow_module_level=True)

URDFS = ["ur5_robot.urdf", "panda.urdf", "baxter.urdf", "talos_reduced.urdf", "hyq_no_sensors.urdf", "double_pendulum_continuous.urdf"]


@pytest.mark.parametrize("name", URDFS)
def test_idm_inertia_ddm_match_pinocchio(name):
    path = find(name)
    robot = robodyn.load(path)
    p = Pin(path, robot.joint_names)
    rng = np.random.default_rng(7)
    n = robot.nq
    qs, qds, qdds = (rng.uniform(-1, 1, (6, n)) for _ in range(3))
    taus = robot.idm(qs, qds, qdds)
    inertias = robot.inertia(qs)
    worst = 0.0
    for r in range(len(qs)):
        q, qd, qdd = qs[r], qds[r], qdds[r]
        pq, pv, pa = p.q(q), p.v(qd), p.v(qdd)
        tau_pin = pin.rnea(p.model, p.data, pq, pv, pa) + p.drive(qd)
        tau_pin = tau_pin[p.iv]
        scale = max(1.0, np.abs(tau_pin).max())
        assert np.abs(tau_pin).max() > 1e-3
        np.testing.assert_allclose(taus[r], tau_pin, rtol=0, atol=1e-10 * scale)
        worst = max(worst, np.abs(taus[r] - tau_pin).max() / scale)
        a_pin = pin.crba(p.model, p.data, pq)
        a_pin = np.triu(a_pin) + np.triu(a_pin, 1).T
        a_pin = a_pin[np.ix_(p.iv, p.iv)] + np.diag(p.model.armature[p.iv])
        np.testing.assert_allclose(inertias[r], a_pin, rtol=0, atol=1e-10 * max(1.0, np.abs(a_pin).max()))
        tau = rng.uniform(-5, 5, n)
        qdd_pin = pin.aba(p.model, p.data, pq, pv, p.v(tau) - p.drive(qd))[p.iv]
        for method in ["composite", "aba"]:
            ours = robot.ddm(q, qd, tau, method=method)
            np.testing.assert_allclose(ours, qdd_pin, rtol=0, atol=1e-10 * max(1.0, np.abs(qdd_pin).max()))
    print(f"{name}: worst relative idm difference to pinocchio.rnea {worst:.2e}")
