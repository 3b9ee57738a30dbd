#!/usr/bin/env python3
"""Side-by-side benchmark: robodyn against Pinocchio (C++) on real URDFs. NOT run by CI.

    pip install pin example-robot-data cmeel-eigen cmeel-urdfdom-headers   # once
    python3 crates/robodyn/benches/peers/run.py [--rounds 5] [--robots ur5,panda,talos]
    python3 crates/robodyn/benches/peers/run.py --rounds 31 --robots talos_ff,hyq,solo12  # floating

What it does (build products in target/peers/):
1. Pinocchio's URDF parser (the pip wheel's Python bindings) reads UR5, Panda and Talos (full)
   from example-robot-data, fixed base, and Talos full, HyQ and Solo12 with a free-flyer root
   (`JointModelFreeFlyer`; robodyn: `LoadOptions::floating()`), and every joint (parent, type, axis, placement, inertia,
   fixed joints already merged into their parent body) is dumped to `<robot>.model`.
   pinocchio_peer.cpp rebuilds the identical model in C++: the wheel's URDF parser needs urdfdom,
   a shared library built without -march=native, which must not be mixed with -march=native code.
2. Random states (seed 1): q in [-pi, pi], v in [-2, 2], a in [-5, 5] (a free flyer: position in
   [-2, 2], a uniformly random unit quaternion, its v and a as the joints'), tau = rnea(q, v, a') for
   another random a' (so that both direct models must give back a'), written to `<robot>.states`
   with the joint names; both sides read that file (robodyn maps the names onto its frames).
3. Builds pinocchio_peer (header-only Pinocchio, g++ -O3 -march=native, once) and robodyn's
   `peer_timing` example (cargo --release with RUSTFLAGS=-Ctarget-cpu=native).
4. Both programs write their results on every state (floating robots: the dynamics only, rnea,
   crba, aba and A^-1(tau - H); Pinocchio's crba fills the upper triangle (and, with a free
   flyer, the whole 6 x 6 base block), its strict lower triangle is copied from the upper one,
   robodyn returns the full matrix); the agreement (max abs and relative
   difference per algorithm) is printed; a disagreement above 1e-9 (relative) stops the run.
5. Interleaved rounds pinned to one core (`taskset -c 1`): in each round, per robot, Pinocchio then
   robodyn (order swapped every other round); each program prints the median over samples of ns
   per call (a sample loops over all states, repeated to last ~400 us). The table gives the median
   over rounds and the spread (min-max over rounds) as a percentage; the ratio is the median over
   rounds of each round's ratio (the two programs back to back), with its range: the VM's speed
   changes by up to 2x within seconds, so a ratio of medians taken at different times can mislead.
6. With --codegen, the generated-code comparison of codegen.py runs too.
"""

import argparse
import math
import os
import shutil
import statistics
import subprocess
import sys
import sysconfig

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", "..", ".."))
BUILD = os.path.join(ROOT, "target", "peers")

# key: (label, URDF under example-robot-data's robots/, free-flyer root)
ROBOTS = {
    "ur5": ("UR5", "ur_description/urdf/ur5_robot.urdf", False),
    "panda": ("Panda", "panda_description/urdf/panda.urdf", False),
    "talos": ("Talos full", "talos_data/robots/talos_full_v2.urdf", False),
    "talos_ff": ("Talos full, floating", "talos_data/robots/talos_full_v2.urdf", True),
    "hyq": ("HyQ, floating", "hyq_description/robots/hyq_no_sensors.urdf", True),
    "solo12": ("Solo12, floating", "solo_description/robots/solo12.urdf", True),
}
JOINT_TYPES = {
    "JointModelRX": "RX",
    "JointModelRY": "RY",
    "JointModelRZ": "RZ",
    "JointModelPX": "PX",
    "JointModelPY": "PY",
    "JointModelPZ": "PZ",
    "JointModelRevoluteUnaligned": "RU",
    "JointModelPrismaticUnaligned": "PU",
    "JointModelFreeFlyer": "FF",
}
N_STATES = 64
# Pinocchio's headers need these (its CMake config exports them): joint variants of > 20 types.
PIN_DEFINES = [
    "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
    "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
    "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
    "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
]


