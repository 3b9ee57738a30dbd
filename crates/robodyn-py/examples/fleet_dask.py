"""Identify a fleet of robots from many logs on Dask (map-reduce on the sufficient statistics).

Each log's statistics (per joint, the triangular factor of [W y]: W^T W, W^T y, y^T y carried
without squaring the condition number) are computed on a worker by robodyn.ident_statistics;
robodyn.identify_from_statistics merges them into the numbers of robodyn.identify of all the
logs. The logs here are simulated: a TX40 (bundled robot file) moving along random Fourier
trajectories, torques from robodyn's inverse dynamics (Newton-Euler, with the file's friction)
plus white Gaussian noise of 0.05 N m. Run from the repository's root:

    pip install ./crates/robodyn-py distributed
    python crates/robodyn-py/examples/fleet_dask.py --logs 200 --workers 2
"""

import argparse
import time

import numpy as np
from distributed import Client, LocalCluster

import robodyn

ROBOT = "robots/tx40.toml"
OPTIONS = dict(offsets=True)


def simulated_log(robot, seed, duration=2.0, dt=0.004, noise=0.05):
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, dt)
    n = robot.nq
    q, qd, qdd = (np.zeros((len(t), n)) for _ in range(3))
    for k in range(1, 5):
        w = 2 * np.pi * k / 2.0
        a, b = rng.uniform(-0.4, 0.4, (2, n)) / k
        s, c = np.sin(w * t)[:, None], np.cos(w * t)[:, None]
        q += a * s + b * c
        qd += w * (a * c - b * s)
        qdd += -w * w * (a * s + b * c)
    tau = robot.idm(q, qd, qdd) + rng.normal(0.0, noise, (len(t), n))
    log = {"t": t}
    for j in range(n):
        log[f"q{j + 1}"], log[f"qd{j + 1}"] = q[:, j], qd[:, j]
        log[f"qdd{j + 1}"], log[f"tau{j + 1}"] = qdd[:, j], tau[:, j]
    return log


def statistics(seed):
    """On a worker: simulate log `seed` and return its statistics (a small picklable object)."""
    return robodyn.ident_statistics(ROBOT, simulated_log(robodyn.load(ROBOT), seed), **OPTIONS)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--logs", type=int, default=200)
    p.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    a = p.parse_args()
    seeds = list(range(a.logs))
    results = {}
    for workers in a.workers:
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
            with Client(cluster) as client:
                client.submit(statistics, 0).result()  # warm the workers (import, first load)
                start = time.perf_counter()
                stats = client.gather(client.map(statistics, seeds))
                fleet = robodyn.identify_from_statistics(ROBOT, stats, **OPTIONS)
                elapsed = time.perf_counter() - start
        results[workers] = fleet
        print(f"{workers} worker(s): {a.logs} logs in {elapsed:.2f} s")
    # the single-process identification of the same logs
    robot = robodyn.load(ROBOT)
    start = time.perf_counter()
    single = robodyn.identify(ROBOT, [simulated_log(robot, s) for s in seeds], **OPTIONS)
    print(f"one process, robodyn.identify of the {a.logs} logs: {time.perf_counter() - start:.2f} s")
    for workers, fleet in results.items():
        scale = np.maximum(np.abs(single.values), 1e-3 * np.abs(single.values).max())
        print(f"{workers} worker(s): largest relative difference from one process "
              f"{np.max(np.abs(fleet.values - single.values) / scale):.1e}")
    print(single.text())


if __name__ == "__main__":
    main()
