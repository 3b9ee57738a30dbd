"""robot.view(): the page of `robodyn view` from Python (shown inline in Jupyter, saved with
.save). The page itself is checked in a browser by crates/robodyn-cli/tests/cli_view.rs; here:
the pose and the trajectory reach the page, closed robots are closed by the library's loop
closure (the same values as ClosedChain.closure), errors are exceptions."""

import html
import json
import re

import numpy as np
import pytest

import robodyn
from conftest import robot_path


def scene(page):
    m = re.search(r'id="robodyn-scene">(.*?)</script>', page, re.S)
    return json.loads(m.group(1))


def test_a_tree_at_given_joint_values_saved_and_shown_inline(tmp_path):
    robot = robodyn.load(robot_path("rx90.toml"))
    view = robot.view(q=np.full(6, 0.2))
    s = scene(view.html)
    assert s["nf"] == 6 and s["pose"]["q"] == [0.2] * 6
    assert view.warnings == []
    path = tmp_path / "rx90.html"
    path.write_text("old")
    view.save(path)
    assert path.read_text() == view.html
    assert [p.name for p in tmp_path.iterdir()] == ["rx90.html"]  # no temporary file left
    inline = view._repr_html_()
    m = re.fullmatch(r'<iframe srcdoc="([^"]*)" .*</iframe>', inline, re.S)
    assert m and html.unescape(m.group(1)) == view.html


def test_a_closed_robot_by_its_actuated_joints_is_closed_by_loop_closure():
    robot = robodyn.load(robot_path("sr400.toml"))
    qa = [0.1, 0.2, 0.3, 0.4, 0.5, 1.6]
    q = scene(robot.view(q=qa).html)["pose"]["q"]
    c = robodyn.ClosedChain(robot).closure(qa)
    np.testing.assert_allclose(q[:8], c["q_tree"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(q[8:], c["q_c"], rtol=0, atol=1e-12)
    # all movable joints: drawn as given, the open loop reported
    view = robot.view(q=np.zeros(8))
    assert len(view.warnings) == 1 and "open" in view.warnings[0]


def test_trajectories_from_a_file_or_arrays(tmp_path):
    robot = robodyn.load(robot_path("scara.toml"))
    t = np.linspace(0.0, 1.0, 11)
    Q = np.outer(t, [0.5, -0.3, 0.1, 1.0])
    arrays = scene(robot.view(trajectory=(t, Q)).html)["trajectory"]
    path = tmp_path / "traj.csv"
    rows = ["t,q1,q2,q3,q4"] + [",".join(repr(float(x)) for x in [ti, *qi]) for ti, qi in zip(t, Q)]
    path.write_text("\n".join(rows) + "\n")
    from_file = scene(robot.view(trajectory=str(path)).html)["trajectory"]
    assert from_file["t"] == arrays["t"] == list(t)
    assert from_file["q"] == arrays["q"]
    np.testing.assert_array_equal(np.array(arrays["q"]), Q)


def test_errors_are_exceptions():
    robot = robodyn.load(robot_path("rx90.toml"))
    with pytest.raises(robodyn.DimensionError):
        robot.view(q=[0.1, 0.2])
    with pytest.raises(robodyn.Error, match="does not increase"):
        robot.view(trajectory=([0.0, 0.0], np.zeros((2, 6))))
    with pytest.raises(robodyn.InputError, match="names"):
        robot.view(names="other")
