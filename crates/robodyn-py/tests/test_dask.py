"""Identification of a fleet on Dask: the statistics of 20 simulated TX40 logs computed by a
LocalCluster of 2 worker processes (robodyn.ident_statistics, pickled between processes), merged
by identify_from_statistics, equal the single-process identify of the 20 logs to 1e-10.

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


def test_fleet_on_a_local_cluster_equals_one_process():
    path = str(robot_path("tx40.toml"))
    logs = noisy_logs(robodyn.load(path), 20)
    options = dict(offsets=True)
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