def cmeel_prefix():
    for base in {sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]}:
        p = os.path.join(base, "cmeel.prefix")
        if os.path.isdir(os.path.join(p, "include", "pinocchio")):
            return p
    sys.exit("Pinocchio's headers not found: pip install pin cmeel-eigen cmeel-urdfdom-headers")


def urdf_path(prefix, rel):
    p = os.path.join(prefix, "share", "example-robot-data", "robots", rel)
    if not os.path.isfile(p):
        sys.exit(f"{p} missing: pip install example-robot-data")
    return p


def load_model(pin, prefix, key):
    """The URDF's path and Pinocchio's model of it (free-flyer root for the floating robots)."""
    urdf = urdf_path(prefix, ROBOTS[key][1])
    if ROBOTS[key][2]:
        return urdf, pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
    return urdf, pin.buildModelFromUrdf(urdf)


def robodyn_options(key, model):
    """peer_timing's options for a robot: --floating, or the frame of the kinematics' rows."""
    return ["--floating"] if ROBOTS[key][2] else ["--tip", tip_name(model)]


def num(x):
    return repr(float(x))


def dump_model(model, path):
    """One line per joint: name parent type axis(3) R(9, row-major) p(3) mass c(3) I(xx xy xz yy yz zz)."""
    lines = ["# joint name parent type axis R p mass com inertia(about com)"]
    lines.append("gravity " + " ".join(num(x) for x in model.gravity.linear))
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        t = JOINT_TYPES.get(j.shortname())
        if t is None:
            sys.exit(f"joint {model.names[jid]}: type {j.shortname()} not handled by the peer")
        axis = j.extract().axis if t in ("RU", "PU") else np.zeros(3)
        pl = model.jointPlacements[jid]
        ine = model.inertias[jid]
        i3 = ine.inertia
        fields = [model.names[jid], str(model.parents[jid]), t]
        fields += [num(x) for x in axis]
        fields += [num(x) for x in pl.rotation.reshape(-1)]
        fields += [num(x) for x in pl.translation]
        fields += [num(ine.mass)] + [num(x) for x in ine.lever]
        fields += [num(i3[0, 0]), num(i3[0, 1]), num(i3[0, 2]), num(i3[1, 1]), num(i3[1, 2]), num(i3[2, 2])]
        lines.append("joint " + " ".join(fields))
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")


def merged_urdf(pin, model, path):
    """The Pinocchio model (fixed joints merged into their parent body by its parser) written back
    as a URDF: one body per joint, no fixed joint. Timing robodyn on it measures what merging the
    fixed frames out of the dynamic recursions would gain (issue 18)."""
    axes = {"X": "1 0 0", "Y": "0 1 0", "Z": "0 0 1"}
    out = [f'<robot name="{model.name}_merged">', '  <link name="universe"/>']
    for jid in range(1, model.njoints):
        j = model.joints[jid]
        t = JOINT_TYPES[j.shortname()]
        axis = " ".join(num(x) for x in j.extract().axis) if t[1] == "U" else axes[t[1]]
        ine, pl = model.inertias[jid], model.jointPlacements[jid]
        i3 = ine.inertia
        parent = "universe" if model.parents[jid] == 0 else f"body_{model.parents[jid]}"
        out += [
            f'  <link name="body_{jid}"><inertial><origin xyz="{" ".join(num(x) for x in ine.lever)}" rpy="0 0 0"/>'
            f'<mass value="{num(ine.mass)}"/><inertia ixx="{num(i3[0, 0])}" ixy="{num(i3[0, 1])}" '
            f'ixz="{num(i3[0, 2])}" iyy="{num(i3[1, 1])}" iyz="{num(i3[1, 2])}" izz="{num(i3[2, 2])}"/>'
            "</inertial></link>",
            f'  <joint name="{model.names[jid]}" type="{"revolute" if t[0] == "R" else "prismatic"}">'
            f'<parent link="{parent}"/><child link="body_{jid}"/>'
            f'<origin xyz="{" ".join(num(x) for x in pl.translation)}" '
            f'rpy="{" ".join(num(x) for x in pin.rpy.matrixToRpy(pl.rotation))}"/>'
            f'<axis xyz="{axis}"/><limit lower="-10" upper="10" effort="1" velocity="1"/></joint>',
        ]
    with open(path, "w") as fh:
        fh.write("\n".join(out + ["</robot>"]) + "\n")


