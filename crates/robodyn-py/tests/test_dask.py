"""Identification of a fleet on Dask: the statistics of 200 simulated logs of the TX40 (a tree
with a coupled wrist) and of the SR400 (a closed chain) computed by a LocalCluster of 2 worker
processes (robodyn.ident_statistics, pickled between processes; each worker builds the parameter
model once per robot and options), merged by identify_from_statistics, equal the single-process
identify of the 200 logs to 1e-10. IdentStatisticsBuilder gives ident_statistics' numbers.

Needs `distributed` (pip install distributed): skips visibly without it, and fails with
ROBODYN_REQUIRE=all (or a list naming `dask`), as CI runs it.
"""

import os

import numpy as np
import pytest

import robodyn
from conftest import robot_path
from test_identification import fourier_log

try:
    from distributed import Client, LocalCluster
except ImportError as e:  # pragma: no cover - depends on the machine
    keys = [k.strip() for k in os.environ.get("ROBODYN_REQUIRE", "").split(",")]
    if "all" in keys or "dask" in keys:
        raise
    pytest.skip(f"distributed not installed ({e}): pip install distributed", allow_module_level=True)


def noisy_logs(robot, count, sd=0.05):
    logs = []
    for k in range(count):
        log = fourier_log(robot, 1000 + k, duration=2.0)
        rng = np.random.default_rng(k)
        for j in range(robot.nq):
            log[f"tau{j + 1}"] = log[f"tau{j + 1}"] + rng.normal(0.0, sd, len(log["t"]))
        logs.append(log)
    return logs


def closed_chain_logs(chain, count, sd=0.05, duration=2.0, dt=0.004):
    """Logs of a closed chain: q_a(t) a sum of sines about the assembly's q_a, torques of the
    actuated joints from ClosedChain.idm (loop closure on the assembly branch) plus noise."""
    q0 = np.array(chain.branch["q_a"])
    t = np.arange(0.0, duration, dt)
    logs = []
    for k in range(count):
        rng = np.random.default_rng(2000 + k)
        n = chain.nq
        q = np.tile(q0, (len(t), 1)); qd = np.zeros_like(q); qdd = np.zeros_like(q)
        for h in range(1, 5):
            w = 2 * np.pi * h / 2.0
            a, b = rng.uniform(-0.25, 0.25, (2, n)) / h
            s, c = np.sin(w * t)[:, None], np.cos(w * t)[:, None]
            q += a * s + b * (c - 1.0)
            qd += w * (a * c - b * s)
            qdd += -w * w * (a * s + b * c)
        chain.reset()
        tau = chain.idm(q, qd, qdd) + rng.normal(0.0, sd, (len(t), n))
        log = {"t": t}
        for i, j in enumerate(chain.joint_frames):
            log[f"q{j}"], log[f"qd{j}"], log[f"qdd{j}"], log[f"tau{j}"] = q[:, i], qd[:, i], qdd[:, i], tau[:, i]
        logs.append(log)
    return logs


def fleet_equals_one_process(path, logs, options):
    single = robodyn.identify(path, logs, **options)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            futures = client.map(lambda log: robodyn.ident_statistics(path, log, **options), logs)
            stats = client.gather(futures)
            workers = {w for w in client.who_has(futures).values() for w in w}
    assert len(workers) == 2, workers
    fleet = robodyn.identify_from_statistics(path, stats, **options)
    scale = np.maximum(np.abs(single.values), 1e-3 * np.abs(single.values).max())
    assert np.max(np.abs(fleet.values - single.values) / scale) < 1e-10
    np.testing.assert_allclose(fleet.std, single.std, rtol=1e-10)
    assert [j["rows"] for j in fleet.per_joint] == [j["rows"] for j in single.per_joint]
    assert abs(fleet.validation["relative_error"] - single.validation["relative_error"]) < 1e-10
    return fleet


def test_tx40_fleet_on_a_local_cluster_equals_one_process():
    path = str(robot_path("tx40.toml"))
    fleet = fleet_equals_one_process(path, noisy_logs(robodyn.load(path), 200), dict(offsets=True))
    assert fleet.report["processing"]["samples"] == 200 * 500


def test_sr400_closed_chain_fleet_on_a_local_cluster_equals_one_process():
    path = str(robot_path("sr400.toml"))
    chain = robodyn.ClosedChain(robodyn.load(path))
    fleet = fleet_equals_one_process(path, closed_chain_logs(chain, 200), dict(rotor="none"))
    assert fleet.report["processing"]["samples"] == 200 * 500


def test_builder_gives_the_numbers_of_ident_statistics():
    path = str(robot_path("tx40.toml"))
    logs = noisy_logs(robodyn.load(path), 3)
    builder = robodyn.IdentStatisticsBuilder(path, offsets=True)
    for log in logs:
        assert builder(log).to_json() == robodyn.ident_statistics(path, log, offsets=True).to_json()
    other = robodyn.ident_statistics(path, logs[0], offsets=False)
    assert other.to_json() != builder(logs[0]).to_json()
