"""Pinocchio and example-robot-data as the reference of the URDF cross-checks (test_pinocchio.py,
test_kinematics.py): `SKIP` is None when both are installed, else the reason to skip; with
ROBODYN_REQUIRE=all or a list naming `pinocchio` (README; CI sets `all`), or the older
ROBODYN_REQUIRE_PINOCCHIO, their absence is an error. `Pin` is Pinocchio's model with
robodyn's joint order."""

import os
import pathlib

import numpy as np

try:
    import cmeel
    import pinocchio as pin

    ERD = pathlib.Path(os.path.dirname(os.path.dirname(cmeel.__file__))) / "cmeel.prefix" / "share" / "example-robot-data" / "robots"
    if not ERD.is_dir():
        raise ImportError(f"{ERD} not found")
    SKIP = None
except ImportError as e:  # pragma: no cover - depends on the machine
    keys = [k.strip() for k in os.environ.get("ROBODYN_REQUIRE", "").split(",")]
    if "all" in keys or "pinocchio" in keys or os.environ.get("ROBODYN_REQUIRE_PINOCCHIO"):
        raise
    pin, ERD = None, None
    SKIP = f"pinocchio / example-robot-data not found ({e}): pip install pin example-robot-data"


def find(name):
    hits = sorted(ERD.rglob(name))
    assert hits, f"{name} not in {ERD}"
    return hits[0]


class Pin:
    """Pinocchio's model with robodyn's joint order: idx maps our vector to Pinocchio's v."""

    def __init__(self, path, names):
        self.model = pin.buildModelFromUrdf(str(path))
        self.data = self.model.createData()
        m = self.model
        assert m.nv == len(names), (m.nv, len(names))
        self.iv = np.array([m.joints[m.getJointId(n)].idx_v for n in names])
        self.iq = np.array([m.joints[m.getJointId(n)].idx_q for n in names])
        self.nqs = np.array([m.joints[m.getJointId(n)].nq for n in names])

    def q(self, q):
        out = np.zeros(self.model.nq)
        for k, (i, nq) in enumerate(zip(self.iq, self.nqs)):
            if nq == 2:  # continuous joint: (cos, sin)
                out[i], out[i + 1] = np.cos(q[k]), np.sin(q[k])
            else:
                out[i] = q[k]
        return out

    def v(self, x):
        out = np.zeros(self.model.nv)
        out[self.iv] = x
        return out

    def drive(self, qd):
        """Damping and friction Pinocchio's rnea/aba leave out (robodyn's Fv, Fs)."""
        v = self.v(qd)
        return self.model.damping * v + self.model.friction * np.sign(v)

    def body_frames(self):
        """The names of the URDF links (Pinocchio's BODY frames), the base link left out."""
        return [f.name for f in self.model.frames if f.type == pin.FrameType.BODY and f.parentJoint > 0]

