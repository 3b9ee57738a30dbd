"""Errors: every kind is a Python exception class under robodyn.Error, with the library's
message; shapes are checked with a message naming the expected shape; NaN is refused."""

import numpy as np
import pytest

import robodyn
from conftest import robot_path


@pytest.fixture
def rx90():
    return robodyn.load(robot_path("rx90.toml"))


def test_classes_subclass_error():
    for cls in [robodyn.RobotFileError, robodyn.PhysicalParameterError, robodyn.DimensionError,
                robodyn.NotFiniteError, robodyn.SingularConfiguration, robodyn.LoopClosureError,
                robodyn.BranchLost, robodyn.InputError, robodyn.NumericalError]:
        assert issubclass(cls, robodyn.Error)
    assert issubclass(robodyn.BranchLost, robodyn.LoopClosureError)
    assert issubclass(robodyn.SingularityWarning, UserWarning)


def test_bad_shapes_name_the_expected_shape(rx90):
    with pytest.raises(robodyn.DimensionError, match=r"q has shape \(5,\), expected \(6,\) for one state or \(N, 6\)") as e:
        rx90.idm(np.zeros(5))
    assert e.value.expected == 6 and e.value.got == 5
    with pytest.raises(robodyn.DimensionError, match=r"qd has shape \(3, 7\)"):
        rx90.idm(np.zeros((3, 6)), np.zeros((3, 7)))
    with pytest.raises(robodyn.DimensionError, match=r"same N"):
        rx90.idm(np.zeros((3, 6)), np.zeros((4, 6)))
    with pytest.raises(robodyn.DimensionError, match="one state"):
        rx90.idm(np.zeros((3, 6)), np.zeros(6))
    with pytest.raises(robodyn.DimensionError):
        rx90.inertia(np.zeros((2, 3, 6)))
    chain = robodyn.ClosedChain(robodyn.load(robot_path("fourbar.toml")))
    with pytest.raises(robodyn.DimensionError, match=r"expected \(1,\).*actuated joints"):
        chain.idm(np.zeros(2))


def test_nan_is_refused_with_its_row(rx90):
    q = np.zeros((4, 6))
    q[2, 3] = np.nan
    with pytest.raises(robodyn.NotFiniteError, match=r"row 3: q\[3\] = NaN") as e:
        rx90.idm(q)
    assert e.value.row == 3 and e.value.index == 3
    with pytest.raises(robodyn.NotFiniteError):
        rx90.ddm(np.zeros(6), np.array([0, 0, np.inf, 0, 0, 0]))
    with pytest.raises(robodyn.NotFiniteError):
        rx90.forward_kinematics(np.full(6, np.nan))
    with pytest.raises(robodyn.NotFiniteError):
        rx90.with_values(d3=float("nan"))


def test_bad_files_give_file_and_line(tmp_path):
    bad = tmp_path / "bad.toml"
    text = (robot_path("rx90.toml")).read_text().splitlines()
    # break a value on a known line: the error names the file and that line
    for i, line in enumerate(text):
        if line.strip().startswith("d ") or line.strip().startswith("d="):
            text[i] = line.split("=")[0] + "= 1.2.3"
            lineno = i + 1
            break
    else:
        text.insert(3, "this is = = not toml")
        lineno = 4
    bad.write_text("\n".join(text))
    with pytest.raises(robodyn.RobotFileError) as e:
        robodyn.load(bad)
    assert e.value.file == str(bad)
    assert e.value.line == lineno
    assert str(bad) in str(e.value)
    with pytest.raises(robodyn.RobotFileError) as e:
        robodyn.load(tmp_path / "missing.toml")
    assert e.value.file == str(tmp_path / "missing.toml")
    with pytest.raises(robodyn.RobotFileError):
        robodyn.Robot.from_toml_str("not a robot")


TWO_LINKS = """
name = "two links with symbolic masses"
nl = 2
nj = 2

[symbols]
M1 = 2.0
M2 = 1.0
ZZ2 = 0.1
IA2 = 0.0

[[frame]]
j = 1
ant = 0
sigma = 0
mu = 1

[[frame]]
j = 2
ant = 1
sigma = 0
mu = 1
alpha = "pi/2"
d = 0.5

[[link]]
j = 1
XX = 0.1
YY = 0.1
ZZ = 0.1
M = "M1"

[[link]]
j = 2
XX = 0.1
YY = 0.1
ZZ = "ZZ2"
M = "M2"
IA = "IA2"
"""


def test_negative_mass_is_a_physical_error():
    robot = robodyn.Robot.from_toml_str(TWO_LINKS)
    assert {"M1", "M2"} <= set(robot.symbols)
    with pytest.raises(robodyn.PhysicalParameterError):
        robot.with_values(M2=-1.0)


def test_options_are_checked(rx90):
    with pytest.raises(robodyn.InputError, match="composite"):
        rx90.ddm(np.zeros(6), method="lu")
    with pytest.raises(robodyn.InputError):
        rx90.regressor(np.zeros(6), columns="all")
    with pytest.raises(robodyn.InputError):
        rx90.base_parameters(method="svd")
    with pytest.raises(robodyn.InputError):
        rx90.generate(lang="cobol")


def test_singular_mass_matrix():
    # joint 2 drives a link with no inertia about its axis and no rotor: A is singular
    robot = robodyn.Robot.from_toml_str(TWO_LINKS)
    light = robot.with_values(ZZ2=0.0)
    robot.ddm(np.zeros(2))  # the regular robot solves
    with pytest.raises(robodyn.SingularConfiguration):
        light.ddm(np.zeros(2))
