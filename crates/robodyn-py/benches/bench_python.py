"""Python call overhead and batch throughput of robodyn against Pinocchio's Python API on the
UR5 (example-robot-data). Not run by CI (timings on a shared machine).

    python crates/robodyn-py/benches/bench_python.py [--rows 100000] [--repeat 7]

1. one state: robot.idm(q, qd, qdd) vs pin.rnea(model, data, q, v, a) per call (medians of
   `repeat` runs of a timed loop; the same NumPy inputs);
2. 100,000 states: robot.idm on (N, 6) arrays (one call, all cores) vs a Python loop over
   pin.rnea, and vs robodyn's own single-state loop.
"""

import argparse
import os
import pathlib
import statistics
import time

import numpy as np

import cmeel
import pinocchio as pin
import robodyn

ERD = pathlib.Path(os.path.dirname(os.path.dirname(cmeel.__file__))) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"


def per_call(fs, calls, repeat):
    """Median seconds per call of each function; the runs alternate between the functions so
    that a change of the machine's load hits both alike."""
    times = [[] for _ in fs]
    for _ in range(repeat):
        for k, f in enumerate(fs):
            t0 = time.perf_counter()
            for _ in range(calls):
                f()
            times[k].append((time.perf_counter() - t0) / calls)
    return [statistics.median(t) for t in times]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rows", type=int, default=100_000)
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--calls", type=int, default=20_000)
    a = ap.parse_args()
    path = next(ERD.rglob("ur5_robot.urdf"))
    robot = robodyn.load(path)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    names = robot.joint_names
    iv = [model.joints[model.getJointId(n)].idx_v for n in names]
    assert iv == list(range(6)) and model.nq == 6, "same joint order (revolute joints)"
    rng = np.random.default_rng(1)
    q, qd, qdd = (rng.uniform(-1, 1, 6) for _ in range(3))
    # same result (UR5 has no damping/friction in the URDF: checked)
    assert not model.damping.any() and not model.friction.any()
    assert np.allclose(robot.idm(q, qd, qdd), pin.rnea(model, data, q, qd, qdd), atol=1e-10)

    t_rd, t_pin = per_call([lambda: robot.idm(q, qd, qdd), lambda: pin.rnea(model, data, q, qd, qdd)], a.calls, a.repeat)
    print(f"one state, UR5: robodyn.idm {t_rd * 1e6:.2f} us/call, pin.rnea {t_pin * 1e6:.2f} us/call, "
          f"ratio {t_rd / t_pin:.2f}")

    Q, QD, QDD = (rng.uniform(-1, 1, (a.rows, 6)) for _ in range(3))
    times = []
    for _ in range(a.repeat):
        t0 = time.perf_counter()
        TAU = robot.idm(Q, QD, QDD)
        times.append(time.perf_counter() - t0)
    t_batch = statistics.median(times)

    def pin_loop():
        out = np.empty((a.rows, 6))
        for r in range(a.rows):
            out[r] = pin.rnea(model, data, Q[r], QD[r], QDD[r])
        return out

    times = []
    for _ in range(max(1, a.repeat // 2)):
        t0 = time.perf_counter()
        ref = pin_loop()
        times.append(time.perf_counter() - t0)
    t_loop = statistics.median(times)
    assert np.allclose(TAU, ref, atol=1e-9)
    t0 = time.perf_counter()
    for r in range(a.rows):
        robot.idm(Q[r], QD[r], QDD[r])
    t_own = time.perf_counter() - t0
    print(f"{a.rows} states, UR5: robodyn batch {t_batch * 1e3:.1f} ms ({a.rows / t_batch / 1e6:.2f} M states/s, "
          f"{os.cpu_count()} cores); Python loop over pin.rnea {t_loop * 1e3:.1f} ms "
          f"({a.rows / t_loop / 1e6:.2f} M states/s); speed-up {t_loop / t_batch:.1f}x; "
          f"Python loop over robodyn.idm {t_own * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
