"""`nsection` (full closure) as a CasADi SX graph: RHS, its sparse `jacobian`, generated C
compiled with `gcc -O3`, and one simulated second with CVODES (BDF, Newton, analytic Jacobian
from the graph).

Timing of the compiled functions (fair to CasADi): a Python call into `casadi.external` costs
microseconds of wrapper overhead, more than the RHS itself at small n. So the generated C is
timed from C (`casadi_timer.c`, compiled with gcc -O2 and loading the library): the same state,
the same batches of calls (about 2 ms each) and median as `bench_native` uses for ours, the
outputs written into buffers of the functions' nonzeros. Where no C is generated (the SX
virtual machine, large n), the library's `f.map(K, 'serial')` (one call evaluating K copies)
is timed from Python at K1 < K2 and `(t(K2) - t(K1)) / (K2 - K1)` cancels the per-call wrapper
overhead (not the allocation of the K outputs, which counts against CasADi there).

CVODES: states are scaled `z = x / s` with the same scales as ours, so a scalar `abstol`
reproduces our per-state `atol * s_i`; `reltol = rtol`. Two runs are timed: CasADi's default
(the SX virtual machine evaluates the RHS and Jacobian for CVODES) and with `jit=True`
(CasADi generates and compiles the integrator's functions with gcc -O3); the faster one is
the comparison. Each is timed as ours is (`bench_native`): the median of 3 to 7 runs of the
same integrator (the first alone moved by 20 % from one call to the next).

Run alone: `python casadi_model.py --n 10`.
"""
import argparse
import json
import os
import subprocess
import tempfile
import time

import casadi as ca
import numpy as np

from common import Topology, median_time

HERE = os.path.dirname(os.path.abspath(__file__))
BUILD = os.path.join(HERE, ".build")


def _num(v):
    """A topology constant: a literal (folded into the generated C) or, in the like-for-like
    variant (`casadi_params.py`), an expression of the parameters."""
    return v if isinstance(v, ca.SX) else float(v)


def _nz(v):
    """Whether a topology coefficient is structurally nonzero."""
    return isinstance(v, ca.SX) or v != 0


def build_graph(topo: Topology):
    p = topo.p
    ncv, nx = topo.ncv, topo.nx
    z = ca.SX.sym("z", nx)
    x, v, y, w = z[0], z[1], z[2], z[3]
    P = [z[4 + i] for i in range(ncv)]
    m = [z[4 + ncv + i] for i in range(ncv)]
    g, R, cp, eps = p["gamma"], p["R"], topo.cp, p["mdot_eps"]
    V, Vd, T = [], [], []
    for i in range(ncv):
        Vi = _num(topo.V0[i])
        if _nz(topo.ax[i]):
            Vi = Vi + _num(topo.ax[i]) * x
        if _nz(topo.ay[i]):
            Vi = Vi + _num(topo.ay[i]) * y
        V.append(Vi)
        Vd.append(_num(topo.ax[i]) * v + _num(topo.ay[i]) * w)
        T.append(P[i] * Vi / (m[i] * R))
    E = []
    for i in range(ncv):
        Aw = _num(topo.Aw0[i])
        if _nz(topo.dAx[i]):
            Aw = Aw + _num(topo.dAx[i]) * x
        if _nz(topo.dAy[i]):
            Aw = Aw + _num(topo.dAy[i]) * y
        E.append(_num(topo.h[i]) * Aw * (_num(topo.Tw[i]) - T[i]))
    Mn = [0] * ncv
    for l in range(ncv - 1):
        mdot = (P[l] - P[l + 1]) / _num(topo.Rl[l])
        s = 0.5 * (1 + ca.tanh(mdot / eps))
        H = cp * mdot * (s * T[l] + (1 - s) * T[l + 1])
        E[l] = E[l] - H
        E[l + 1] = E[l + 1] + H
        Mn[l] = Mn[l] - mdot
        Mn[l + 1] = Mn[l + 1] + mdot
    Pd = [((g - 1) * E[i] - g * P[i] * Vd[i]) / V[i] for i in range(ncv)]
    Fx = topo.Fx0 + sum(_num(topo.ax[i]) * P[i] for i in range(ncv) if _nz(topo.ax[i]))
    Fy = topo.Fy0 + sum(_num(topo.ay[i]) * P[i] for i in range(ncv) if _nz(topo.ay[i]))
    vd = (Fx - p["kd"] * x - p["bd"] * v - p["b"] * (v - w) - p["bqd"] * v * ca.fabs(v)) / p["md"]
    wd = (Fy - p["kp"] * y - p["bp"] * w - p["b"] * (w - v) - p["bqp"] * w * ca.fabs(w)) / p["mp"]
    f = ca.vertcat(v, vd, w, wd, *Pd, *Mn)
    return z, f


