"""Per-call cost of robodyn's Python idm against Pinocchio's Python rnea, in one process, in
paired rounds (the two alternate, so that a change of the machine's load hits both alike), and
the batch throughput. Not run by CI (timings on a shared machine).

    python crates/robodyn-py/benches/bench_python.py [--rounds 31] [--calls 20000] [--rows 100000]

1. One state on the UR5 (example-robot-data): robot.idm(q, qd, qdd), the same with out=, and
   pin.rnea(model, data, q, v, a); the same NumPy inputs, the results checked equal.
2. The binding's own cost, per call: the same calls on a one-joint robot (one URDF loaded by
   both), where the dynamics costs a few nanoseconds and the call is almost all conversion of
   arguments and result.
3. 100,000 UR5 states: one robot.idm call on (N, 6) arrays (all cores) vs a Python loop over
   pin.rnea.

Each line gives the medians over rounds of the per-call times (µs) and the median of the
per-round ratios robodyn / Pinocchio with its range.
"""

import argparse
import os
import pathlib
import statistics
import tempfile
import time
import timeit

import numpy as np

import cmeel
import pinocchio as pin
import robodyn

ERD = pathlib.Path(os.path.dirname(os.path.dirname(cmeel.__file__))) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"

ONE_JOINT = """<robot name="one joint">
  <link name="base"/>
  <link name="arm"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="10" velocity="10"/></joint>
</robot>"""


def paired(fs, rounds, calls):
    """Per-call seconds of each function in each round, the functions alternating."""
    times = {k: [] for k in fs}
    for _ in range(rounds):
        for k, f in fs.items():
            times[k].append(timeit.timeit(f, number=calls) / calls)
    return times


def report(title, times, ref):
    print(title)
    for k, t in times.items():
        ratios = [a / b for a, b in zip(t, times[ref])]
        line = f"  {k:<32} {statistics.median(t) * 1e6:6.3f} µs/call"
        if k != ref:
            line += (f"   ratio to {ref}: {statistics.median(ratios):.2f} "
                     f"({min(ratios):.2f}-{max(ratios):.2f})")
        print(line)


def models(path):
    robot = robodyn.load(path)
    model = pin.buildModelFromUrdf(str(path))
    assert model.nq == model.nv == robot.nq, "revolute joints only"
    assert [model.names[i] for i in range(1, model.njoints)] == robot.joint_names, "same order"
    return robot, model, model.createData()


def calls(robot, model, data, rng):
    q, qd, qdd = (rng.uniform(-1, 1, robot.nq) for _ in range(3))
    out = np.empty(robot.nq)
    # the same numbers (friction=False: Pinocchio's rnea leaves the URDF's <dynamics> out)
    assert np.allclose(robot.idm(q, qd, qdd, friction=False), pin.rnea(model, data, q, qd, qdd),
                       rtol=0, atol=1e-10)
    return {
        "pin.rnea(model, data, q, v, a)": lambda: pin.rnea(model, data, q, qd, qdd),
        "robot.idm(q, qd, qdd)": lambda: robot.idm(q, qd, qdd),
        "robot.idm(q, qd, qdd, out=out)": lambda: robot.idm(q, qd, qdd, out=out),
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=31)
    ap.add_argument("--calls", type=int, default=20_000)
    ap.add_argument("--rows", type=int, default=100_000)
    a = ap.parse_args()
    rng = np.random.default_rng(1)
    ref = "pin.rnea(model, data, q, v, a)"

    ur5 = models(next(ERD.rglob("ur5_robot.urdf")))
    report(f"UR5, one state ({a.rounds} paired rounds of {a.calls} calls):",
           paired(calls(*ur5, rng), a.rounds, a.calls), ref)

    with tempfile.TemporaryDirectory() as d:
        path = pathlib.Path(d) / "one_joint.urdf"
        path.write_text(ONE_JOINT)
        one = models(path)
    report("One joint, one state (the binding's cost per call):",
           paired(calls(*one, rng), a.rounds, a.calls), ref)

    robot, model, data = ur5
    Q, QD, QDD = (rng.uniform(-1, 1, (a.rows, 6)) for _ in range(3))

    def pin_loop():
        out = np.empty((a.rows, 6))
        for r in range(a.rows):
            out[r] = pin.rnea(model, data, Q[r], QD[r], QDD[r])
        return out

    t_batch, t_loop = [], []
    for _ in range(max(3, a.rounds // 6)):
        t0 = time.perf_counter()
        tau = robot.idm(Q, QD, QDD, friction=False)
        t_batch.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        ref_tau = pin_loop()
        t_loop.append(time.perf_counter() - t0)
    assert np.allclose(tau, ref_tau, atol=1e-9)
    tb, tl = statistics.median(t_batch), statistics.median(t_loop)
    print(f"UR5, {a.rows} states: robot.idm on (N, 6) {tb * 1e3:.1f} ms ({a.rows / tb / 1e6:.2f} M "
          f"states/s, {os.cpu_count()} cores); Python loop over pin.rnea {tl * 1e3:.1f} ms "
          f"({a.rows / tl / 1e6:.2f} M states/s): {tl / tb:.1f}x")


if __name__ == "__main__":
    main()
