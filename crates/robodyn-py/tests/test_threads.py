"""Batches release the GIL: while one thread runs a batch in Rust, another Python thread keeps
running, and two threads run batches concurrently. Timings are printed (pytest -s), not asserted:
the machine is shared."""

import threading
import time

import numpy as np

import robodyn
from conftest import robot_path


def test_batches_release_the_gil():
    robot = robodyn.load(robot_path("rx90.toml"))
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-1, 1, (200_000, robot.nq)) for _ in range(3))
    t0 = time.perf_counter()
    expected = robot.idm(q, qd, qdd)
    serial_one = time.perf_counter() - t0

    # another Python thread makes progress while a batch runs (a held GIL would stop it:
    # the batch is a single Rust call)
    done = threading.Event()
    ticks = []

    def ticker():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.0005)

    th = threading.Thread(target=ticker)
    th.start()
    time.sleep(0.01)
    before = len(ticks)
    t_start = time.perf_counter()
    out = robot.idm(q, qd, qdd)
    t_end = time.perf_counter()
    done.set()
    th.join()
    during = [t for t in ticks if t_start < t < t_end]
    np.testing.assert_array_equal(out, expected)
    assert before > 0
    assert len(during) >= 2, f"the other thread did not run during a {t_end - t_start:.3f} s batch"

    # two batches in two threads
    results = [None, None]

    def run(k):
        results[k] = robot.idm(q, qd, qdd)

    threads = [threading.Thread(target=run, args=(k,)) for k in range(2)]
    t0 = time.perf_counter()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    both = time.perf_counter() - t0
    for r in results:
        np.testing.assert_array_equal(r, expected)
    print(f"one batch {serial_one:.3f} s; two batches in two threads {both:.3f} s "
          f"(serial would be {2 * serial_one:.3f} s); other thread ticked {len(during)} times during a batch")
