"""Side-by-side benchmark of `nsection` (full closure): ours (generated Rust), CasADi (SX graph,
generated C compiled with gcc -O3, CVODES) and SciPy (NumPy RHS, hand-written Jacobian,
`solve_ivp` BDF).

For each n: run the Rust binary (`examples/bench_native.rs`, JSON), build the CasADi and
SciPy models on the parameters the binary printed, check that all three give the same RHS and
Jacobian at the same state (relative 1e-9; otherwise the race is not fair and the run stops),
then time. Prints one table, writes `results.json` and `scaling.svg` next to this file.

Usage: python compare.py [--ns 2,10,100,1000] [--native PATH] [--scipy-sim-max-n 100]
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

import casadi_model
import scipy_model
from common import Topology

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
TOL = 1e-9


def native(path, n, t_end, kernels_only=False, sim_only=False):
    cmd = [path, "--n", str(n), "--json", "--t-end", str(t_end)]
    if kernels_only:
        cmd += ["--no-sim", "--no-poles"]
    if sim_only:
        cmd += ["--no-poles"]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


KERNELS = ("rhs", "jac", "rhs_jac", "jac_triplets", "rhs_jac_triplets")


def fastest_sim(ours, sims):
    """Ours' simulated second as the fastest of its first run and `sims` (the rounds that
    alternated with CVODES's runs); the solver's counts are the same in every run."""
    best = ours.get("sim")
    for s in sims:
        if s.get("ok") and best and best.get("ok") and s["seconds"] < best["seconds"]:
            best["seconds"] = s["seconds"]


def fastest_rounds(ours, rounds):
    """Each of ours' kernel timings as the fastest of its first measurement and `rounds`."""
    for r in rounds:
        for k in KERNELS:
            if k in r["timings"] and k in ours["timings"]:
                ours["timings"][k] = min(ours["timings"][k], r["timings"][k])


def dense(trip, nx):
    J = np.zeros((nx, nx))
    for r, c, v in trip:
        J[int(r), int(c)] += v
    return J


def rel_err(a, b, groups):
    """max over entries of |a - b| / max(|b|, 1e-4 * max|b| over the entry's group): relative,
    with a floor for entries that cancel (a section's mass balance, inflow minus outflow of
    nearly equal flows): below 1e-4 of the group's largest an entry is compared in absolute
    terms, so that at TOL = 1e-9 the two may differ by 1e-13 of the group's scale, a few
    round-offs of the terms that cancelled (a floor of 1e-12, as before Dec 3, passed only
    when both sides rounded alike, e.g. both divided where one now multiplies by 1 / b)."""
    a, b = np.asarray(a), np.asarray(b)
    worst = 0.0
    for g in groups:
        bg, ag = b[g], a[g]
        floor = 1e-4 * max(np.abs(bg).max(), 1e-300)
        worst = max(worst, float(np.max(np.abs(ag - bg) / np.maximum(np.abs(bg), floor))))
    return worst


def fairness(ours, other, nx, ncv):
    groups = [np.arange(0, 4), 4 + np.arange(ncv), 4 + ncv + np.arange(ncv)]
    ex = float(np.max(np.abs(np.array(ours["x"]) - np.array(other["x"])) / np.maximum(np.abs(ours["x"]), 1e-300)))
    ef = rel_err(other["f"], ours["f"], groups)
    Jo, Jt = dense(ours["jac"], nx), dense(other["jac"], nx)
    # compare entrywise on the union of both patterns, relative to each column's largest entry
    # within the same state group as the row (so mechanical rows are not swamped by pressure rows)
    ej = 0.0
    for g in groups:
        sub_o, sub_t = Jo[g, :], Jt[g, :]
        colmax = np.maximum(np.abs(sub_o).max(axis=0), 1e-300)
        d = np.abs(sub_t - sub_o)
        rel = np.where(np.abs(sub_o) > 1e-12 * colmax, d / np.maximum(np.abs(sub_o), 1e-300), d / colmax)
        ej = max(ej, float(rel.max()))
    return {"x": ex, "f": ef, "jac": ej}


def fmt_t(s):
    if s is None:
        return "-"
    if s < 1e-6:
        return f"{s * 1e9:.0f} ns"
    if s < 1e-3:
        return f"{s * 1e6:.2f} us"
    if s < 1:
        return f"{s * 1e3:.1f} ms"
    return f"{s:.2f} s"


def ratio(a, b):
    return None if (a is None or b is None or a == 0) else b / a