def write_states(pin, model, path, seed=1):
    rng = np.random.default_rng(seed)
    data = model.createData()
    nv = model.nv
    rows = []
    for _ in range(N_STATES):
        q = rng.uniform(-math.pi, math.pi, model.nq)
        if model.nq != nv:  # free flyer: position, then a unit quaternion (x, y, z, w)
            quat = rng.normal(size=4)
            q[:7] = np.concatenate([rng.uniform(-2, 2, 3), quat / np.linalg.norm(quat)])
        v = rng.uniform(-2, 2, nv)
        a = rng.uniform(-5, 5, nv)
        tau = pin.rnea(model, data, q, v, rng.uniform(-5, 5, nv)).copy()
        rows.append(" ".join(num(x) for x in np.concatenate([q, v, a, tau])))
    with open(path, "w") as fh:
        fh.write("names " + " ".join(model.names[1:]) + "\n" + "\n".join(rows) + "\n")


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, **kw)


def build_pinocchio(prefix):
    exe = os.path.join(BUILD, "pinocchio_peer")
    src = os.path.join(HERE, "pinocchio_peer.cpp")
    if os.path.exists(exe) and os.path.getmtime(exe) > os.path.getmtime(src):
        return exe
    print("building pinocchio_peer (header-only Pinocchio, -O3 -march=native; a few minutes)...", flush=True)
    inc = os.path.join(prefix, "include")
    run(["nice", "-n", "19", "g++", "-std=c++17", "-O3", "-march=native", "-DNDEBUG", "-w", *PIN_DEFINES,
         "-I", inc, "-I", os.path.join(inc, "eigen3"), src, "-o", exe])
    return exe


def build_robodyn():
    print("building robodyn's peer_timing example (--release, target-cpu=native)...", flush=True)
    env = dict(os.environ, RUSTFLAGS=os.environ.get("RUSTFLAGS", "-Ctarget-cpu=native"),
               CARGO_TARGET_DIR=os.path.join(BUILD, "cargo"))
    run(["nice", "-n", "19", "cargo", "build", "--release", "-q", "-p", "robodyn", "--example", "peer_timing"],
        cwd=ROOT, env=env)
    return os.path.join(BUILD, "cargo", "release", "examples", "peer_timing")


def tip_name(model):
    """The frame of the one-frame Jacobian: the last joint's child link (its frame is that
    joint's frame, Pinocchio's joint frame)."""
    return next(f.name for f in model.frames
                if f.parentJoint == model.njoints - 1 and str(f.type) == "BODY")


def read_results(path):
    out = {}
    with open(path) as fh:
        for line in fh:
            tag, *vals = line.split()
            out.setdefault(tag, []).append(np.array([float(v) for v in vals]))
    return {k: np.array(v) for k, v in out.items()}


def agreement(pin_res, rd_res):
    """Max abs and relative differences per algorithm (those both programs wrote)."""
    rows = {}
    for alg in ("rnea", "crba", "aba", "composite", "jac", "com", "drnea", "daba"):
        if alg not in pin_res and alg not in rd_res:
            continue
        p, r = pin_res[alg], rd_res[alg]
        diff = np.abs(p - r).max()
        rel = diff / max(1.0, np.abs(p).max())
        rows[alg] = (diff, rel)
    return rows


def timed(cmd):
    out = run(["taskset", "-c", "1", *cmd], capture_output=True).stdout
    return {l.split()[1]: float(l.split()[2]) for l in out.splitlines() if l.startswith("time ")}


