#!/usr/bin/env python3
"""Generated code side by side: robodyn's `generate --lang c` / `--lang rust` against Pinocchio +
CppADCodeGen, on UR5 and Panda (fixed base). NOT run by CI.

    pip install pin example-robot-data cmeel-eigen cmeel-urdfdom-headers cmeel-cppad cmeel-cppadcodegen
    python3 crates/robodyn/benches/peers/codegen.py [--rounds 5] [--robots ur5,panda]

1. Same models and states as run.py (Pinocchio's URDF parser, dumped; seed 1).
2. cg_generate.cpp (Pinocchio's CodeGenRNEA / CodeGenCRBA / CodeGenABA / CodeGenRNEADerivatives
   on CppADCodeGen, built once) writes the C of rnea, crba (upper triangle), aba (WORLD), of
   computeRNEADerivatives traced (dtau_dq, dtau_dv, dtau_da) and of CppAD's Jacobian of rnea
   (`CodeGenRNEA::evalJacobian`, d tau / d[q v a]) for the robot; robodyn's CLI writes
   `--model idm`, `--model inertia` (lower triangle), `--model ddm` (A^-1 (Gamma - H) with
   L D L' written out) and `--model idm-derivatives` (dGamma/dq, dGamma/dqd, A) with
   `--numeric --no-friction --no-rotor`, in C and in Rust. The operation counts of both sides'
   derivative code are printed (CppADCodeGen's counted in its C as robodyn counts its own:
   binary `*`, `/`, `+`, `-`).
3. Every C function is compiled in its own translation unit with the same flags (default
   `-O3 -march=native`; CppADCodeGen's sources called directly, not through its dlopen'ed
   model-library wrapper, so that no call overhead is added to the peer) and linked with
   cg_timing.c; the Rust code is compiled into cg_timing.rs by rustc -C opt-level=3
   -C target-cpu=native.
4. All results are checked against Pinocchio's numeric rnea / crba / aba /
   computeRNEADerivatives (Python bindings) on the same states; then interleaved rounds pinned to one core; medians as in run.py.
"""

import json
import os
import statistics
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import run as peers  # noqa: E402

BUILD = peers.BUILD


def build_generator(prefix):
    exe = os.path.join(BUILD, "cg_generate")
    srcs = [os.path.join(HERE, f) for f in ("cg_generate.cpp", "peer_model.hpp")]
    if os.path.exists(exe) and os.path.getmtime(exe) > max(map(os.path.getmtime, srcs)):
        return exe
    print("building cg_generate (Pinocchio on CppADCodeGen; several minutes, ~3 GB)...", flush=True)
    inc = os.path.join(prefix, "include")
    peers.run(["nice", "-n", "19", "g++", "-std=c++17", "-O2", "-w", "-DNDEBUG", *peers.PIN_DEFINES,
               "-I", inc, "-I", os.path.join(inc, "eigen3"), srcs[0], "-o", exe, "-ldl"])
    return exe


def build_cli():
    print("building robodyn's CLI (--release)...", flush=True)
    env = dict(os.environ, CARGO_TARGET_DIR=os.path.join(BUILD, "cargo"),
               RUSTFLAGS=os.environ.get("RUSTFLAGS", "-Ctarget-cpu=native"))
    peers.run(["nice", "-n", "19", "cargo", "build", "--release", "-q", "-p", "robodyn-cli"],
              cwd=peers.ROOT, env=env)
    return os.path.join(BUILD, "cargo", "release", "robodyn")


def robodyn_order(cli, urdf, names):
    """idx[k]: index of Pinocchio's joint k in robodyn's joint arrays (the movable joints in
    frame order, as the generated code takes them); rank[k]: its place among the outputs (the
    same order)."""
    info = json.loads(peers.run([cli, "info", urdf, "--format", "json"], capture_output=True).stdout)
    frames = info["frames"][: info["nl"]]
    movable = [f["j"] for f in frames if f["sigma"] != 2]
    by_name = {f["name"]: f["j"] for f in frames if f["sigma"] != 2}
    rank = [movable.index(by_name[n]) for n in names]
    return len(movable), rank, rank


def write_cg_states(states_path, out_path, nv, nl, idx, rank):
    with open(states_path) as fh:
        rows = fh.read().splitlines()[1:]
    with open(out_path, "w") as fh:
        fh.write(f"{nv} {nl} {len(rows)}\n{' '.join(map(str, idx))}\n{' '.join(map(str, rank))}\n")
        fh.write("\n".join(rows) + "\n")