def fmt_r(r):
    return "-" if r is None else (f"{r:.1f}x" if r < 100 else f"{r:.0f}x")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ns", default="2,10,100,1000")
    ap.add_argument("--native", default=os.path.join(ROOT, "target", "release", "examples", "bench_native"))
    ap.add_argument("--scipy-sim-max-n", type=int, default=100,
                    help="skip the SciPy simulated second above this n (it takes minutes)")
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--no-casadi-vm", action="store_true", help="skip CVODES with the SX virtual machine")
    ap.add_argument("--rounds", type=int, default=3,
                    help="time ours' and CasADi's C kernels, and the simulated seconds (ours and "
                         "CVODES's), in turn this many times each and keep each one's fastest (a "
                         "machine whose speed drifts skews neither)")
    ap.add_argument("--casadi-c-max-n", type=int, default=100,
                    help="above this n CasADi generates no C (gcc -O3 of ~2000 states takes too long): "
                         "its kernels and CVODES run on the SX virtual machine")
    a = ap.parse_args()
    ns = [int(s) for s in a.ns.split(",")]
    rows = []
    for n in ns:
        print(f"--- n = {n}", file=sys.stderr, flush=True)
        ours = native(a.native, n, a.t_end)
        params = ours["params"]
        nx, ncv = ours["n_states"], n + 2
        topo = Topology(n, params)
        assert topo.nx == nx
        print("    casadi", file=sys.stderr, flush=True)
        cas = casadi_model.run(n, params, t_end=a.t_end, rtol=ours["rtol"], atol=ours["atol"],
                               vm_sim=not a.no_casadi_vm, c_max_n=a.casadi_c_max_n,
                               ours_kernels=lambda: native(a.native, n, a.t_end, kernels_only=True),
                               rounds=a.rounds,
                               ours_sim=lambda: native(a.native, n, a.t_end, sim_only=True)["sim"])
        fastest_rounds(ours, cas.get("ours_rounds", []))
        fastest_sim(ours, cas.get("ours_sims", []))
        print("    scipy", file=sys.stderr, flush=True)
        sci = scipy_model.run(n, params, do_sim=n <= a.scipy_sim_max_n, t_end=a.t_end, rtol=ours["rtol"], atol=ours["atol"])
        # the simulation starts and scales must agree too
        assert np.allclose(topo.sim_start(), ours["x0_sim"], rtol=1e-14, atol=0), "different sim start"
        assert np.allclose(topo.scale(), ours["scale"], rtol=1e-14, atol=0), "different tolerance scales"
        fair = {"casadi": fairness(ours, cas, nx, ncv), "scipy": fairness(ours, sci, nx, ncv)}
        for who, e in fair.items():
            bad = {k: v for k, v in e.items() if v > TOL}
            if bad:
                sys.exit(f"n = {n}: {who} disagrees with ours beyond {TOL}: {bad}")
        t_o, t_c, t_s = ours["timings"], cas["timings"], sci["timings"]
        sims_c = [s for s in cas.get("sims", []) if s.get("ok")]
        best_c = min(sims_c, key=lambda s: s["seconds"]) if sims_c else None
        sim_o = ours["sim"] if ours.get("sim", {}).get("ok") else None
        sim_s = sci.get("sim") if sci.get("sim", {}).get("ok") else None
        # end states should agree to the integration tolerance (a sanity check, not a gate)
        def end_dev(s):
            if not (s and sim_o):
                return None
            d = (np.array(s["x_end"]) - np.array(sim_o["x_end"])) / np.array(ours["scale"])
            return float(np.abs(d).max())
        row = {
            "n": n, "states": nx, "fair": fair,
            "rhs": {"ours": t_o["rhs"], "casadi": t_c["rhs"], "scipy": t_s["rhs"]},
            "jac": {"ours": t_o["jac"], "casadi": t_c["jac"], "scipy": t_s["jac"]},
            "rhs_jac": {"ours": t_o.get("rhs_jac"), "casadi": t_c.get("rhs_jac")},
            "triplets_ours": {"jac": t_o.get("jac_triplets"), "rhs_jac": t_o.get("rhs_jac_triplets")},
            "casadi_kernels": cas.get("kernels", "C -O3"),
            "casadi_kernel_timer": t_c.get("kernel_timer"),
            "jac_fd_ours": t_o["jac_fd"],
            "sim": {"ours": sim_o and sim_o["seconds"], "casadi": best_c and best_c["seconds"],
                    "scipy": sim_s and sim_s["seconds"]},
            "sim_detail": {"ours": {k: v for k, v in (ours.get("sim") or {}).items() if k != "x_end"},
                           "casadi": [{k: v for k, v in s.items() if k != "x_end"} for s in cas.get("sims", [])],
                           "scipy": {k: v for k, v in (sci.get("sim") or {}).items() if k != "x_end"}},
            "sim_end_dev": {"casadi": end_dev(best_c), "scipy": end_dev(sim_s)},
            "poles_ours": ours.get("poles"),
            "casadi_build_s": cas["build_and_compile_seconds"],
            "casadi_python_call": {"rhs": t_c["rhs_python_call"], "jac": t_c["jac_python_call"]},
        }
        rows.append(row)
        print(f"    fair: {fair}", file=sys.stderr, flush=True)
    with open(os.path.join(HERE, "results.json"), "w") as fh:
        json.dump(rows, fh, indent=1)
    print_table(rows, a.t_end)
    plot(rows)


