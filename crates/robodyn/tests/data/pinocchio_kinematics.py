"""Reference kinematics by Pinocchio for kinematics_pinocchio.rs (an independent route).

Usage: python3 pinocchio_kinematics.py IN.json OUT.json
IN: {"robots": [{"urdf": path, "states": [{"q": {joint: value}, "qd": {...}, "qdd": {...},
     "frame": link name}]}]}
OUT: {"robots": [{"nv": int, "joints": [joint names in Pinocchio's v order],
      "mass": float, "states": [{"M": 4x4, "J": {ref: 6 x nv}, "dJ": {ref: 6 x nv},
      "acc": {ref: 6}, "com": 3, "vcom": 3, "acom": 3, "Jcom": 3 x nv}]}]}
Joints are matched by name (columns of nv named in "joints"); continuous joints (nq = 2) get
(cos q, sin q). Frames are Pinocchio's BODY frames, by URDF link name. Gravity plays no part.
"""
import json
import math
import sys

import numpy as np
import pinocchio as pin

REFS = {
    "world": pin.ReferenceFrame.WORLD,
    "local": pin.ReferenceFrame.LOCAL,
    "local_world_aligned": pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
}


def state_vectors(model, st):
    q = pin.neutral(model)
    v = np.zeros(model.nv)
    a = np.zeros(model.nv)
    for i in range(1, model.njoints):
        name = model.names[i]
        jm = model.joints[i]
        x = st["q"][name]
        if jm.nq == 1:
            q[jm.idx_q] = x
        elif jm.nq == 2:
            q[jm.idx_q] = math.cos(x)
            q[jm.idx_q + 1] = math.sin(x)
        else:
            raise SystemExit(f"joint {name}: nq = {jm.nq} not handled")
        v[jm.idx_v] = st["qd"][name]
        a[jm.idx_v] = st["qdd"][name]
    return q, v, a


def one_state(model, data, st):
    q, v, a = state_vectors(model, st)
    fid = model.getFrameId(st["frame"], pin.FrameType.BODY)
    if fid >= len(model.frames):
        raise SystemExit(f"no BODY frame {st['frame']}")
    pin.forwardKinematics(model, data, q, v, a)
    pin.computeJointJacobians(model, data, q)
    pin.computeJointJacobiansTimeVariation(model, data, q, v)
    pin.updateFramePlacements(model, data)
    out = {"M": data.oMf[fid].homogeneous.tolist(), "J": {}, "dJ": {}, "acc": {}}
    for name, rf in REFS.items():
        out["J"][name] = pin.getFrameJacobian(model, data, fid, rf).tolist()
        out["dJ"][name] = pin.getFrameJacobianTimeVariation(model, data, fid, rf).tolist()
        out["acc"][name] = pin.getFrameClassicalAcceleration(model, data, fid, rf).vector.tolist()
    pin.centerOfMass(model, data, q, v, a)
    out["com"] = data.com[0].tolist()
    out["vcom"] = data.vcom[0].tolist()
    out["acom"] = data.acom[0].tolist()
    out["Jcom"] = pin.jacobianCenterOfMass(model, data, q).tolist()
    return out


def main():
    spec = json.load(open(sys.argv[1]))
    out = []
    for rob in spec["robots"]:
        model = pin.buildModelFromUrdf(rob["urdf"])
        data = model.createData()
        joints = [""] * model.nv
        for i in range(1, model.njoints):
            joints[model.joints[i].idx_v] = model.names[i]
        states = [one_state(model, data, st) for st in rob["states"]]
        mass = sum(model.inertias[i].mass for i in range(1, model.njoints))
        out.append({"nv": model.nv, "joints": joints, "mass": mass, "states": states})
    json.dump({"robots": out}, open(sys.argv[2], "w"))


if __name__ == "__main__":
    main()
