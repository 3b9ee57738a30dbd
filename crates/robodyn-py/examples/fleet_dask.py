"""Identify a fleet of robots from many logs on Dask (map-reduce on the sufficient statistics).

Each log's statistics (per joint, the triangular factor of [W y]: W^T W, W^T y, y^T y carried
without squaring the condition number) are computed on a worker by robodyn.ident_statistics;
robodyn.identify_from_statistics merges them into the numbers of robodyn.identify of all the
logs. Each worker process builds the robot's parameter model (the numerical base parameters)
once per robot and options and reuses it for every log (robodyn.IdentStatisticsBuilder does the
same explicitly); --rebuild builds it again for every log, as before.

The logs here are simulated: a TX40 (bundled robot file, a tree with a coupled wrist) and an
SR400 (a closed chain, torques of its actuated joints by loop closure) moving along random
Fourier trajectories, torques from robodyn's inverse dynamics (Newton-Euler, with the file's
friction) plus white Gaussian noise of 0.05 N m. Run from the repository's root:

    pip install ./crates/robodyn-py distributed
    python crates/robodyn-py/examples/fleet_dask.py --logs 200 --workers 1 2 --robot tx40 sr400
"""

import argparse
import time

import numpy as np
from distributed import Client, LocalCluster

import robodyn

ROBOTS = {
    "tx40": ("robots/tx40.toml", dict(offsets=True)),
    "sr400": ("robots/sr400.toml", dict(rotor="none")),
}


def fourier(rng, t, q0, amplitude):
    n = len(q0)
    q = np.tile(np.asarray(q0, float), (len(t), 1))
    qd, qdd = np.zeros_like(q), np.zeros_like(q)
    for k in range(1, 5):
        w = 2 * np.pi * k / 2.0
        a, b = rng.uniform(-amplitude, amplitude, (2, n)) / k
        s, c = np.sin(w * t)[:, None], np.cos(w * t)[:, None]
        q += a * s + b * (c - 1.0)
        qd += w * (a * c - b * s)
        qdd += -w * w * (a * s + b * c)
    return q, qd, qdd


def simulated_log(name, seed, duration=2.0, dt=0.004, noise=0.05):
    """Log `seed` of robot `name`: q, qd, qdd of a random Fourier motion and noisy torques."""
    path, _ = ROBOTS[name]
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration, dt)
    robot = robodyn.load(path)
    if robot.is_tree:
        q, qd, qdd = fourier(rng, t, np.zeros(robot.nq), 0.4)
        tau, joints = robot.idm(q, qd, qdd), range(1, robot.nq + 1)
    else:
        chain = robodyn.ClosedChain(robot)
        q, qd, qdd = fourier(rng, t, chain.branch["q_a"], 0.25)
        tau, joints = chain.idm(q, qd, qdd), chain.joint_frames
    tau = tau + rng.normal(0.0, noise, tau.shape)
    log = {"t": t}
    for i, j in enumerate(joints):
        log[f"q{j}"], log[f"qd{j}"] = q[:, i], qd[:, i]
        log[f"qdd{j}"], log[f"tau{j}"] = qdd[:, i], tau[:, i]
    return log


def statistics(name, seed, rebuild=False):
    """On a worker: simulate log `seed` and return its statistics (a small picklable object)."""
    path, options = ROBOTS[name]
    log = simulated_log(name, seed)
    if rebuild:
        # the parameter model built for this log alone
        return robodyn.IdentStatisticsBuilder(path, **options)(log)
    return robodyn.ident_statistics(path, log, **options)


def fleet(name, seeds, workers, rebuild):
    """The fleet's identification on `workers` processes, and the time of the map and reduce."""
    path, options = ROBOTS[name]
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with Client(cluster) as client:
            # warm the workers (import, first load, and the cached model when not rebuilding)
            client.gather([client.submit(statistics, name, 10**6 + k, pure=False) for k in range(2 * workers)])
            start = time.perf_counter()
            stats = client.gather(client.map(statistics, [name] * len(seeds), seeds, [rebuild] * len(seeds)))
            result = robodyn.identify_from_statistics(path, stats, **options)
            return result, time.perf_counter() - start


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--logs", type=int, default=200)
    p.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    p.add_argument("--robot", nargs="+", choices=sorted(ROBOTS), default=["tx40", "sr400"])
    p.add_argument("--rebuild", action="store_true", help="also time the parameter model built per log")
    a = p.parse_args()
    seeds = list(range(a.logs))
    for name in a.robot:
        path, options = ROBOTS[name]
        results = {}
        for rebuild in [False, True] if a.rebuild else [False]:
            for workers in a.workers:
                result, elapsed = fleet(name, seeds, workers, rebuild)
                results[(workers, rebuild)] = result
                how = "model built per log" if rebuild else "model built once per worker"
                print(f"{name}: {workers} worker(s), {how}: {a.logs} logs in {elapsed:.2f} s")
        # the single-process identification of the same logs
        logs = [simulated_log(name, s) for s in seeds]
        start = time.perf_counter()
        single = robodyn.identify(path, logs, **options)
        print(f"{name}: one process, robodyn.identify of the {a.logs} logs: {time.perf_counter() - start:.2f} s")
        scale = np.maximum(np.abs(single.values), 1e-3 * np.abs(single.values).max())
        for (workers, rebuild), result in results.items():
            print(f"{name}: {workers} worker(s){' (rebuild)' if rebuild else ''}: largest relative "
                  f"difference from one process {np.max(np.abs(result.values - single.values) / scale):.1e}")
        print(single.text())


if __name__ == "__main__":
    main()
