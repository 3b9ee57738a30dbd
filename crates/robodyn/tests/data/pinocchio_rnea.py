"""Reference inverse dynamics by Pinocchio for io_urdf_pinocchio.rs (an independent route).

Usage: python3 pinocchio_rnea.py IN.json OUT.json
IN: {"robots": [{"urdf": path, "states": [{"q": {joint: value}, "qd": {...}, "qdd": {...}}]}]}
OUT: {"robots": [{"tau": [{joint: torque}], "nv": int}]}
Joints are matched by name; continuous joints (nq = 2 in Pinocchio) get (cos q, sin q);
mimic joints are ordinary joints (mimic=False). Gravity is Pinocchio's default (0, 0, -9.81).
"""
import json
import math
import sys

import numpy as np
import pinocchio as pin


def main():
    spec = json.load(open(sys.argv[1]))
    out = []
    for rob in spec["robots"]:
        model = pin.buildModelFromUrdf(rob["urdf"])
        data = model.createData()
        taus = []
        for st in rob["states"]:
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
            tau = pin.rnea(model, data, q, v, a)
            taus.append(
                {model.names[i]: float(tau[model.joints[i].idx_v]) for i in range(1, model.njoints)}
            )
        out.append({"tau": taus, "nv": int(model.nv)})
    json.dump({"robots": out}, open(sys.argv[2], "w"))


if __name__ == "__main__":
    main()
