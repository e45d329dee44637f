"""Engines from files against the macro and CasADi (issue 35's speed bars), in one run.

For each n: run `examples/files_speed.rs` (JSON: the load and compile time of
`examples/engines/nsection.stirling`, and RHS + Jacobian values per call of the macro's
`nsection`, the file's model compiled by the JIT, and the JIT with the parameters folded in,
at the benchmarks' fairness state). For n up to `--casadi-max-n`, also build CasADi's
generated C twice - every parameter a literal (`casadi_model.py`) and the parameters as the
functions' second input (`casadi_params.py`) - check that both give our folded model's RHS
and Jacobian at the same state (relative 1e-9, as `compare.py`; otherwise the race is not
fair and the run stops), and time CasADi's `fj` (RHS and Jacobian in one call) from C
(`casadi_timer.c`). Ours and CasADi's are timed in alternating rounds, each keeping its
fastest, so every ratio is measured in the same run on the same machine load.

Prints one table; writes `files_results.json` next to this file.

Usage: python files_compare.py --speed PATH [--ns 2,10,100,1000] [--casadi-max-n 100]
       [--rounds 3] [--before PATH]
(`--before`: another build of files_speed, e.g. the branch point's, timed in the same rounds,
so that a change is measured against its base in one run under one load.)
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

from casadi_model import CasadiModel
from casadi_params import NAMES, compile_params, time_c
from common import Topology
from compare import TOL, fairness

HERE = os.path.dirname(os.path.abspath(__file__))


def speed(path, n):
    out = subprocess.run([path, "--json", "--ns", str(n)], check=True, capture_output=True,
                         text=True).stdout
    doc = json.loads(out)
    return doc["load"], doc["rhs_jacobian"][0]


TIMES = ("macro_ns", "jit_ns", "jit_folded_ns", "cc_folded_ns", "kernel_ns")


def keep_fastest(best, row):
    for k in TIMES:
        if k in best and k in row:
            best[k] = min(best[k], row[k])
    best["jit_over_macro"] = best["jit_ns"] / best["macro_ns"]
    best["jit_folded_over_macro"] = best["jit_folded_ns"] / best["macro_ns"]


def check(ours, cas, n):
    """CasADi's literal model at our state agrees with our folded model (else stop)."""
    x = np.array(ours["x"])
    r, c, v = cas.jac_triplets(x)
    other = {"x": ours["x"], "f": cas.rhs(x), "jac": list(zip(r, c, v))}
    err = fairness(ours, other, len(x), n + 2)
    if max(err.values()) > TOL:
        sys.exit(f"n = {n}: CasADi and the folded model disagree ({err}); not a fair race")
    return err


def before_row(before, n, rounds):
    """The same row of another build of `files_speed` (`--before`), its fastest of `rounds`."""
    if not before:
        return None
    row = speed(before, n)[1]
    for _ in range(rounds - 1):
        keep_fastest(row, speed(before, n)[1])
    return row


def with_before(best, old):
    """`best` with the other build's times and ratios (`before_*`)."""
    if old is None:
        return best
    for k in ("macro_ns", "jit_ns", "jit_folded_ns"):
        best["before_" + k] = old[k]
    best["before_jit_over_macro"] = old["jit_ns"] / old["macro_ns"]
    lit = best.get("casadi_literal_ns")
    if lit:
        best["before_literal_over_folded"] = lit / old["jit_folded_ns"]
    return best


