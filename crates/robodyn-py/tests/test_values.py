"""Values by name (issue 30 item 2): unknown names are refused with the names known, in
`load`, `set`, `with_values` and `base_parameters` alike (the library's rule, the CLI's `--set`);
a standard parameter of a URDF robot (numbers, no symbols) is changed by its name (`M3`, `FS2`),
checked against the regressor (tau = Phi K is linear in K) and against the CLI's `--set`."""

import csv
import subprocess

import numpy as np
import pytest

import robodyn
from conftest import ROOT, cli, robot_path


def test_unknown_names_are_refused_with_the_known_ones(tmp_path):
    robot = robodyn.load(robot_path("rx90.toml"))
    before = robot.standard_parameters
    for call in [lambda: robot.with_values(FOO=1), lambda: robot.set(FOO=1),
                 lambda: robodyn.load(robot_path("rx90.toml"), FOO=1),
                 lambda: robodyn.base_parameters(robot_path("rx90.toml"), FOO=1)]:
        with pytest.raises(robodyn.InputError) as e:
            call()
        msg = str(e.value)
        assert "`FOO`" in msg and "D3, G3, RL4" in msg and "M<j>" in msg, msg
    assert robot.standard_parameters == before and "FOO" not in robot.symbols
    # a name that differs in case only is pointed at
    with pytest.raises(robodyn.InputError, match=r"did you mean `D3`"):
        robot.with_values(d3=0.5)
    # several names: nothing changes when one is unknown
    with pytest.raises(robodyn.InputError):
        robot.set(D3=0.6, FOO=1)
    assert robot.symbols["D3"] == 0.45


def k_index(robot, name):
    return robot.parameter_names.index(name)


def test_urdf_standard_parameters_by_name():
    """URDF parameters are numbers: M3 names link 3's mass (it was renamed M3_ before, and the
    value went to an unused symbol)."""
    robot = robodyn.load(robot_path("rx90.urdf"))
    assert robot.symbols == {}
    names = robot.parameter_names
    heavy = robot.with_values(M3=100.0, FS2=0.7, FV4=0.3)
    assert heavy.parameter_names == names  # no renaming (M3_ before)
    k, k2 = np.array(robot.standard_parameters), np.array(heavy.standard_parameters)
    changed = {names[i] for i in np.nonzero(k != k2)[0]}
    assert changed == {"M3", "FS2", "FV4"}
    assert k2[k_index(robot, "M3")] == 100.0 and k2[k_index(robot, "FS2")] == 0.7
    # the torques are those of the regressor (of the unchanged robot) times the new K
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-1, 1, (4, 6)) for _ in range(3))
    phi = robot.regressor(q, qd, qdd)
    cols = [k_index(robot, c) for c in robot.regressor_columns()]
    tau = heavy.idm(q, qd, qdd).reshape(-1)
    np.testing.assert_allclose(phi @ k2[cols], tau, rtol=0, atol=1e-9 * np.abs(tau).max())
    assert not np.allclose(tau, robot.idm(q, qd, qdd).reshape(-1))
    # friction of joint 2 alone: FS2 sign(qd2) + FV2 qd2 on joint 2, nothing elsewhere
    fr = robot.with_values(FS2=0.5, FV2=0.25)
    d = fr.idm(q, qd, qdd) - robot.idm(q, qd, qdd)
    np.testing.assert_allclose(d[:, 1], 0.5 * np.sign(qd[:, 1]) + 0.25 * qd[:, 1], atol=1e-12)
    np.testing.assert_array_equal(d[:, [0, 2, 3, 4, 5]], 0)
    # the same through load and set
    loaded = robodyn.load(robot_path("rx90.urdf"), M3=100.0, FS2=0.7, FV4=0.3)
    np.testing.assert_array_equal(loaded.standard_parameters, heavy.standard_parameters)
    robot.set(M3=100.0, FS2=0.7, FV4=0.3)
    np.testing.assert_array_equal(robot.standard_parameters, heavy.standard_parameters)


TWO_LINKS = """
name = "two links, link 2's mass a symbol of the file's own name"
nl = 2
nj = 2
[symbols]
mass_b = 1.0
[[frame]]
j = 1
ant = 0
[[frame]]
j = 2
ant = 1
d = 0.5
[[link]]
j = 1
ZZ = 0.1
MX = 0.2
M = 2.0
[[link]]
j = 2
ZZ = 0.05
MX = 0.1
M = "mass_b"
"""


def test_symbol_and_parameter_names_of_a_toml_file():
    """A parameter written as a symbol is named by that symbol (and set as a symbol); one
    written as a number by its canonical name (and replaced)."""
    robot = robodyn.Robot.from_toml_str(TWO_LINKS)
    names = robot.parameter_names
    assert names[13 + 9] == "mass_b" and names[9] == "M1"
    other = robot.with_values(mass_b=3.0, M1=4.0)
    assert other.symbols["mass_b"] == 3.0
    k = other.standard_parameters
    assert k[13 + 9] == 3.0 and k[9] == 4.0
    with pytest.raises(robodyn.InputError, match="`M2`"):
        robot.with_values(M2=7.0)  # its name is mass_b


def test_cli_set_and_python_agree(tmp_path):
    """`robodyn idm rx90.urdf --set M3=100 --set FS2=0.7` = with_values(M3=100, FS2=0.7)."""
    q = [0.1, -0.4, 1.2, 0.3, -0.7, 0.2]
    qd = [0.5, 0.1, -0.3, 0.8, 0.2, -0.6]
    out = tmp_path / "tau.csv"
    r = subprocess.run(cli() + ["idm", str(robot_path("rx90.urdf")), "--set", "M3=100",
                                "--set", "FS2=0.7", "--q", ",".join(map(repr, q)),
                                "--qd", ",".join(map(repr, qd)), "--output", str(out)],
                       cwd=ROOT, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    with open(out) as f:
        row = next(csv.DictReader(f))
    theirs = np.array([float(row[f"tau{j}"]) for j in range(1, 7)])
    ours = robodyn.load(robot_path("rx90.urdf")).with_values(M3=100, FS2=0.7).idm(q, qd)
    np.testing.assert_array_equal(ours, theirs)
    r = subprocess.run(cli() + ["idm", str(robot_path("rx90.urdf")), "--set", "FOO=1",
                                "--q", "0,0,0,0,0,0"], cwd=ROOT, capture_output=True, text=True)
    assert r.returncode != 0 and "no symbol `FOO`" in r.stderr, r.stderr
