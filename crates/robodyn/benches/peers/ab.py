#!/usr/bin/env python3
"""Paired A/B timing of robodyn's kernels: this tree against another commit. NOT run by CI.

    python3 crates/robodyn/benches/peers/ab.py --base <commit> [--rounds 21] [--robots ur5,panda,talos]
                                               (floating robots: talos_ff,hyq,solo12, dynamics only)
                                               [--base-exe <peer_timing built at that commit>]
                                               [--this-exe <peer_timing built in this tree>]

Why: a refactoring must not slow the kernels, and on a shared VM whose speed changes by up to 2x
within seconds only back-to-back pairs can show it. What it does:
1. `git worktree add` of <commit> under target/peers/ab-base (kept for the next run), and the
   same `peer_timing` example built in both trees (--release, target-cpu=native); `--base-exe`
   names a binary built at <commit> instead (no second build on a busy machine).
2. The states of run.py (Pinocchio's URDF parser, seed 1) for each robot; both builds must give
   the same results on them (max relative difference 1e-12), else no timing.
3. Rounds pinned to one core (`taskset -c 1`): per robot, base then this tree (order swapped every
   other round); each program prints the median over samples of ns per call.
4. Per algorithm: the median over rounds of each round's ratio this/base, its range and the
   fraction of rounds where this tree was slower. A ratio whose median is within the range's noise
   is reported as such, not as a change.
"""

import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run as peers  # noqa: E402

ALGORITHMS = ["rnea", "crba_full", "aba", "composite", "joint_jacobians", "all_frame_jacobians",
              "frame_jacobian", "com_jacobian", "rnea_derivatives", "aba_derivatives"]


def build(root, target):
    env = dict(os.environ, RUSTFLAGS=os.environ.get("RUSTFLAGS", "-Ctarget-cpu=native"), CARGO_TARGET_DIR=target)
    peers.run(["nice", "-n", "19", "cargo", "build", "--release", "-q", "-p", "robodyn", "--example", "peer_timing"],
              cwd=root, env=env)
    return os.path.join(target, "release", "examples", "peer_timing")


def base_tree(commit):
    path = os.path.join(peers.BUILD, "ab-base")
    if os.path.isdir(path):
        peers.run(["git", "-C", path, "checkout", "-q", "--detach", commit])
    else:
        peers.run(["git", "-C", peers.ROOT, "worktree", "add", "-q", "--detach", path, commit])
    return path


def main():
    ap = peers.arg_parser(__doc__, "ur5,panda,talos")
    ap.add_argument("--base", required=True, help="the commit to compare against")
    ap.add_argument("--base-exe", help="a peer_timing binary already built at --base (skips its build)")
    ap.add_argument("--this-exe", help="a peer_timing binary already built in this tree (skips its build)")
    args = ap.parse_args()
    import pinocchio as pin
    import numpy as np

    prefix = peers.cmeel_prefix()
    os.makedirs(peers.BUILD, exist_ok=True)
    robots = [r.strip() for r in args.robots.split(",")]
    print(f"building peer_timing at {args.base} and in this tree...", flush=True)
    exes = {
        "base": args.base_exe or build(base_tree(args.base), os.path.join(peers.BUILD, "ab-base-target")),
        "this": args.this_exe or build(peers.ROOT, os.path.join(peers.BUILD, "cargo")),
    }
    files = {}
    for key in robots:
        urdf, model = peers.load_model(pin, prefix, key)
        sfile = os.path.join(peers.BUILD, f"{key}.states")
        peers.write_states(pin, model, sfile)
        rd_opts = peers.robodyn_options(key, model)
        files[key] = (urdf, sfile, rd_opts)
        res = {}
        for side, exe in exes.items():
            out = os.path.join(peers.BUILD, f"{key}.ab-{side}.results")
            peers.run([exe, urdf, sfile, out, "--samples", "1", "--target-us", "1", *rd_opts],
                      capture_output=True)
            res[side] = peers.read_results(out)
        for alg in ("rnea", "crba", "aba", "composite", "jac", "com"):
            if alg not in res["base"]:  # a floating robot: the dynamics only
                continue
            a, b = res["this"][alg], res["base"][alg]
            rel = np.abs(a - b).max() / max(1.0, np.abs(b).max())
            if rel > 1e-12:
                sys.exit(f"{key} {alg}: the two builds disagree ({rel:.1e}): no timing")
    opts = ["--samples", str(args.samples)]

    def sides(key):
        urdf, sfile, rd_opts = files[key]
        return [(side, [exe, urdf, sfile, os.devnull, *opts, *rd_opts]) for side, exe in exes.items()]

    times = peers.interleaved(args.rounds, robots, sides)
    print()
    print(f"| robot | algorithm | base ns | this ns | ratio this/base, median (range) | rounds slower |")
    print("|---|---|---|---|---|---|")
    for key in robots:
        base, this = times[key]["base"], times[key]["this"]
        for alg in (a for a in ALGORITHMS if a in base[0]):
            ratios = [t[alg] / b[alg] for t, b in zip(this, base)]
            slower = sum(r > 1 for r in ratios)
            print(f"| {peers.ROBOTS[key][0]} | {alg} | {statistics.median(b[alg] for b in base):.0f} | "
                  f"{statistics.median(t[alg] for t in this):.0f} | {statistics.median(ratios):.3f} "
                  f"({min(ratios):.2f}-{max(ratios):.2f}) | {slower}/{len(ratios)} |")


if __name__ == "__main__":
    main()
