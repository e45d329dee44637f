"""Like-for-like check of the CasADi comparison (issue 21's open question).

`casadi_model.py` builds CasADi's graph with every parameter - and every per-section
constant derived from them (volumes, wall areas and temperatures, link resistances) - folded in
as a literal, so its generated C is specialised to one parameter set: it cannot be called with
other parameters (a fit, a sweep) without regenerating and recompiling. Ours takes the
parameters at run time. This script generates CasADi's C a second time with the parameters as
the functions' second input (the same graph, the topology's constants computed from them as
`Topology` computes them), checks it against the literal one, and times ours, CasADi's literal
C and CasADi's parameter-input C in alternating rounds (each kernel keeps its fastest round),
all from C with the same driver (`casadi_timer.c`, `--np`) and state as `compare.py`.

Usage (after `bench/run.sh` has built the venv and the native binary):
    bench/.venv/bin/python bench/casadi_params.py --ns 2,10,100 \
        --native target/native/release/examples/bench_native
"""
import argparse
import json
import math
import os
import subprocess
import sys

import casadi as ca
import numpy as np

from common import DEFAULT_PARAMS, Topology
from casadi_model import BUILD, HERE, CasadiModel, build_graph
from compare import native

NAMES = list(DEFAULT_PARAMS)


class SymTopology:
    """`Topology` with the parameters as the symbols `self.psym` (same formulas)."""

    def __init__(self, n):
        self.psym = ca.SX.sym("p", len(NAMES))
        p = {k: self.psym[i] for i, k in enumerate(NAMES)}
        self.p, self.n = p, n
        self.ncv = ncv = n + 2
        self.nx = 4 + 2 * ncv
        A, Ar = p["A"], p["Ar"]
        piD = math.pi * ca.sqrt(4 * A / math.pi)
        self.cp = p["gamma"] * p["R"] / (p["gamma"] - 1)
        self.V0 = [p["Vh0"]] + [p["Vr"] / n] * n + [p["Vc0"]]
        self.ax = [-A] + [0.0] * n + [A - Ar]
        self.ay = [0.0] * (n + 1) + [-(A - Ar)]
        self.Tw = [p["Th"]] + [p["Th"] - (j + 0.5) * (p["Th"] - p["Tk"]) / n for j in range(n)] + [p["Tk"]]
        self.h = [p["hh"]] + [p["hr"]] * n + [p["hk"]]
        self.Aw0 = [p["Awh0"]] + [p["Awr"] / n] * n + [p["Awc0"]]
        self.dAx = [-piD] + [0.0] * n + [piD]
        self.dAy = [0.0] * (n + 1) + [-piD]
        self.Rl = [p["Rf"] / (2 * n)] + [p["Rf"] / n] * (n - 1) + [p["Rf"] / (2 * n)]
        self.Fx0 = Ar * p["Pb"]
        self.Fy0 = (A - Ar) * p["Pb"]


def compile_params(n):
    """Generated C of f(z, p), jacf(z, p), fj(z, p) compiled with gcc -O3 -march=native."""
    topo = SymTopology(n)
    z, f = build_graph(topo)
    J = ca.jacobian(f, z)
    fs = [ca.Function("f", [z, topo.psym], [f]), ca.Function("jacf", [z, topo.psym], [J]),
          ca.Function("fj", [z, topo.psym], [f, J])]
    name = f"nsection_params_{n}"
    cg = ca.CodeGenerator(name + ".c", {"with_header": False})
    for fn in fs:
        cg.add(fn)
    os.makedirs(BUILD, exist_ok=True)
    cwd = os.getcwd()
    os.chdir(BUILD)
    try:
        cg.generate()
        subprocess.run(["gcc", "-O3", "-march=native", "-fPIC", "-shared", name + ".c", "-o", name + ".so"], check=True)
    finally:
        os.chdir(cwd)
    return os.path.join(BUILD, name + ".so"), fs


def time_c(lib, zv, pv=None):
    timer = os.path.join(BUILD, "casadi_timer")
    src = os.path.join(HERE, "casadi_timer.c")
    if not os.path.exists(timer) or os.path.getmtime(timer) < os.path.getmtime(src):
        subprocess.run(["gcc", "-O2", src, "-o", timer, "-ldl"], check=True)
    args = [timer, lib, str(len(zv))]
    text = " ".join(repr(float(v)) for v in zv)
    if pv is not None:
        args.append(f"--np={len(pv)}")
        text += " " + " ".join(repr(float(v)) for v in pv)
    run = subprocess.run(args + ["f", "jacf", "fj"], input=text, capture_output=True, text=True, check=True)
    t = json.loads(run.stdout)
    return {"rhs": t["f"], "jac": t["jacf"], "rhs_jac": t["fj"]}


def best(rounds):
    return {k: min(r[k] for r in rounds) for k in ("rhs", "jac", "rhs_jac")}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ns", default="2,10,100")
    ap.add_argument("--native", required=True)
    ap.add_argument("--rounds", type=int, default=3)
    a = ap.parse_args()
    rows = []
    for n in [int(s) for s in a.ns.split(",")]:
        print(f"--- n = {n}", file=sys.stderr, flush=True)
        ours0 = native(a.native, n, 1.0, kernels_only=True)
        params = ours0["params"]
        topo = Topology(n, params)
        literal = CasadiModel(topo)
        zv = topo.fairness_state()
        pv = [topo.p[k] for k in NAMES]
        lib, fs = compile_params(n)
        # the same functions: values at the bench state
        f_lit, f_par = np.array(literal.cF(zv)).ravel(), np.array(fs[0](zv, pv)).ravel()
        j_lit, j_par = literal.cJ(zv), fs[1](zv, pv)
        ef = np.max(np.abs(f_lit - f_par) / np.maximum(np.abs(f_lit), 1e-300))
        ej = np.max(np.abs(np.array(ca.DM(j_lit - j_par).nonzeros())))
        assert ef < 1e-12 and ej < 1e-9 * np.max(np.abs(np.array(j_lit.nonzeros()))), (ef, ej)
        ours, lit, par = [ours0["timings"]], [], []
        for r in range(a.rounds):
            lit.append(literal._c_kernel_times(zv))
            par.append(time_c(lib, zv, pv))
            if r > 0:
                ours.append(native(a.native, n, 1.0, kernels_only=True)["timings"])
        row = {"n": n, "ours": best(ours), "casadi_literal": best(lit), "casadi_params": best(par)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    print("\n  n | rhs+jac (ns): ours | CasADi literal p | CasADi p input | literal/ours | p-input/ours")
    for r in rows:
        s = {k: r[k]["rhs"] + r[k]["jac"] for k in ("ours", "casadi_literal", "casadi_params")}
        print(f"{r['n']:>4} | {s['ours'] * 1e9:>10.0f} | {s['casadi_literal'] * 1e9:>10.0f} | "
              f"{s['casadi_params'] * 1e9:>10.0f} | {s['casadi_literal'] / s['ours']:>6.2f}x | "
              f"{s['casadi_params'] / s['ours']:>6.2f}x")


if __name__ == "__main__":
    main()
