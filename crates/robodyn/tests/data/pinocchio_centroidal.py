"""Reference centroidal momentum matrices by Pinocchio (JointModelFreeFlyer root) for
floating_centroidal.rs (an independent implementation: Pinocchio's ccrba).

Usage: python3 pinocchio_centroidal.py IN.json OUT.json
IN: {"robots": [{"urdf": path, "joints": [robodyn's joint names, its vector order],
     "states": [{"q": [nq, robodyn's order], "v": [nv, robodyn's order]}]}]}
OUT: {"robots": [{"states": [{"Ag": [[nv] x 6] (rows linear then angular, world axes at the
      CoM; columns in robodyn's order), "hg": [6] (Ag v)}]}]}
The base entries are the same in both (q = [p, quaternion x y z w], v in the base frame), so
only the joints are mapped, by name. Continuous joints (nq = 2) are not handled.
"""
import json
import sys

import numpy as np
import pinocchio as pin


def main():
    spec = json.load(open(sys.argv[1]))
    out = []
    for rob in spec["robots"]:
        model = pin.buildModelFromUrdf(rob["urdf"], pin.JointModelFreeFlyer())
        data = model.createData()
        assert model.joints[1].nv == 6 and model.joints[1].idx_v == 0
        joints = [model.joints[model.getJointId(n)] for n in rob["joints"]]
        if any(j.nq != 1 for j in joints):
            raise SystemExit("continuous joints not handled")
        iq = np.r_[np.arange(7), [j.idx_q for j in joints]]
        iv = np.r_[np.arange(6), [j.idx_v for j in joints]]
        res = []
        for st in rob["states"]:
            q = np.zeros(model.nq)
            v = np.zeros(model.nv)
            q[iq] = st["q"]
            v[iv] = st["v"]
            ag = pin.ccrba(model, data, q, v)[:, iv]
            res.append({"Ag": ag.tolist(), "hg": np.concatenate([data.hg.linear, data.hg.angular]).tolist()})
        out.append({"states": res})
    json.dump({"robots": out}, open(sys.argv[2], "w"))


main()
