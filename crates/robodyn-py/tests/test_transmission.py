"""Robots with a motor-joint transmission from Python (robodyn.load of a [transmission] file):
idm, ddm, inertia apply it through the library's one path. Cross-checks: the TX40 (coupled wrist,
motor 6 turning with q5 + q6) with motors' IA, FS, FV against the links alone (the same file
without drive parameters) plus R^T (IA R qdd + FV R qd + FS sign(R qd)) computed here with NumPy;
ddm inverts idm; A(q) is the links' plus R^T IA R; the derivatives refuse (not applied yet)."""

import numpy as np
import pytest

import robodyn
from conftest import robot_path

R = np.array(
    [
        [32, 0, 0, 0, 0, 0],
        [0, 32, 0, 0, 0, 0],
        [0, 0, 45, 0, 0, 0],
        [0, 0, 0, -48, 0, 0],
        [0, 0, 0, 0, 45, 0],
        [0, 0, 0, 0, 32, 32],
    ],
    dtype=float,
)
IA = np.array([3e-5, 3e-5, 5e-5, 1.2e-5, 1.8e-5, 9e-6])
FS = np.array([0.2, 0.25, 0.12, 0.04, 0.06, 0.07])
FV = np.array([8e-3, 5e-3, 1e-3, 5e-4, 6e-4, 6e-4])
LINK6 = dict(XX6=1e-3, YY6=1e-3, ZZ6=1e-3)


def motors():
    v = dict(LINK6)
    for j in range(6):
        v[f"IA{j + 1}"] = IA[j]
        v[f"FS{j + 1}"] = FS[j]
        v[f"FV{j + 1}"] = FV[j]
    return v


def test_tx40_models_apply_the_transmission(rng):
    tx40 = robodyn.load(robot_path("tx40.toml"), **motors())
    links = robodyn.load(robot_path("tx40.toml"), **LINK6)
    for _ in range(5):
        q, qd, qdd = (rng.uniform(-1, 1, 6) for _ in range(3))
        md, mdd = R @ qd, R @ qdd
        drives = R.T @ (IA * mdd + FV * md + FS * np.sign(md))
        tau = tx40.idm(q, qd, qdd)
        np.testing.assert_allclose(tau, links.idm(q, qd, qdd) + drives, rtol=1e-12, atol=1e-12)
        assert abs(drives[5]) > 1e-2  # the motors matter here
        for method in ["composite", "aba"]:
            np.testing.assert_allclose(tx40.ddm(q, qd, tau, method=method), qdd, atol=1e-9)
        np.testing.assert_allclose(tx40.inertia(q), links.inertia(q) + R.T @ np.diag(IA) @ R, atol=1e-14)
    # N states at once: the same path
    Q, QD, QDD = (rng.uniform(-1, 1, (4, 6)) for _ in range(3))
    np.testing.assert_allclose(
        tx40.idm(Q, QD, QDD), np.array([tx40.idm(Q[k], QD[k], QDD[k]) for k in range(4)]), rtol=1e-14
    )
    # what does not apply transmissions refuses
    with pytest.raises(robodyn.Error, match="transmission"):
        tx40.idm_derivatives(Q[0], QD[0], QDD[0])
    with pytest.raises(robodyn.Error, match="transmission"):
        tx40.regressor(Q[0], QD[0], QDD[0])
