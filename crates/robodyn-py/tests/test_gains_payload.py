"""Drive gains and payloads from Python: robodyn.identify(..., estimate_gains=True, reference=...)
and robodyn.identify(..., payload=LINK, before=...), the CLI's --estimate-gains and --payload.

Cross-checks: noise-free logs of the RX-90 made by the CLI (excite, then simulate --track of the
robot and of the robot carrying point masses on link 6, given with --set) give back the payload's
10 parameters, computed here from the point masses' definitions, and the drive gains the currents
were divided by (currents = torques / gains, written here); the CLI's JSON report of the same
identification has the same numbers as the Python result's report.
"""

import json
import subprocess

import numpy as np
import pytest

import robodyn
from conftest import cli, robot_path

NAMES = ["XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M"]
GAINS = np.array([31.0, 47.0, 22.0, 7.5, 6.2, 3.9])
COMMON = dict(estimator="ols", validation=None)
CLI_COMMON = ["--estimator", "ols", "--validation", "none"]


def point_masses():
    """The payload's standard parameters about O_6 in R_6, from the point masses' definitions."""
    k = np.zeros(10)
    for m, r in [(1.5, [0.02, 0.01, 0.1]), (0.7, [-0.04, 0.03, 0.05])]:
        r = np.array(r)
        j = m * (r @ r * np.eye(3) - np.outer(r, r))
        k += [j[0, 0], j[0, 1], j[0, 2], j[1, 1], j[1, 2], j[2, 2], *(m * r), m]
    return k


def run(args):
    out = subprocess.run(cli() + args, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("gains_payload")
    rx90 = str(robot_path("rx90.toml"))
    excite = d / "excite.csv"
    run(["excite", rx90, "--period", "4", "--harmonics", "4", "--qd-max", "1.5", "--qdd-max", "6",
         "--iterations", "60", "--periods", "2", "--output", str(excite)])
    phi = point_masses()
    k = robodyn.load(rx90).standard_parameters
    sets = []
    for i, name in enumerate(NAMES):
        sets += ["--set", f"{name}6={float(k[13 * 5 + i] + phi[i])!r}"]
    paths = {}
    for name, extra in [("empty", []), ("loaded", sets)]:
        paths[name] = d / f"{name}.csv"
        run(["simulate", rx90, "--duration", "8", "--dt", "0.001", "--output-step", "0.004",
             "--track", str(excite), "--kp", "400", "--kd", "40", "--coulomb-smoothing", "0",
             "--output", str(paths[name])] + extra)
    return rx90, paths, phi


def table(path):
    t = np.genfromtxt(path, delimiter=",", names=True)
    return {name: t[name] for name in t.dtype.names}


def currents(path):
    """The log with its torques tau<j> replaced by currents i<j> = tau<j> / g_j."""
    out = {}
    for name, v in table(path).items():
        if name.startswith("tau"):
            out["i" + name[3:]] = v / GAINS[int(name[3:]) - 1]
        else:
            out[name] = v
    return out


def close(got, truth, tol):
    scale = np.max(np.abs(truth))
    np.testing.assert_array_less(np.abs(got - truth), tol * np.maximum(np.abs(truth), 1e-3 * scale))


def test_payload_recovered_and_equal_to_the_cli(logs):
    rx90, paths, phi = logs
    # the robot known: the payload alone
    known = robodyn.identify(rx90, str(paths["loaded"]), payload=6, **COMMON)
    assert isinstance(known, robodyn.PayloadIdentification)
    assert known.names == NAMES and known.link == 6
    assert known.rank == 10 and known.structural_rank == 10
    close(known.values, phi, 1e-8)
    assert [p["name"] for p in known.payload] == NAMES
    ref = json.loads(run(["identify", rx90, "--data", str(paths["loaded"]), "--payload", "6",
                          "--format", "json"] + CLI_COMMON))
    assert known.report == ref
    # before/after, the logs as arrays: the robot's parameters identified too
    both = robodyn.identify(rx90, table(paths["loaded"]), payload=6, before=[table(paths["empty"])], **COMMON)
    close(both.values, phi, 1e-8)
    assert len(both.others) > 10
    assert both.report["payload"] == both.payload


def test_gains_recovered_with_torques_and_with_a_known_payload(logs):
    rx90, paths, phi = logs
    by_torques = robodyn.identify(rx90, currents(paths["empty"]), estimate_gains=True,
                                  reference=str(paths["empty"]), **COMMON)
    assert isinstance(by_torques, robodyn.GainIdentification)
    close(by_torques.gain_values, GAINS, 1e-8)
    assert [g["value"] for g in by_torques.gains] == list(by_torques.gain_values)
    by_payload = robodyn.identify(rx90, [currents(paths["empty"])], estimate_gains=True,
                                  reference=currents(paths["loaded"]), known_payload=(6, list(phi)), **COMMON)
    close(by_payload.gain_values, GAINS, 1e-8)
    assert "payload" in by_payload.reference
    # the same numbers as the CLI's report (the currents written as a CSV file)
    f = paths["empty"].parent / "currents.csv"
    c = currents(paths["empty"])
    np.savetxt(f, np.column_stack(list(c.values())), delimiter=",", header=",".join(c), comments="", fmt="%.17g")
    ref = json.loads(run(["identify", rx90, "--data", str(f), "--estimate-gains", "--reference",
                          str(paths["empty"]), "--format", "json"] + CLI_COMMON))
    by_file = robodyn.identify(rx90, str(f), estimate_gains=True, reference=str(paths["empty"]), **COMMON)
    assert by_file.report == ref
    np.testing.assert_array_equal(by_file.gain_values, by_torques.gain_values)


def test_joint_problems_refuse_what_they_do_not_take(logs):
    rx90, paths, _ = logs
    log = str(paths["empty"])
    with pytest.raises(robodyn.InputError, match="reference"):
        robodyn.identify(rx90, log, estimate_gains=True)
    with pytest.raises(robodyn.InputError, match="estimate_gains"):
        robodyn.identify(rx90, log, reference=log)
    with pytest.raises(robodyn.InputError, match="payload"):
        robodyn.identify(rx90, log, before=log)
    with pytest.raises(robodyn.InputError, match="consistent"):
        robodyn.identify(rx90, log, payload=6, consistent=True)
    with pytest.raises(robodyn.InputError, match="known_payload"):
        robodyn.identify(rx90, log, estimate_gains=True, reference=log, known_payload=(6, [1.0] * 9))
    # a log of torques where currents are expected
    with pytest.raises(robodyn.Error, match="current"):
        robodyn.identify(rx90, log, estimate_gains=True, reference=log, **COMMON)
