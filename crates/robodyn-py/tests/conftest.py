"""Shared fixtures: the bundled robots (robots/ of the repository) and a seeded generator."""

import os
import pathlib

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
