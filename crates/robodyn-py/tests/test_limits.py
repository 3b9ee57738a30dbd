"""Hostile inputs (issue 24): no abort on memory (item 2: MemoryError), bounded and interruptible
runs (items 4 and 1: the step limit of the CLI, Ctrl-C raises KeyboardInterrupt in simulations,
batches and closed-chain batches), no NaN or inf returned for finite inputs that overflow
(item 9: an error, as ddm and the CLI). The long runs are child processes: a missing bound or
signal check makes them time out instead of hanging the suite."""

import os
import signal
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import robodyn
from conftest import ROOT, cli, robot_path

ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", PYTHONUNBUFFERED="1")


def child(code, timeout=60, sigint_after=None):
    """Run `code` in a child Python; with `sigint_after`, send SIGINT that many seconds after
    the child prints `ready`. Returns (returncode, stdout, stderr); a child still running at
    `timeout` is killed and the test fails."""
    p = subprocess.Popen([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, env=ENV,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        if sigint_after is not None:
            line = p.stdout.readline()
            assert line.strip() == "ready", line + p.stderr.read()
            time.sleep(sigint_after)
            p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        pytest.fail(f"still running after {timeout} s:\n{out}\n{err}")
    return p.returncode, out, err


# --- item 2: MemoryError, never an abort ----------------------------------------------------

def test_a_batch_larger_than_memory_raises_memory_error():
    """r.idm(Z, Z, Z) with Z of 20 M x 6 (the issue's case) under an address-space limit that
    holds Z but not the result: MemoryError, and the interpreter goes on."""
    code = f"""
        import resource, sys
        import numpy as np
        import robodyn
        r = robodyn.load({str(robot_path("rx90.toml"))!r})
        Z = np.zeros((20_000_000, 6))
        vm = int([l for l in open("/proc/self/status") if l.startswith("VmSize")][0].split()[1]) * 1024
        resource.setrlimit(resource.RLIMIT_AS, (vm + 400 * 2**20, resource.RLIM_INFINITY))
        try:
            r.idm(Z, Z, Z)
            print("no error")
        except MemoryError as e:
            print("MemoryError", e)
        print(r.idm(np.zeros(6))[1] != 0)  # still usable
        # a result of 3.5e18 bytes (the inputs a broadcast view)
        huge = np.broadcast_to(np.zeros(6), (2**56, 6))
        try:
            r.idm(huge)
        except MemoryError as e:
            print("MemoryError", e)
    """
    rc, out, err = child(code)
    assert rc == 0, f"rc {rc}: {err}"
    lines = out.splitlines()
    assert lines[0].startswith("MemoryError cannot allocate 120000000 float64"), out
    assert lines[1] == "True"
    assert lines[2].startswith("MemoryError cannot allocate 432345564227567616 float64"), out


# --- item 4: simulations bounded and interruptible ------------------------------------------

def test_simulation_has_the_clis_step_limit():
    robot = robodyn.load(robot_path("rx90.toml"))
    import inspect
    default = inspect.signature(robot.simulate).parameters["max_steps"].default
    help_text = subprocess.run(cli() + ["simulate", "--help"], cwd=ROOT, capture_output=True,
                               text=True).stdout
    assert f"[default: {default}]" in help_text.replace("\n", " "), help_text
    chain = robodyn.ClosedChain(robodyn.load(robot_path("fourbar.toml")))
    assert inspect.signature(chain.simulate).parameters["max_steps"].default == default
    # a run that needs more steps than the limit is refused before it starts
    with pytest.raises(robodyn.NumericalError, match=r"at least 1e12 integration steps.*max_steps = 5000000"):
        robot.simulate(1e9, dt=1e-3)
    with pytest.raises(robodyn.NumericalError, match=r"at least 1e3 integration steps.*max_steps = 100\)"):
        robot.simulate(1.0, dt=1e-3, max_steps=100)
    with pytest.raises(robodyn.NumericalError, match=r"output step"):
        robot.simulate(10.0, output_dt=0.01, max_steps=50)  # adaptive: one step per output row
    with pytest.raises(robodyn.InputError, match="at least 1"):
        robot.simulate(1.0, max_steps=0)
    assert robot.simulate(0.1, dt=1e-3, max_steps=100)["t"][-1] == 0.1


def test_simulate_1e9_is_refused_promptly():
    """The issue's call: `simulate(1e9, dt=1e-3)` ran without a step limit, memory growing."""
    code = f"""
        import robodyn
        r = robodyn.load({str(robot_path("rx90.toml"))!r})
        try:
            r.simulate(1e9, dt=1e-3)
        except robodyn.NumericalError as e:
            print("refused:", e)
    """
    rc, out, err = child(code, timeout=60)
    assert rc == 0 and out.startswith("refused:"), out + err


def test_ctrl_c_stops_a_simulation():
    code = f"""
        import robodyn
        r = robodyn.load({str(robot_path("rx90.toml"))!r})
        print("ready")
        try:
            r.simulate(1e4, dt=1e-4, output_dt=1.0, max_steps=10**9)  # 1e8 RK4 steps: minutes
            print("finished")
        except KeyboardInterrupt:
            print("interrupted")
    """
    rc, out, err = child(code, timeout=30, sigint_after=0.5)
    assert rc == 0 and out.strip() == "interrupted", out + err


# --- batches interruptible (items 4 and 1) ---------------------------------------------------

def batch_code(setup, call, rows, width):
    return f"""
        import numpy as np
        import robodyn
        {setup}
        out = np.full(({rows}, {width}), np.nan)
        print("ready")
        try:
            {call}
            print("finished")
        except KeyboardInterrupt:
            done = int((~np.isnan(out).any(axis=1)).sum())
            print("interrupted", done)
            np.testing.assert_array_equal(out[:done], np.tile(one, (done, 1)))
            assert np.isnan(out[done:]).all()
    """


def test_ctrl_c_stops_a_tree_batch():
    """A batch of 10 M states (seconds of work on all cores) stops at the next block after
    SIGINT: the rows before it are written, the others not."""
    rows = 10_000_000
    setup = f"""r = robodyn.load({str(robot_path("rx90.toml"))!r})
        q = np.broadcast_to(np.linspace(-0.5, 0.5, 6), ({rows}, 6))
        one = r.ddm(q[0], q[0], q[0], method="aba")"""
    call = "r.ddm(q, q, q, method='aba', out=out)"
    rc, out, err = child(batch_code(setup, call, rows, 6), timeout=60, sigint_after=0.3)
    assert rc == 0 and out.startswith("interrupted"), out + err
    assert 0 < int(out.split()[1]) < rows


def test_ctrl_c_stops_a_closed_chain_batch():
    rows = 2_000_000
    setup = f"""c = robodyn.ClosedChain(robodyn.load({str(robot_path("sr400.toml"))!r}))
        qa = np.array(c.branch["q_a"]) + 0.01
        q = np.broadcast_to(qa, ({rows}, 6))
        one = c.idm(qa, qa, qa)"""
    call = "c.idm(q, q, q, out=out)"
    rc, out, err = child(batch_code(setup, call, rows, 6), timeout=60, sigint_after=0.3)
    assert rc == 0 and out.startswith("interrupted"), out + err
    assert 0 < int(out.split()[1]) < rows


def test_a_huge_closed_chain_value_errors_or_finishes_promptly():
    """`ClosedChain(...).idm([1e7, 0, ...])` followed the branch for minutes (1e6: 11 s)."""
    code = f"""
        import robodyn
        c = robodyn.ClosedChain(robodyn.load({str(robot_path("sr400.toml"))!r}))
        try:
            print("result", c.idm([1e7, 0, 0, 0, 0, 0]))
        except robodyn.Error as e:
            print("error", type(e).__name__, e)
    """
    rc, out, err = child(code, timeout=10)
    assert rc == 0 and out.startswith(("result", "error")), out + err


# --- item 9: overflow is an error, never NaN or inf ------------------------------------------

def test_finite_inputs_that_overflow_raise():
    robot = robodyn.load(robot_path("rx90.toml"))
    q, big = np.zeros(6), np.full(6, 1e200)
    calls = {
        "idm": lambda: robot.idm(q, big),
        "h": lambda: robot.h(q, big),
        "regressor": lambda: robot.regressor(q, big),
        "ddm": lambda: robot.ddm(q, big),
        "idm batch": lambda: robot.idm(np.zeros((3, 6)), np.array([np.zeros(6), np.zeros(6), big])),
        "idm friction=False": lambda: robot.idm(q, big, friction=False),
    }
    for name, call in calls.items():
        with pytest.raises((robodyn.NumericalError, robodyn.SingularConfiguration)) as e:
            call()
        assert "overflow" in str(e.value) or "non-finite" in str(e.value), (name, e.value)
    with pytest.raises(robodyn.NumericalError) as e:
        calls["idm batch"]()
    assert e.value.row == 3
    # gravity 1e308: m g overflows
    heavy = robot.with_values(G3=1e308)
    for call in [lambda: heavy.idm(q), lambda: heavy.h(q)]:
        with pytest.raises(robodyn.NumericalError, match="overflow"):
            call()
    # masses of 1.5e308: the composite links' masses overflow
    with pytest.raises(robodyn.NumericalError, match=r"A\[\d, \d\] = (inf|NaN)"):
        robot.with_values(M2=1.5e308, M3=1.5e308).inertia(np.full(6, 0.3))
    # closed chains: the same rule
    chain = robodyn.ClosedChain(robodyn.load(robot_path("sr400.toml")))
    qa = np.array(chain.branch["q_a"])
    with pytest.raises(robodyn.NumericalError, match="overflow"):
        chain.idm(qa, np.full(6, 1e200))
    # finite results stay results
    assert np.isfinite(robot.idm(q, np.full(6, 1e10))).all()