def casadi_row(path, n, rounds, before=None):
    load, first = speed(path, n)
    topo = Topology(n, first["params"])
    literal = CasadiModel(topo, K=(16, 32))
    err = check(first["folded_at_x"], literal, n)
    check(first["cc_folded_at_x"], literal, n)
    lib, fs = compile_params(n)
    x = first["folded_at_x"]["x"]
    pv = [topo.p[k] for k in NAMES]
    f_par = np.array(fs[0](x, pv)).ravel()
    assert np.allclose(f_par, literal.rhs(np.array(x)), rtol=1e-12, atol=0), "p-input C differs"
    best = dict(first)
    lit, par = float("inf"), float("inf")
    old = None
    for r in range(rounds):
        if r > 0:
            keep_fastest(best, speed(path, n)[1])
        if before:
            row = speed(before, n)[1]
            if old is None:
                old = row
            else:
                keep_fastest(old, row)
        lit = min(lit, literal._c_kernel_times(np.array(x))["rhs_jac"] * 1e9)
        par = min(par, time_c(lib, x, pv)["rhs_jac"] * 1e9)
    best.pop("folded_at_x", None)
    best.pop("cc_folded_at_x", None)
    best.update({"casadi_literal_ns": lit, "casadi_params_ns": par, "fairness": err,
                 "literal_over_folded": lit / best["jit_folded_ns"],
                 "literal_over_model": lit / best["cc_folded_ns"],
                 "literal_over_kernel": lit / best["kernel_ns"],
                 "params_over_folded": par / best["jit_folded_ns"],
                 "params_over_jit": par / best["jit_ns"]})
    return load, with_before(best, old)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--speed", required=True, help="the files_speed example binary")
    ap.add_argument("--ns", default="2,10,100,1000")
    ap.add_argument("--casadi-max-n", type=int, default=100)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--before", help="another build of files_speed (e.g. before a change), "
                    "timed in the same rounds: its JIT / macro and literal / folded printed too")
    a = ap.parse_args()
    rows, loads = [], []
    for n in [int(s) for s in a.ns.split(",")]:
        print(f"--- files, n = {n}", file=sys.stderr, flush=True)
        if n <= a.casadi_max_n:
            load, row = casadi_row(a.speed, n, a.rounds, a.before)
        else:
            load, row = speed(a.speed, n)
            old = None
            for r in range(a.rounds):
                if r > 0:
                    keep_fastest(row, speed(a.speed, n)[1])
                if a.before:
                    o = speed(a.before, n)[1]
                    if old is None:
                        old = o
                    else:
                        keep_fastest(old, o)
            row.pop("folded_at_x", None)
            row.pop("cc_folded_at_x", None)
            row = with_before(row, old)
        loads.append(load)
        rows.append(row)
    with open(os.path.join(HERE, "files_results.json"), "w") as fh:
        json.dump({"load": loads, "rows": rows}, fh, indent=1)
    print_table(loads, rows)


def print_table(loads, rows):
    total = sorted(l["total_ms"] for l in loads)
    l0 = min(loads, key=lambda l: l["total_ms"])
    print(f"\nnsection.stirling, read to native RHS + Jacobian at n = {l0['n']}: "
          f"{l0['total_ms']:.1f} ms at best of {len(total)} runs (median {total[len(total) // 2]:.1f}; "
          f"read+lower {l0['read_lower_ms']:.1f}, assemble+differentiate "
          f"{l0['assemble_differentiate_ms']:.1f}, tapes {l0['tapes_ms']:.1f}, JIT "
          f"{l0['jit_rhs_jacobian_ms']:.1f}); target <= 50 ms")
    print("\nRHS + Jacobian values, ns per call (same run, alternating rounds)")
    print("folded: Cranelift's folded tapes through the Model trait; folded*: the C compiler's where"
          " it pays (files::folded_native), through the Model trait; kernel: that model's kernel"
          " (the state alone, no parameter check: like CasADi's literal C)")
    print("     n    macro      JIT  JIT/macro  JIT compile  folded folded*  kernel  CasADi lit"
          "  CasADi p-in  lit/folded lit/folded*  lit/kernel  p-in/folded")
    for r in rows:
        lit = r.get("casadi_literal_ns")
        cas = (f"{lit:>11.0f}  {r['casadi_params_ns']:>11.0f}  {r['literal_over_folded']:>9.2f}x"
               f"  {r['literal_over_model']:>9.2f}x  {r['literal_over_kernel']:>9.2f}x"
               f"  {r['params_over_folded']:>10.2f}x") if lit else f"{'-':>11}  {'-':>11}"
        print(f"{r['n']:>6} {r['macro_ns']:>8.0f} {r['jit_ns']:>8.0f} {r['jit_over_macro']:>9.2f}x"
              f" {r['jit_compile_ms']:>9.1f} ms {r['jit_folded_ns']:>7.0f} {r['cc_folded_ns']:>7.0f}"
              f" {r['kernel_ns']:>7.0f}  {cas}")
    if any("before_jit_ns" in r for r in rows):
        print("\nthe other build (--before), same rounds:")
        print("     n    macro      JIT  JIT/macro  folded  lit/folded")
        for r in rows:
            if "before_jit_ns" not in r:
                continue
            lf = r.get("before_literal_over_folded")
            lf = f"{lf:>9.2f}x" if lf else f"{'-':>10}"
            print(f"{r['n']:>6} {r['before_macro_ns']:>8.0f} {r['before_jit_ns']:>8.0f}"
                  f" {r['before_jit_over_macro']:>9.2f}x {r['before_jit_folded_ns']:>7.0f}  {lf}")
    print("\nbars: JIT/macro <= 1.3 at every n; CasADi literal / kernel >= 1.5 at n <= 100 (like for"
          " like: neither takes the parameters); lit/folded* is the same code through the Model trait")


if __name__ == "__main__":
    main()
