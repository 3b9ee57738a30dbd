#!/usr/bin/env python3
"""Peer timing: Pinocchio's RNEA on models comparable to robodyn's inverse_dynamics bench.

NOT run by CI. Needs `pip install pin` (Pinocchio's Python bindings).

    python3 crates/robodyn/benches/peers/pinocchio_rnea.py [--robodyn target/debug/robodyn]

- "sr400_tree": the SR400's equivalent tree read from robots/sr400.toml (Khalil-Kleinfinger
  frames converted to Pinocchio joint placements, inertias about O_j converted to the centre of
  mass). With --robodyn, the torques are also compared with `robodyn idm` (Pinocchio's RNEA plus
  the friction and rotor-inertia terms Fs sign(qd) + Fv qd + Ia qdd, which Pinocchio's RNEA does
  not have): an external cross-check of the model and of the frame conversion.
- "random_tree_30": a random 30-joint tree (revolute/prismatic z joints, random parents and
  placements), comparable in size and joint mix to the Rust bench's tree, not identical.

Times are medians of per-call times of `pin.rnea(model, data, q, v, a)` called from Python:
the Python -> C++ call overhead (~hundreds of ns) IS included.
"""

import argparse
import json
import math
import os
import random
import statistics
import subprocess
import sys
import timeit
import tomllib

import numpy as np
import pinocchio as pin

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))


