"""Reference floating-base dynamics by Pinocchio (JointModelFreeFlyer root) for
floating_pinocchio.rs (an independent implementation).

Usage: python3 pinocchio_floating.py IN.json OUT.json
IN: {"robots": [{"urdf": path, "states": [{"base_q": [7], "base_v": [6], "base_a": [6],
     "base_tau": [6], "q": {joint: x}, "v": {...}, "a": {...}, "tau": {...}}]}]}
OUT: {"robots": [{"nv": int, "joints": [names in Pinocchio's v order, after the base],
      "mass": float, "states": [{"rnea": [nv], "crba": [[nv]], "aba": [nv], "hg": [6]
      (centroidal momentum, linear then angular, world frame at the CoM), "com": [3],
      "integrate": [7] (the base part of integrate(q, v * 0.01))}]}]}
With "frame" (a URDF link name) in a state, its entry also holds the kinematics of that BODY
frame and of the robot: "M" (4x4, world), "J", "dJ" ({reference: 6 x nv}), "acc" ({reference:
6}, classical), "vcom", "acom" (3), "Jcom" (3 x nv), and "placements" ({link name: 4x4} of every
BODY frame, framesForwardKinematics).
Vectors are in Pinocchio's v order (base 6 first). Continuous joints (nq = 2) get (cos, sin).
Gravity is Pinocchio's default (0, 0, -9.81).
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


def kinematics(model, data, q, v, a, frame):
    """The kinematics of BODY frame `frame` and of the centre of mass at (q, v, a)."""
    fid = model.getFrameId(frame, pin.FrameType.BODY)
    if fid >= len(model.frames):
        raise SystemExit(f"no BODY frame {frame}")
    pin.framesForwardKinematics(model, data, q)
    placements = {f.name: data.oMf[i].homogeneous.tolist()
                  for i, f in enumerate(model.frames) if f.type == pin.FrameType.BODY}
    pin.forwardKinematics(model, data, q, v, a)
    pin.computeJointJacobians(model, data, q)
    pin.computeJointJacobiansTimeVariation(model, data, q, v)
    pin.updateFramePlacements(model, data)
    out = {"M": data.oMf[fid].homogeneous.tolist(), "J": {}, "dJ": {}, "acc": {},
           "placements": placements}
    for name, rf in REFS.items():
        out["J"][name] = pin.getFrameJacobian(model, data, fid, rf).tolist()
        out["dJ"][name] = pin.getFrameJacobianTimeVariation(model, data, fid, rf).tolist()
        out["acc"][name] = pin.getFrameClassicalAcceleration(model, data, fid, rf).vector.tolist()
    pin.centerOfMass(model, data, q, v, a)
    out["vcom"] = data.vcom[0].tolist()
    out["acom"] = data.acom[0].tolist()
    out["Jcom"] = pin.jacobianCenterOfMass(model, data, q).tolist()
    return out


def fill(model, st):
    q = pin.neutral(model)
    v = np.zeros(model.nv)
    a = np.zeros(model.nv)
    tau = np.zeros(model.nv)
    q[:7] = st["base_q"]
    v[:6] = st["base_v"]
    a[:6] = st["base_a"]
    tau[:6] = st["base_tau"]
    for i in range(2, model.njoints):
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
        v[jm.idx_v] = st["v"][name]
        a[jm.idx_v] = st["a"][name]
        tau[jm.idx_v] = st["tau"][name]
    return q, v, a, tau


def main():
    spec = json.load(open(sys.argv[1]))
    out = []
    for rob in spec["robots"]:
        model = pin.buildModelFromUrdf(rob["urdf"], pin.JointModelFreeFlyer())
        data = model.createData()
        assert model.joints[1].nv == 6 and model.joints[1].idx_v == 0
        names = [None] * model.nv
        for i in range(2, model.njoints):
            names[model.joints[i].idx_v] = model.names[i]
        res = []
        for st in rob["states"]:
            q, v, a, tau = fill(model, st)
            r = pin.rnea(model, data, q, v, a)
            m = pin.crba(model, data, q)
            m = np.triu(m) + np.triu(m, 1).T
            dd = pin.aba(model, data, q, v, tau)
            hg = pin.computeCentroidalMomentum(model, data, q, v)
            com = pin.centerOfMass(model, data, q)
            qn = pin.integrate(model, q, v * 0.01)
            entry = {"rnea": r.tolist(), "crba": m.tolist(), "aba": dd.tolist(),
                     "hg": np.concatenate([hg.linear, hg.angular]).tolist(),
                     "com": np.asarray(com).tolist(), "integrate": qn[:7].tolist()}
            if "frame" in st:
                entry.update(kinematics(model, data, q, v, a, st["frame"]))
            res.append(entry)
        out.append({
            "nv": int(model.nv),
            "joints": names[6:],
            "mass": float(pin.computeTotalMass(model)),
            "states": res,
        })
    json.dump({"robots": out}, open(sys.argv[2], "w"))


if __name__ == "__main__":
    main()
