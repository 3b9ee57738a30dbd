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


def test_negative_mass_is_a_physical_error(tmp_path):
    text = robot_path("scara.toml").read_text()
    robot = robodyn.Robot.from_toml_str(text)
    masses = [p for p in robot.parameter_names if p.startswith("M") and p[1:].isdigit()]
    sym = [m for m in masses if m in robot.symbols]
    if not sym:
        pytest.skip("scara.toml gives masses as numbers")
    with pytest.raises(robodyn.PhysicalParameterError):
        robot.with_values(**{sym[0]: -1.0})


def test_options_are_checked(rx90):
    with pytest.raises(robodyn.InputError, match="composite"):
        rx90.ddm(np.zeros(6), method="lu")
    with pytest.raises(robodyn.InputError):
        rx90.regressor(np.zeros(6), columns="all")
    with pytest.raises(robodyn.InputError):
        rx90.base_parameters(method="svd")
    with pytest.raises(robodyn.InputError):
        rx90.generate(lang="cobol")


def test_singular_mass_matrix(tmp_path):
    # a massless last link with no rotor: A is singular
    robot = robodyn.load(robot_path("rx90.toml"))
    zero = {p: 0.0 for p in robot.parameter_names if p.endswith("6") and p in robot.symbols}
    if not zero:
        pytest.skip("rx90.toml gives link 6 as numbers")
    light = robot.with_values(**zero)
    with pytest.raises(robodyn.SingularConfiguration):
        light.ddm(np.zeros(6))
