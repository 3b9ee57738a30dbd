"""Reference derivatives of the dynamics by Pinocchio for derivatives_pinocchio.rs (an
independent route: Carpentier & Mansard's analytical derivatives, RSS 2018).

Usage: python3 pinocchio_derivatives.py IN.json OUT.json
IN: {"robots": [{"urdf": path, "states": [{"q": {joint: value}, "qd": {...}, "qdd": {...},
     "tau": {...}}]}]}
OUT: {"robots": [{"nv": int, "joints": [joint names in Pinocchio's v order],
      "states": [{"dtau_dq", "dtau_dv", "M", "ddq", "ddq_dq", "ddq_dv", "Minv": nv x nv or nv}]}]}
computeRNEADerivatives at (q, qd, qdd), computeABADerivatives at (q, qd, tau); Pinocchio fills
the upper triangles of M and Minv only: both are symmetrized here. Continuous joints (nq = 2)
get (cos q, sin q); their derivatives are along the tangent, the angle's. Gravity is Pinocchio's
default (0, 0, -9.81); URDF <dynamics> (friction) is ignored by Pinocchio.
"""
import json
import math
import sys

import numpy as np
import pinocchio as pin


def vectors(model, st):
    q = pin.neutral(model)
    v, a, t = (np.zeros(model.nv) for _ in range(3))
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
        t[jm.idx_v] = st["tau"][name]
    return q, v, a, t


def sym(m):
    m = np.array(m)
    return np.triu(m) + np.triu(m, 1).T


def main():
    spec = json.load(open(sys.argv[1]))
    out = []
    for rob in spec["robots"]:
        model = pin.buildModelFromUrdf(rob["urdf"])
        data = model.createData()
        names = [""] * model.nv
        for i in range(1, model.njoints):
            names[model.joints[i].idx_v] = model.names[i]
        states = []
        for st in rob["states"]:
            q, v, a, t = vectors(model, st)
            pin.computeRNEADerivatives(model, data, q, v, a)
            r = {
                "dtau_dq": np.array(data.dtau_dq).tolist(),
                "dtau_dv": np.array(data.dtau_dv).tolist(),
                "M": sym(data.M).tolist(),
            }
            pin.computeABADerivatives(model, data, q, v, t)
            r["ddq"] = np.array(data.ddq).tolist()
            r["ddq_dq"] = np.array(data.ddq_dq).tolist()
            r["ddq_dv"] = np.array(data.ddq_dv).tolist()
            r["Minv"] = sym(data.Minv).tolist()
            states.append(r)
        out.append({"nv": int(model.nv), "joints": names, "states": states})
    json.dump({"robots": out}, open(sys.argv[2], "w"))


if __name__ == "__main__":
    main()