def reference(pin, model, states_path):
    """Pinocchio's numeric results (Python bindings) on the states, in the RESULTS layout."""
    data = model.createData()
    nv = model.nv
    out = {"rnea": [], "crba": [], "aba": [], "drnea": []}
    with open(states_path) as fh:
        for line in fh.read().splitlines()[1:]:
            x = np.array([float(v) for v in line.split()])
            q, v, a, tau = (x[k * nv:(k + 1) * nv] for k in range(4))
            out["rnea"].append(pin.rnea(model, data, q, v, a).copy())
            m = pin.crba(model, data, q).copy()
            out["crba"].append(np.triu(m) + np.triu(m, 1).T)
            out["aba"].append(pin.aba(model, data, q, v, tau).copy())
            dq, dv, da = (np.array(m) for m in pin.computeRNEADerivatives(model, data, q, v, a))
            # Pinocchio fills the upper triangle of dtau_da = M
            da = np.triu(da) + np.triu(da, 1).T
            out["drnea"].append(np.concatenate([dq.ravel(), dv.ravel(), da.ravel()]))
    return {k: np.array(v).reshape(len(v), -1) for k, v in out.items()}


def build_robot(key, cli, gen, cflags, pin, prefix):
    d = os.path.join(BUILD, "cg", key)
    os.makedirs(d, exist_ok=True)
    urdf = peers.urdf_path(prefix, peers.ROBOTS[key][1])
    model = pin.buildModelFromUrdf(urdf)
    mfile, sfile = os.path.join(d, "model"), os.path.join(d, "states")
    peers.dump_model(model, mfile)
    peers.write_states(pin, model, sfile)
    nl, idx, rank = robodyn_order(cli, urdf, model.names[1:])
    cgstates = os.path.join(d, "cgstates")
    write_cg_states(sfile, cgstates, model.nv, nl, idx, rank)
    peers.run([gen, mfile, d])
    objs = []
    for name, fun in (("rnea", "forward_zero"), ("crba", "forward_zero"), ("aba", "forward_zero"),
                      ("drnea", "forward_zero"), ("jrnea", "jacobian")):
        wrapper = os.path.join(d, f"cg_{name}.c")
        with open(wrapper, "w") as fh:
            fh.write(f'#include "{name}_{fun}.c"\n'
                     f"void cg_{name}(const double *x, double *y) {{\n"
                     "  const double *in[1] = {x};\n  double *out[1] = {y};\n"
                     "  struct LangCAtomicFun atomics = {0};\n"
                     f"  {name}_{fun}(in, out, atomics);\n}}\n")
        objs.append(wrapper)
    rs = {}
    ops = {}
    for model_kind, fname in (("idm", "rd_idm"), ("inertia", "rd_inertia"), ("ddm", "rd_ddm"),
                              ("idm-derivatives", "rd_idm_derivatives")):
        for lang, ext in (("c", "c"), ("rust", "rs")):
            path = os.path.join(d, f"{fname}.{ext}")
            res = peers.run([cli, "generate", urdf, "--model", model_kind, "--numeric", "--no-friction",
                             "--no-rotor", "--lang", lang, "--name", fname, "--output", path],
                            capture_output=True)
            ops[fname] = res.stderr.strip()
            if ext == "c":
                objs.append(path)
            else:
                rs[fname] = path
    o_files = []
    for src in objs:
        o = src[:-2] + ".o"
        peers.run(["nice", "-n", "19", "gcc", *cflags.split(), "-c", src, "-o", o, "-I", d])
        o_files.append(o)
    cexe = os.path.join(d, "cg_timing_c")
    peers.run(["gcc", *cflags.split(), os.path.join(HERE, "cg_timing.c"), *o_files, "-o", cexe, "-lm"])
    rexe = os.path.join(d, "cg_timing_rs")
    env = dict(os.environ, RD_IDM=rs["rd_idm"], RD_INERTIA=rs["rd_inertia"], RD_DDM=rs["rd_ddm"],
               RD_IDM_DERIVATIVES=rs["rd_idm_derivatives"])
    peers.run(["nice", "-n", "19", "rustc", "--edition", "2021", "-C", "opt-level=3", "-C", "target-cpu=native",
               os.path.join(HERE, "cg_timing.rs"), "-o", rexe], env=env)
    return {"dir": d, "cgstates": cgstates, "c": cexe, "rs": rexe, "ref": reference(pin, model, sfile),
            "nv": model.nv, "ops": ops,
            "cg_ops": count_c_ops(os.path.join(d, "drnea_forward_zero.c"), "drnea_forward_zero"),
            "jac_ops": count_c_ops(os.path.join(d, "jrnea_jacobian.c"), "jrnea_jacobian")}


def count_c_ops(path, fun):
    """(multiplications, additions, function calls) of a CppADCodeGen C function: its binary
    `*` and `/`, binary `+` and `-` (a sign after an operand), and calls, as robodyn counts its
    own generated C (tests/codegen_opcount.rs)."""
    import re
    with open(path) as fh:
        text = fh.read()
    body = text[text.index("{", text.index(fun + "(")):]
    mul = add = calls = 0
    for line in body.splitlines():
        line = line.strip()
        if "=" not in line or not line.endswith(";") or line.startswith(("//", "/*", "*")):
            continue
        rhs = line.split("=", 1)[1]
        # numbers (with exponents) are operands, not operators
        rhs = re.sub(r"\d+\.?\d*(e[+-]?\d+)?", "0", rhs, flags=re.I)
        calls += len(re.findall(r"\b(sin|cos|tan|sqrt|pow|exp|log|atan2?)\s*\(", rhs))
        mul += rhs.count("*") + rhs.count("/")
        add += len(re.findall(r"[\w\])]\s*[+-]", rhs))
    return mul, add, calls