def rot_z(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_x(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def kk_placement(gamma, b, alpha, d, theta, r):
    """iT_j = Rot(z,gamma) Trans(z,b) Rot(x,alpha) Trans(x,d) Rot(z,theta) Trans(z,r)."""
    rot = rot_z(gamma) @ rot_x(alpha) @ rot_z(theta)
    pos = rot_z(gamma) @ (np.array([0.0, 0.0, b]) + rot_x(alpha) @ np.array([d, 0.0, 0.0]))
    pos = pos + rot_z(gamma) @ rot_x(alpha) @ np.array([0.0, 0.0, r])
    return pin.SE3(rot, pos)


def inertia_from_standard(p):
    """XX XY XZ YY YZ ZZ MX MY MZ M (about O_j) -> pin.Inertia (about the centre of mass)."""
    xx, xy, xz, yy, yz, zz, mx, my, mz, m = p[:10]
    jo = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    c = np.array([mx, my, mz]) / m
    jg = jo - m * (c @ c * np.eye(3) - np.outer(c, c))
    return pin.Inertia(m, c, jg)


def build(frames, links, gravity):
    """frames: list of dicts (ant, sigma, gamma, b, alpha, d, theta, r) for j = 1..n."""
    model = pin.Model()
    for j, f in enumerate(frames, start=1):
        if f["sigma"] == 2:
            raise SystemExit(f"frame {j} is fixed: not handled by this script")
        joint = pin.JointModelRZ() if f["sigma"] == 0 else pin.JointModelPZ()
        placement = kk_placement(f["gamma"], f["b"], f["alpha"], f["d"], f["theta"], f["r"])
        jid = model.addJoint(f["ant"], joint, placement, f"j{j}")
        assert jid == j
        model.appendBodyToJoint(jid, inertia_from_standard(links[j - 1]), pin.SE3.Identity())
    model.gravity.linear = np.array(gravity)
    return model


def evaluate(x, symbols):
    if isinstance(x, (int, float)):
        return float(x)
    env = {"pi": math.pi, "sin": math.sin, "cos": math.cos, "sqrt": math.sqrt}
    env.update(symbols)
    return float(eval(x, {"__builtins__": {}}, env))


def load_sr400():
    with open(os.path.join(ROOT, "robots", "sr400.toml"), "rb") as fh:
        doc = tomllib.load(fh)
    sym = doc.get("symbols", {})
    nl = doc["nl"]
    by_j = {f["j"]: f for f in doc["frame"]}
    frames = []
    for j in range(1, nl + 1):
        f = by_j[j]
        frames.append(
            {
                "ant": f["ant"],
                "sigma": f.get("sigma", 0),
                **{k: evaluate(f.get(k, 0), sym) for k in ("gamma", "b", "alpha", "d", "theta", "r")},
            }
        )
    names = ["XX", "XY", "XZ", "YY", "YZ", "ZZ", "MX", "MY", "MZ", "M", "IA", "FS", "FV"]
    lk = {l["j"]: l for l in doc["link"]}
    links = [[evaluate(lk[j].get(k, 0), sym) for k in names] for j in range(1, nl + 1)]
    gravity = [evaluate(g, sym) for g in doc.get("gravity", [0, 0, -9.81])]
    return frames, links, gravity


def random_tree(n, seed):
    rng = random.Random(seed)
    frames, links = [], []
    for j in range(1, n + 1):
        ant = j - 1 if (j == 1 or rng.random() < 0.6) else rng.randrange(0, j)
        frames.append(
            {
                "ant": ant,
                "sigma": 1 if rng.random() < 0.25 else 0,
                "gamma": rng.uniform(-3, 3),
                "b": rng.uniform(-0.5, 0.5),
                "alpha": rng.uniform(-3, 3),
                "d": rng.uniform(-0.5, 0.5),
                "theta": rng.uniform(-3, 3),
                "r": rng.uniform(-0.5, 0.5),
            }
        )
        m = rng.uniform(0.5, 5.0)
        c = np.array([rng.uniform(-0.3, 0.3) for _ in range(3)])
        jo = np.diag([rng.uniform(0.01, 0.3) for _ in range(3)]) + m * (c @ c * np.eye(3) - np.outer(c, c))
        links.append([jo[0, 0], jo[0, 1], jo[0, 2], jo[1, 1], jo[1, 2], jo[2, 2], *(m * c), m, 0, 0, 0])
    return frames, links, [0.0, 0.0, -9.81]


def median_ns(model, q, v, a, number=20000, repeat=15):
    data = model.createData()
    t = timeit.repeat(lambda: pin.rnea(model, data, q, v, a), number=number, repeat=repeat)
    return statistics.median(t) / number * 1e9


def cross_check(robodyn, frames, links, gravity, states=20):
    model = build(frames, links, gravity)
    data = model.createData()
    rng = np.random.default_rng(3)
    worst = 0.0
    for _ in range(states):
        n = len(frames)
        q, v, a = rng.uniform(-3, 3, n), rng.uniform(-2, 2, n), rng.uniform(-5, 5, n)
        tau_pin = pin.rnea(model, data, q, v, a).copy()
        ia, fs, fv = (np.array([l[k] for l in links]) for k in (10, 11, 12))
        tau_pin += fs * np.sign(v) + fv * v + ia * a
        lst = lambda x: ",".join(repr(float(e)) for e in x)
        out = subprocess.run(
            [robodyn, "idm", os.path.join(ROOT, "robots", "sr400.toml"), "--q", lst(q), "--qd", lst(v),
             "--qdd", lst(a), "--format", "json"],
            check=True, capture_output=True, text=True,
        ).stdout
        row = json.loads(out)[0]
        tau_rd = np.array([row[f"tau{j}"] for j in range(1, n + 1)])
        worst = max(worst, np.linalg.norm(tau_rd - tau_pin) / np.linalg.norm(tau_pin))
    return worst


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robodyn", help="path of the robodyn binary: compare torques on the SR400 tree")
    args = ap.parse_args()
    print(f"pinocchio {pin.__version__}, python {sys.version.split()[0]}")
    sr = load_sr400()
    if args.robodyn:
        err = cross_check(args.robodyn, *sr)
        print(f"sr400_tree: robodyn idm vs pinocchio rnea (+friction, Ia): max relative error {err:.2e}")
    for name, (frames, links, gravity) in [("sr400_tree", sr), ("random_tree_30", random_tree(30, 30))]:
        model = build(frames, links, gravity)
        rng = np.random.default_rng(1)
        n = model.nq
        q, v, a = rng.uniform(-3, 3, n), rng.uniform(-2, 2, n), rng.uniform(-5, 5, n)
        print(f"{name}: pinocchio.rnea from Python (call overhead included): median {median_ns(model, q, v, a):.0f} ns/call")


if __name__ == "__main__":
    main()