class CasadiModel:
    def __init__(self, topo: Topology, K=(16, 256), compiled=True):
        self.topo = topo
        self.z, self.f = build_graph(topo)
        self.J = ca.jacobian(self.f, self.z)  # sparse SX
        self.F = ca.Function("f", [self.z], [self.f])
        self.Jf = ca.Function("jacf", [self.z], [self.J])
        # RHS and Jacobian in one function: CasADi's own common-subexpression sharing
        self.FJ = ca.Function("fj", [self.z], [self.f, self.J])
        self.K = K
        self.compiled = compiled
        if compiled:
            self._compile()
        else:
            self._vm()

    def _vm(self):
        """No C: the functions run on CasADi's SX virtual machine (for n where gcc -O3 of the
        generated C takes too long)."""
        self.compile_seconds = 0.0
        self.cF, self.cJ, self.cFJ = self.F, self.Jf, self.FJ
        self.cFmap = {k: self.F.map(f"f_map{k}", "serial", k, [], []) for k in self.K}
        self.cJmap = {k: self.Jf.map(f"jacf_map{k}", "serial", k, [], []) for k in self.K}
        self.cFJmap = {k: self.FJ.map(f"fj_map{k}", "serial", k, [], []) for k in self.K}

    def _compile(self):
        os.makedirs(BUILD, exist_ok=True)
        name = f"nsection_{self.topo.n}"
        cg = ca.CodeGenerator(name + ".c", {"with_header": False})
        cg.add(self.F)
        cg.add(self.Jf)
        cg.add(self.FJ)
        for k in self.K:
            cg.add(self.F.map(f"f_map{k}", "serial", k, [], []))
            cg.add(self.Jf.map(f"jacf_map{k}", "serial", k, [], []))
            cg.add(self.FJ.map(f"fj_map{k}", "serial", k, [], []))
        cwd = os.getcwd()
        os.chdir(BUILD)
        try:
            cg.generate()
            t0 = time.perf_counter()
            subprocess.run(["gcc", "-O3", "-march=native", "-fPIC", "-shared", name + ".c", "-o", name + ".so"], check=True)
            self.compile_seconds = time.perf_counter() - t0
        finally:
            os.chdir(cwd)
        so = os.path.join(BUILD, name + ".so")
        self.lib = so
        self.cF = ca.external("f", so)
        self.cJ = ca.external("jacf", so)
        self.cFJ = ca.external("fj", so)
        self.cFmap = {k: ca.external(f"f_map{k}", so) for k in self.K}
        self.cJmap = {k: ca.external(f"jacf_map{k}", so) for k in self.K}
        self.cFJmap = {k: ca.external(f"fj_map{k}", so) for k in self.K}

    def rhs(self, zv):
        return np.array(self.cF(zv)).ravel()

    def jac_triplets(self, zv):
        Jm = self.cJ(zv)  # DM, sparse
        sp = Jm.sparsity()
        r, c = sp.get_triplet()
        return np.array(r), np.array(c), np.array(Jm.nonzeros())

    def kernel_times(self, zv):
        """Per-evaluation seconds of the RHS and Jacobian kernels. Generated C: timed from C by
        `casadi_timer.c` (the same batches and median as `bench_native`, no Python in the loop).
        SX virtual machine: `map(K)` calls from Python, `(t256 - t16) / 240` (wrapper overhead
        cancelled)."""
        out = self._c_kernel_times(zv) if self.compiled else self._vm_kernel_times(zv)
        for key, single in (("rhs", self.cF), ("jac", self.cJ), ("rhs_jac", self.cFJ)):
            out[key + "_python_call"] = median_time(lambda: single(zv), reps=31)
        out["jac_nnz"] = int(self.J.nnz())
        return out

    def _c_kernel_times(self, zv):
        timer = os.path.join(BUILD, "casadi_timer")
        src = os.path.join(HERE, "casadi_timer.c")
        if not os.path.exists(timer) or os.path.getmtime(timer) < os.path.getmtime(src):
            subprocess.run(["gcc", "-O2", src, "-o", timer, "-ldl"], check=True)
        state = " ".join(repr(float(v)) for v in zv)
        run = subprocess.run([timer, self.lib, str(len(zv)), "f", "jacf", "fj"], input=state,
                             capture_output=True, text=True, check=True)
        t = json.loads(run.stdout)
        return {"rhs": t["f"], "jac": t["jacf"], "rhs_jac": t["fj"], "kernel_timer": "C driver"}

    def _vm_kernel_times(self, zv):
        k1, k2 = self.K
        Z1 = ca.DM(np.tile(zv[:, None], (1, k1)))
        Z2 = ca.DM(np.tile(zv[:, None], (1, k2)))
        out = {"kernel_timer": "map(K) from Python"}
        for key, fmap in (("rhs", self.cFmap), ("jac", self.cJmap), ("rhs_jac", self.cFJmap)):
            t1 = median_time(lambda: fmap[k1](Z1), reps=31)
            t2 = median_time(lambda: fmap[k2](Z2), reps=31)
            out[key] = max((t2 - t1) / (k2 - k1), 0.0)
        return out

    def simulate(self, t_end=1.0, rtol=1e-7, atol=1e-7, jit=False, max_s=None):
        topo = self.topo
        s = topo.scale()
        zs = ca.SX.sym("zs", topo.nx)
        ode = ca.substitute(self.f, self.z, zs * s) / s
        opts = {
            "abstol": atol, "reltol": rtol, "max_num_steps": 10_000_000,
            "linear_multistep_method": "bdf", "nonlinear_solver_iteration": "newton",
            "newton_scheme": "direct",
        }
        if jit:
            opts.update({"jit": True, "compiler": "shell",
                         "jit_options": {"compiler": "gcc", "flags": ["-O3", "-march=native"], "verbose": False}})
        t0 = time.perf_counter()
        F = ca.integrator("F", "cvodes", {"x": zs, "ode": ode}, 0.0, t_end, opts)
        setup = time.perf_counter() - t0
        z0 = topo.sim_start() / s
        # the rule of ours (`bench_native`): at least 3 runs, more while the total stays under
        # about 3 s, at most 7; the median. One run alone moved by 20 % between calls here.
        times, started = [], time.perf_counter()
        while len(times) < 7 and (len(times) < 3 or time.perf_counter() - started < 3.0):
            t0 = time.perf_counter()
            try:
                r = F(x0=z0)
                ok, err = True, None
            except RuntimeError as e:
                ok, err = False, str(e).splitlines()[-1]
            times.append(time.perf_counter() - t0)
            if not ok or times[0] > 20.0:
                break
        el = float(np.median(times))
        st = F.stats()
        res = {"ok": ok and bool(st.get("success", True)), "seconds": el, "runs": len(times),
               "setup_seconds": setup, "t_end": t_end, "jit": jit}
        if err:
            res["error"] = err
        for k_out, k_in in (("steps", "nsteps"), ("rhs_calls", "nfevals"), ("jacobian_calls", "njevals"),
                            ("lu_factorizations", "nlinsetups"), ("error_test_failures", "netfails"), ("jacobian_calls", "n_call_jacF"),
                            ("newton_iterations", "nniters"), ("newton_failures", "nncfails")):
            if k_in in st:
                res[k_out] = int(st[k_in])
        if ok:
            res["x_end"] = (np.array(r["xf"]).ravel() * s).tolist()
        res["linear_solver"] = st.get("linear_solver", "default")
        return res


