"""Robot files whose symbols have no numeric values (SYMORO files are often symbols only):
`robodyn.load` refuses them saying which symbols and how to go on; `robodyn.base_parameters(path)`
gives their base parameters as the CLI's `robodyn base-params` does (the symbolic method needs
no values, the numerical one takes generic values for the geometry and says so)."""

import json
import subprocess

import numpy as np
import pytest

import robodyn
from conftest import ROOT, cli, robot_path


def symbols_only(tmp_path):
    """robots/rx90.par without its `robodyn values` comment: SYMORO's symbols only."""
    text = robot_path("rx90.par").read_text()
    start = text.index("(* robodyn values")
    p = tmp_path / "rx90_symbols.par"
    p.write_text(text[:start])
    return p


def test_load_names_the_symbols_without_value_and_the_ways_on(tmp_path):
    p = symbols_only(tmp_path)
    with pytest.raises(robodyn.RobotFileError) as e:
        robodyn.load(p)
    msg = str(e.value)
    assert "D3" in msg and "XX1" in msg and "symbols without a value" in msg, msg
    assert "robodyn.load(path, D3=...)" in msg and "robodyn.base_parameters(path)" in msg, msg
    assert e.value.line is not None and str(p) in e.value.file


def test_values_as_keyword_arguments_load_the_same_robot(tmp_path):
    bundled = robodyn.load(robot_path("rx90.par"))
    robot = robodyn.load(symbols_only(tmp_path), **bundled.symbols)
    rng = np.random.default_rng(3)
    q, qd, qdd = (rng.uniform(-1, 1, (4, 6)) for _ in range(3))
    np.testing.assert_array_equal(robot.idm(q, qd, qdd), bundled.idm(q, qd, qdd))


def test_base_parameters_of_a_file_without_values(tmp_path):
    p = symbols_only(tmp_path)
    full = robodyn.load(robot_path("rx90.par")).base_parameters()
    sym = robodyn.base_parameters(p)
    # the symbolic method works on the symbols: the robot's names and grouping equations
    assert sym.method == "symbolic"
    assert sym.names == full.names and sym.equations == full.equations
    assert sym.values == [None] * len(sym) and sym.coefficients is None
    # the numerical method (stacked regressor at generic geometry, independent of the rules)
    # finds the same count and the same parameters without effect, and says the geometry is generic
    num = robodyn.base_parameters(p, method="numeric")
    assert len(num) == len(sym) > 0
    assert set(num.no_effect) == set(sym.no_effect)
    assert num.coefficients is None, "no coefficient table for a generic geometry"
    assert any("generic values" in n and "D3" in n for n in num.notes), num.notes
    # given values, the numerical method has its coefficient table again
    values = {"D3": 0.45, "RL4": 0.45, "G3": -9.81}
    num_d = robodyn.base_parameters(p, method="numeric", **values)
    assert num_d.coefficients is not None and not any("generic" in n for n in num_d.notes)


def same_report(py, cli_json):
    """The Python report and the CLI's: the same except the notes, where the Python one says at
    least that the geometry was generic whenever the CLI does (the CLI adds more advice)."""
    a, b = json.loads(py.json), json.loads(cli_json)
    notes = [a.pop("notes"), b.pop("notes")]
    assert a == b
    generic = [[n.split("(give values")[0] for n in ns if "generic values" in n] for ns in notes]
    assert generic[0] == generic[1]


def test_base_parameters_of_a_file_as_the_cli(tmp_path):
    p = symbols_only(tmp_path)
    for method in ["symbolic", "numeric", "both"]:
        out = subprocess.run(
            cli() + ["base-params", str(p), "--method", method, "--format", "json"],
            capture_output=True, text=True, check=True,
        ).stdout
        same_report(robodyn.base_parameters(p, method=method), out)


def external_rx90():
    """OpenSYMORO's RX90.par (shared/cases/external, read in place), if the project's shared/
    is beside the repository."""
    for d in [ROOT, *ROOT.parents]:
        f = d / "shared" / "cases" / "external" / "opensymoro-symoro" / "RX90.par"
        if f.is_file():
            return f
    return None


def test_opensymoro_rx90_without_values():
    f = external_rx90()
    if f is None:
        pytest.skip("shared/cases/external not found beside the repository")
    with pytest.raises(robodyn.RobotFileError, match=r"robodyn\.base_parameters\(path\)"):
        robodyn.load(f)
    sym = robodyn.base_parameters(f)
    num = robodyn.base_parameters(f, method="numeric")
    assert len(sym) == len(num) > 0
    out = subprocess.run(
        cli() + ["base-params", str(f), "--method", "both", "--format", "json"],
        capture_output=True, text=True, check=True,
    ).stdout
    same_report(robodyn.base_parameters(f, method="both"), out)