def check(robot):
    res = {}
    for exe, tag in ((robot["c"], "c"), (robot["rs"], "rs")):
        out = os.path.join(robot["dir"], f"results_{tag}")
        peers.run([exe, robot["cgstates"], out, "1", "1"], capture_output=True)
        res.update(peers.read_results(out))
    pairs = [("cg_rnea", "rnea"), ("rd_rnea", "rnea"), ("rs_rnea", "rnea"),
             ("cg_crba", "crba"), ("rd_crba", "crba"), ("rs_crba", "crba"),
             ("cg_aba", "aba"), ("rd_ddm", "aba"), ("rs_ddm", "aba"),
             ("cg_drnea", "drnea"), ("cg_jrnea", "drnea"), ("rd_drnea", "drnea"), ("rs_drnea", "drnea")]
    worst = {}
    for tag, ref in pairs:
        r = robot["ref"][ref]
        worst[tag] = np.abs(res[tag] - r).max() / max(1.0, np.abs(r).max())
    return worst


def main():
    ap = peers.arg_parser(__doc__, "ur5,panda")
    ap.add_argument("--cflags", default="-O3 -march=native", help="flags of every generated C file")
    args = ap.parse_args()
    import pinocchio as pin

    prefix = peers.cmeel_prefix()
    if not os.path.isdir(os.path.join(prefix, "include", "cppad", "cg")):
        sys.exit("CppADCodeGen's headers not found: pip install cmeel-cppad cmeel-cppadcodegen")
    os.makedirs(BUILD, exist_ok=True)
    gen = build_generator(prefix)
    cli = build_cli()
    robots = {key: build_robot(key, cli, gen, args.cflags, pin, prefix) for key in args.robots.split(",")}
    print(f"generated code, C flags `{args.cflags}`; agreement with Pinocchio's numeric algorithms "
          "(max abs difference relative to max(1, max |reference|)):")
    ok = True
    for key, robot in robots.items():
        worst = check(robot)
        ok &= all(v < 1e-9 for v in worst.values())
        print(f"  {peers.ROBOTS[key][0]}: " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))
        m, a, c = robot["cg_ops"]
        print(f"    derivative code: robodyn {robot['ops']['rd_idm_derivatives']}; "
              f"CppADCodeGen drnea_forward_zero: {m} multiplications, {a} additions, {c} calls")
        m, a, c = robot["jac_ops"]
        print(f"    CppAD's Jacobian of rnea (jrnea_jacobian): {m} multiplications, {a} additions, {c} calls")
    if not ok:
        sys.exit("results disagree: no timing")
    times = peers.interleaved(
        args.rounds,
        list(robots),
        lambda key: [(side, [robots[key][side], robots[key]["cgstates"], os.devnull, str(args.samples)])
                     for side in ("c", "rs")],
    )
    med = peers.round_stat

    print()
    print("| robot | model | robodyn C ns | robodyn Rust ns | CppADCodeGen ns | ratio C (range) | ratio Rust (range) | spread C / Rust / cg |")
    print("|---|---|---|---|---|---|---|---|")
    for key in robots:
        c, rs = times[key]["c"], times[key]["rs"]
        for label, rname, cname in [("inverse dynamics (IDM / rnea)", "idm", "cg_rnea"),
                                    ("inertia matrix (crba)", "inertia", "cg_crba"),
                                    ("direct dynamics (robodyn L D L' / cg ABA)", "ddm", "cg_aba"),
                                    ("IDM derivatives (dq, dv, M) / computeRNEADerivatives traced", "idm_derivatives", "cg_drnea"),
                                    ("IDM derivatives (dq, dv, M) / CppAD Jacobian of rnea", "idm_derivatives", "cg_jrnea")]:
            (mc, sc), (mr, sr), (mg, sg) = med(c, f"rd_{rname}_c"), med(rs, f"rd_{rname}_rust"), med(c, cname)
            # ratios per round (C: the same program; Rust: the program run next to it), their
            # median and range, as in run.py
            rc = [a[f"rd_{rname}_c"] / a[cname] for a in c]
            rr = [b[f"rd_{rname}_rust"] / a[cname] for a, b in zip(c, rs)]
            fmt = lambda v: f"{statistics.median(v):.2f} ({min(v):.2f}-{max(v):.2f})"  # noqa: E731
            print(f"| {peers.ROBOTS[key][0]} | {label} | {mc:.0f} | {mr:.0f} | {mg:.0f} | {fmt(rc)} | "
                  f"{fmt(rr)} | {sc:.0f}% / {sr:.0f}% / {sg:.0f}% |")


if __name__ == "__main__":
    main()
