"""Shared fixtures: the bundled robots (robots/ of the repository) and a seeded generator."""

import os
import pathlib
import shutil

import numpy as np
import pytest

import robodyn

ROOT = pathlib.Path(__file__).resolve().parents[3]
ROBOTS = ROOT / "robots"
TREES = ["rx90.toml", "rx90.par", "rx90.urdf", "scara.toml", "torso2arms.toml", "tx40.toml", "sr400.par"]
CLOSED = ["sr400.toml", "fourbar.toml", "fivebar.toml", "spatial_loop.toml", "twoloops.toml"]


def robot_path(name):
    return ROBOTS / name


@pytest.fixture
def rng():
    return np.random.default_rng(20261124)


def random_states(rng, n, rows=None):
    shape = (n,) if rows is None else (rows, n)
    return [rng.uniform(-1.0, 1.0, shape) for _ in range(3)]


def cli():
    """The `robodyn` binary: ROBODYN_CLI, one built in target/, else built with cargo."""
    if os.environ.get("ROBODYN_CLI"):
        return [os.environ["ROBODYN_CLI"]]
    for profile in ["release", "debug"]:
        exe = ROOT / "target" / profile / "robodyn"
        if exe.exists():
            return [str(exe)]
    if shutil.which("cargo") is None:
        pytest.skip("no robodyn binary and no cargo")
    return ["cargo", "run", "-q", "--manifest-path", str(ROOT / "Cargo.toml"), "-p", "robodyn-cli", "--"]