def run(n, params=None, do_sim=True, t_end=1.0, rtol=1e-7, atol=1e-7, jit_sim=True, vm_sim=True,
        c_max_n=None, ours_kernels=None, rounds=1, ours_sim=None):
    """`c_max_n`: above this n no C is generated: kernels timed on the SX virtual machine and
    CVODES run with it only (no jit). `ours_kernels` (a function that times ours and returns
    its timings) with `rounds > 1`: the generated C's kernels and ours are timed in turn,
    `rounds` times each, and each kernel keeps its fastest round (`timings` here, the list of
    ours in `ours_rounds`): a drift of the machine's speed during the run then shows in neither.
    `ours_sim` (a function that runs ours' simulated second and returns its result) likewise:
    CVODES's runs and ours alternate `rounds` times (`sims` holds every CVODES run, `ours_sims`
    ours), and the comparison takes each side's fastest."""
    topo = Topology(n, params)
    t0 = time.perf_counter()
    compiled = c_max_n is None or n <= c_max_n
    cm = CasadiModel(topo, compiled=compiled)
    jit_sim = jit_sim and compiled
    vm_sim = vm_sim or not compiled
    build_s = time.perf_counter() - t0
    z = topo.fairness_state()
    r, c, vals = cm.jac_triplets(z)
    out = {
        "n": n, "n_states": topo.nx, "build_and_compile_seconds": build_s,
        "kernels": "C -O3" if compiled else "SX VM",
        "x": z.tolist(), "f": cm.rhs(z).tolist(),
        "jac": [[int(a), int(b), float(v)] for a, b, v in zip(r, c, vals)],
        "timings": cm.kernel_times(z),
    }
    if ours_kernels is not None and compiled and rounds > 1:
        out["ours_rounds"] = []
        for _ in range(rounds - 1):
            out["ours_rounds"].append(ours_kernels())
            again = cm._c_kernel_times(z)
            for k in ("rhs", "jac", "rhs_jac"):
                out["timings"][k] = min(out["timings"][k], again[k])
        out["ours_rounds"].append(ours_kernels())
    if do_sim:
        sims, out["ours_sims"] = [], []
        for k in range(max(rounds, 1)):
            if k > 0 and ours_sim is not None:
                out["ours_sims"].append(ours_sim())
            if vm_sim and (k == 0 or not jit_sim):
                sims.append(cm.simulate(t_end, rtol, atol, jit=False))
            if jit_sim:
                sims.append(cm.simulate(t_end, rtol, atol, jit=True))
            if ours_sim is None:
                break
        out["sims"] = sims
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--no-sim", action="store_true")
    ap.add_argument("--t-end", type=float, default=1.0)
    a = ap.parse_args()
    res = run(a.n, do_sim=not a.no_sim, t_end=a.t_end)
    res.pop("jac"); res.pop("x"); res.pop("f")
    for s_ in res.get("sims", []):
        s_.pop("x_end", None)
    print(json.dumps(res, indent=1))
