"""robodyn.excite (issue 31 item 2) against the CLI's `robodyn excite`: the same design (condition
numbers, binding limit, peaks) and the same trajectory, the arrays equal to the CSV's rows; the
result starts and ends at rest at its start, and respects the velocity and acceleration limits.
Then the designed motion identifies the robot: its torques from the inverse dynamic model,
identified by robodyn.identify, give the base parameters of the robot file."""

import json
import subprocess

import numpy as np
import pytest

import robodyn
from conftest import cli, robot_path

ARGS = dict(period=4.0, harmonics=3, qd_max=1.5, qdd_max=8.0, iterations=150, restarts=4, seed=3, rate=50.0)


def flags(args):
    out = []
    for k, v in args.items():
        out += [f"--{k.replace('_', '-')}", repr(v) if isinstance(v, float) else str(v)]
    return out


def test_excite_equals_the_cli(tmp_path):
    path = robot_path("scara.toml")
    d = robodyn.excite(path, **ARGS)
    csv = tmp_path / "traj.csv"
    run = subprocess.run([*cli(), "excite", str(path), *flags(ARGS), "--output", str(csv), "--format", "json"],
                         capture_output=True, text=True, check=True)
    report = json.loads(run.stdout)
    assert d["condition_number"] == report["condition_number"]
    assert d["initial_condition_number"] == report["initial_condition_number"]
    assert d["evaluations"] == report["evaluations"]
    assert d["binding"] == (report["binding"]["limit"], report["binding"]["joint"])
    peaks = np.array([[p["q"], p["qd"], p["qdd"], p["tau"]] for p in report["peaks"]])
    np.testing.assert_array_equal(d["peaks"], peaks)
    rows = np.genfromtxt(csv, delimiter=",", names=True)
    np.testing.assert_allclose(d["t"], rows["t"], rtol=1e-15, atol=0)
    assert d["q"].shape == (len(rows), 4) and d["joints"] == [1, 2, 3, 4]
    for name in ["q", "qd", "qdd"]:
        for k, j in enumerate(d["joints"]):
            np.testing.assert_allclose(d[name][:, k], rows[f"{name}{j}"], rtol=1e-15, atol=1e-300)


def test_excited_motion_is_at_rest_at_its_ends_within_limits_and_identifies_the_robot():
    path = robot_path("scara.toml")
    d = robodyn.excite(path, **ARGS)
    t, q, qd, qdd = d["t"], d["q"], d["qd"], d["qdd"]
    assert t[0] == 0.0 and t[-1] == pytest.approx(ARGS["period"])
    np.testing.assert_allclose(q[0], q[-1], atol=1e-12)
    assert np.abs(qd[[0, -1]]).max() < 1e-12 and np.abs(qdd[[0, -1]]).max() < 1e-12
    assert np.abs(qd).max() <= ARGS["qd_max"] * (1 + 1e-9)
    assert np.abs(qdd).max() <= ARGS["qdd_max"] * (1 + 1e-9)
    assert 1.0 < d["condition_number"] <= d["initial_condition_number"]
    robot = robodyn.load(path)
    tau = robot.idm(q, qd, qdd)
    log = {"t": t}
    for k, j in enumerate(d["joints"]):
        log[f"q{j}"], log[f"qd{j}"], log[f"qdd{j}"], log[f"tau{j}"] = q[:, k], qd[:, k], qdd[:, k], tau[:, k]
    id = robodyn.identify(path, log, estimator="ols", validation=None, decimation=1)
    truth = robot.base_parameters(method="numeric")
    assert list(id.names) == list(truth.names)
    values = np.array(truth.values)
    err = np.abs(id.values - values) / np.maximum(np.abs(values), 1e-3 * np.abs(values).max())
    assert err.max() < 1e-8, (id.names[int(err.argmax())], err.max())


def test_excite_refuses_missing_limits_and_bad_sampling():
    path = robot_path("scara.toml")
    with pytest.raises(robodyn.InputError, match="velocity limit"):
        robodyn.excite(path, 4.0, 3, qdd_max=8.0)
    with pytest.raises(robodyn.InputError, match="one per actuated joint"):
        robodyn.excite(path, 4.0, 3, qd_max=[1.0, 2.0], qdd_max=8.0)
    with pytest.raises(robodyn.InputError, match="rate"):
        robodyn.excite(path, 4.0, 3, qd_max=1.0, qdd_max=8.0, rate=0.0)