def interleaved(rounds, keys, sides):
    """Interleaved rounds pinned to one core: sides(key) gives [(side, command)], run in that order
    in even rounds and reversed in odd ones. Returns times[key][side] = one dict per round."""
    times = {key: {} for key in keys}
    for r in range(rounds):
        for key in keys:
            order = sides(key)
            for side, cmd in (order if r % 2 == 0 else order[::-1]):
                times[key].setdefault(side, []).append(timed(cmd))
        print(f"round {r + 1}/{rounds} done", flush=True)
    return times


def round_stat(rounds, name):
    """Median over rounds of a timing, and the spread (max - min) in percent of it."""
    v = [t[name] for t in rounds]
    med = statistics.median(v)
    return med, (max(v) - min(v)) / med * 100


def arg_parser(doc, robots):
    """Options shared by run.py and codegen.py."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rounds", type=int, default=5, help="interleaved rounds")
    ap.add_argument("--samples", type=int, default=15, help="samples per timing in each round")
    ap.add_argument("--robots", default=robots, help="comma-separated, among " + ", ".join(ROBOTS))
    return ap


def main():
    ap = arg_parser(__doc__, "ur5,panda,talos")
    ap.add_argument("--codegen", action="store_true", help="also the generated-code comparison (codegen.py)")
    ap.add_argument("--robodyn-exe", help="a peer_timing binary already built (skips the cargo build)")
    ap.add_argument("--merged", action="store_true",
                    help="also time robodyn on the URDF rewritten with fixed joints merged (experiment)")
    args = ap.parse_args()
    import pinocchio as pin

    prefix = cmeel_prefix()
    os.makedirs(BUILD, exist_ok=True)
    robots = [r.strip() for r in args.robots.split(",")]
    for key in robots:
        if key not in ROBOTS:
            sys.exit(f"unknown robot {key}: one of {', '.join(ROBOTS)}")
    for tool in ("g++", "cargo", "taskset"):
        if shutil.which(tool) is None:
            sys.exit(f"{tool} not found")
    pin_exe = build_pinocchio(prefix)
    rd_exe = args.robodyn_exe or build_robodyn()
    files, rd_opts = {}, {}
    for key in robots:
        urdf, model = load_model(pin, prefix, key)
        mfile, sfile, merged = (os.path.join(BUILD, f"{key}.{ext}") for ext in ("model", "states", "merged.urdf"))
        dump_model(model, mfile)
        write_states(pin, model, sfile)
        if args.merged and not ROBOTS[key][2]:
            merged_urdf(pin, model, merged)
        files[key] = (urdf, mfile, sfile, model.nv, merged)
        rd_opts[key] = robodyn_options(key, model)

    print(f"pinocchio {pin.__version__}; {N_STATES} states per robot; agreement (max |robodyn - pinocchio|, "
          "relative to max(1, max |pinocchio|)):")
    ok = True
    for key in robots:
        urdf, mfile, sfile, nv, merged = files[key]
        pres = os.path.join(BUILD, f"{key}.pin.results")
        out = run([pin_exe, mfile, sfile, pres, "--samples", "1", "--target-us", "1"], capture_output=True).stdout
        triangle = next(l.split()[1] for l in out.splitlines() if l.startswith("crba_fills "))
        print(f"  {ROBOTS[key][0]}: Pinocchio's crba fills "
              + ("the upper triangle only" if triangle == "upper" else
                 "the upper triangle and part of the lower one (the free flyer's 6 x 6 block)")
              + "; the strict lower triangle is copied from the upper one on its side")
        merged_too = args.merged and not ROBOTS[key][2]
        for label, path in [("robodyn", urdf)] + ([("merged", merged)] if merged_too else []):
            rres = os.path.join(BUILD, f"{key}.{label}.results")
            run([rd_exe, path, sfile, rres, "--samples", "1", "--target-us", "1", *rd_opts[key]],
                capture_output=True)
            for alg, (d, rel) in agreement(read_results(pres), read_results(rres)).items():
                flag = "" if rel < 1e-9 else "   <-- DISAGREE"
                ok &= rel < 1e-9
                print(f"  {ROBOTS[key][0]:10s} {label:8s} {alg:10s} {d:9.2e} abs {rel:9.2e} rel{flag}")
    if not ok:
        sys.exit("results disagree: no timing")

    opts = ["--samples", str(args.samples)]

    def sides(key):
        urdf, mfile, sfile, _, merged = files[key]
        out = [("pin", [pin_exe, mfile, sfile, os.devnull, *opts]),
               ("rd", [rd_exe, urdf, sfile, os.devnull, *opts, *rd_opts[key]])]
        if args.merged and not ROBOTS[key][2]:
            out.append(("merged", [rd_exe, merged, sfile, os.devnull, *opts]))
        return out

    times = interleaved(args.rounds, robots, sides)
    stat = round_stat

    print()
    extra = " robodyn merged ns | ratio merged |" if args.merged else ""
    print(f"| robot (nv) | algorithm | robodyn ns | Pinocchio ns (variant) | ratio (range) | spread rd / pin |{extra}")
    print("|---|---|---|---|---|---|" + ("---|---|" if args.merged else ""))
    for key in robots:
        nv = files[key][3]
        rd, pn, rdm = times[key]["rd"], times[key]["pin"], times[key].get("merged")
        for label, rname, pnames in [
            ("inverse dynamics (rnea)", "rnea", ["rnea"]),
            ("inertia matrix, full (crba + lower fill)", "crba_full", ["crba_full_local", "crba_full_world"]),
            ("inertia matrix vs crba upper only", "crba_full", ["crba_upper_local", "crba_upper_world"]),
            ("direct dynamics O(n) (aba)", "aba", ["aba_local", "aba_world"]),
            ("direct dynamics A^-1(tau - H)", "composite", ["composite_local", "composite_world"]),
            ("all joints' Jacobians (robodyn: joint_jacobians_into; Pinocchio: computeJointJacobians)",
             "joint_jacobians", ["joint_jacobians"]),
            ("every joint's Jacobian read, WORLD (the above + one read per joint)",
             "all_frame_jacobians", ["all_frame_jacobians"]),
            ("a frame Jacobian, LOCAL, from q (computeFrameJacobian)", "frame_jacobian", ["frame_jacobian"]),
            ("centre of mass + its Jacobian from q (jacobianCenterOfMass)", "com_jacobian", ["com_jacobian"]),
            ("IDM derivatives dtau/dq, dtau/dv, A (computeRNEADerivatives)", "rnea_derivatives",
             ["rnea_derivatives"]),
            ("DDM derivatives dqdd/dq, dqdd/dv, A^-1 (computeABADerivatives)", "aba_derivatives",
             ["aba_derivatives"]),
        ]:
            if rname not in rd[0]:  # a floating robot: the dynamics only
                continue
            rm, rs = stat(rd, rname)
            best = min(pnames, key=lambda n: stat(pn, n)[0])
            pm, ps = stat(pn, best)
            variant = best.rsplit("_", 1)[1] if best.endswith(("_local", "_world")) else (
                "local" if best == "rnea" else "-")
            # the ratio of each round (the two programs ran back to back): its median and range
            # are robust to the VM's speed changing between rounds
            ratios = [a[rname] / b[best] for a, b in zip(rd, pn)]
            rmed = statistics.median(ratios)
            cols = f" {stat(rdm, rname)[0]:.0f} | {stat(rdm, rname)[0] / pm:.2f} |" if rdm else (
                " - | - |" if args.merged else "")
            print(f"| {ROBOTS[key][0]} ({nv}) | {label} | {rm:.0f} | {pm:.0f} ({variant}) | "
                  f"{rmed:.2f} ({min(ratios):.2f}-{max(ratios):.2f}) | {rs:.0f}% / {ps:.0f}% |{cols}")
    if args.codegen:
        run([sys.executable, os.path.join(HERE, "codegen.py")])


if __name__ == "__main__":
    main()