def print_table(rows, t_end):
    hdr = ("| n | states | RHS ours | RHS CasADi | RHS SciPy | Jac ours | Jac CasADi | Jac SciPy | FD ours | FD/Jac "
           "| (RHS+Jac) CasADi/ours | RHS&Jac one call ours | one call CasADi | CasADi best/ours one call "
           "| sim ours | sim CVODES | sim SciPy | CVODES/ours | SciPy/ours | poles ours |")
    print(hdr)
    print("|" + "|".join(["---"] * (hdr.count("|") - 1)) + "|")
    for r in rows:
        rj = r["rhs"], r["jac"]
        sum_o = r["rhs"]["ours"] + r["jac"]["ours"]
        sum_c = r["rhs"]["casadi"] + r["jac"]["casadi"]
        s = r["sim"]
        poles = r["poles_ours"]["seconds"] if r["poles_ours"] and r["poles_ours"].get("ok") else None
        cells = [str(r["n"]), str(r["states"]),
                 fmt_t(rj[0]["ours"]), fmt_t(rj[0]["casadi"]), fmt_t(rj[0]["scipy"]),
                 fmt_t(rj[1]["ours"]), fmt_t(rj[1]["casadi"]), fmt_t(rj[1]["scipy"]),
                 fmt_t(r["jac_fd_ours"]), fmt_r(ratio(r["jac"]["ours"], r["jac_fd_ours"])),
                 fmt_r(ratio(sum_o, sum_c)),
                 fmt_t(r["rhs_jac"]["ours"]),
                 fmt_t(r["rhs_jac"]["casadi"]) + ("" if r["casadi_kernels"] == "C -O3" else " (SX VM)"),
                 fmt_r(ratio(r["rhs_jac"]["ours"], min(x for x in (sum_c, r["rhs_jac"]["casadi"]) if x))),
                 fmt_t(s["ours"]), fmt_t(s["casadi"]), fmt_t(s["scipy"]) if s["scipy"] else "skipped",
                 fmt_r(ratio(s["ours"], s["casadi"])), fmt_r(ratio(s["ours"], s["scipy"])), fmt_t(poles)]
        print("| " + " | ".join(cells) + " |")
    print(f"\nsim = {t_end:g} s of engine time from rest with the displacer moved 5 mm; ratios > 1x mean ours is faster.")
    print_solver_work(rows)


def print_solver_work(rows):
    """The integrators' work for the simulated second: steps, Newton iterations (per step),
    Newton-matrix factorizations and error-test failures, ours beside CVODES's (its fastest run)."""
    print("\n| n | steps ours | steps CVODES | Newton it. ours | Newton it. CVODES | Newton/step ours "
          "| Newton/step CVODES | LU ours | LU CVODES | err. test fails ours | err. test fails CVODES |")
    print("|" + "|".join(["---"] * 11) + "|")
    for r in rows:
        o = r["sim_detail"]["ours"] or {}
        cs = [c for c in r["sim_detail"]["casadi"] if c.get("ok")]
        c = min(cs, key=lambda s: s["seconds"]) if cs else {}
        per = lambda d: f"{d['newton_iterations'] / d['steps']:.2f}" if d.get("steps") and d.get("newton_iterations") is not None else "-"
        cells = [str(r["n"])] + [str(d.get(k, "-")) for k in ("steps", "newton_iterations") for d in (o, c)]
        cells += [per(o), per(c)]
        cells += [str(d.get(k, "-")) for k in ("lu_factorizations", "error_test_failures") for d in (o, c)]
        print("| " + " | ".join(cells) + " |")


def plot(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = [r["n"] for r in rows]
    fig, axs = plt.subplots(1, 3, figsize=(14, 4.2))
    for ax, key, title in ((axs[0], "rhs", "one RHS"), (axs[1], "jac", "one Jacobian")):
        for who, st in (("ours", "o-"), ("casadi", "s--"), ("scipy", "^:")):
            ax.loglog(n, [r[key][who] for r in rows], st, label={"ours": "ours (Rust)", "casadi": "CasADi C -O3 (SX VM above n = 100)", "scipy": "NumPy"}[who])
        if key == "jac":
            ax.loglog(n, [r["jac_fd_ours"] for r in rows], "x-.", label="ours, finite differences")
        ax.set_title(title); ax.set_xlabel("n (regenerator sections)"); ax.set_ylabel("seconds"); ax.grid(True, which="both", alpha=.3); ax.legend()
    ax = axs[2]
    for who, st, lab in (("ours", "o-", "ours (diffsol BDF)"), ("casadi", "s--", "CasADi CVODES"), ("scipy", "^:", "SciPy BDF")):
        pts = [(r["n"], r["sim"][who]) for r in rows if r["sim"][who]]
        if pts:
            ax.loglog(*zip(*pts), st, label=lab)
    ax.set_title("one simulated second"); ax.set_xlabel("n (regenerator sections)"); ax.set_ylabel("seconds"); ax.grid(True, which="both", alpha=.3); ax.legend()
    fig.suptitle("nsection (full closure): time per call / per simulated second")
    fig.tight_layout()
    fig.savefig(os.path.join(HERE, "scaling.svg"))


if __name__ == "__main__":
    main()
