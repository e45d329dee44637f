"""Shared pieces of the comparison harness: the default engine (docs/physics.md section 8), the
`nsection` topology as plain arrays, the fairness state and the tolerance scales.

Everything here mirrors `examples/bench_native.rs` / the generated Rust model; `compare.py`
feeds the parameters printed by the Rust binary in, so all three implementations run on the
very same numbers.
"""
import math
import time

import numpy as np

DEFAULT_PARAMS = {
    "R": 287.05, "gamma": 1.4, "A": math.pi / 4 * 0.06 ** 2, "Ar": math.pi / 4 * 0.015 ** 2,
    "Vh0": 1.5e-4, "Vc0": 1.2e-4, "Vr": 4.0e-5, "Th": 600.0, "Tk": 300.0,
    "Pmean": 101325.0, "Pb": 101325.0,
    "md": 0.08228, "mp": 0.33363, "kd": 650.74, "kp": 61.482, "bd": 0.48643, "bp": 7.9083,
    "b": 0.1, "bqd": 0.5, "bqp": 5.0,
    "Awh0": 0.0128, "Awc0": 0.0112, "Awr": 0.0377, "hh": 500.0, "hk": 500.0, "hr": 100.0,
    "Rf": 1.0e5, "mdot_eps": 1.0e-5,
}


class Topology:
    """`nsection n`, `full` closure: CVs hot, regen[0..n], cold; links i -> i+1.

    State layout `[x, v, y, w, P_0..P_{ncv-1}, m_0..m_{ncv-1}]`, ncv = n + 2.
    Volumes `V = V0 + ax x + ay y`; one heat port per CV with area `Aw0 + dAx x + dAy y`.
    """

    def __init__(self, n, params=None):
        p = dict(DEFAULT_PARAMS)
        if params:
            p.update({k: float(v) for k, v in params.items() if k in p})
        self.p = p
        self.n = n
        self.ncv = ncv = n + 2
        self.nx = 4 + 2 * ncv
        A, Ar = p["A"], p["Ar"]
        self.D = math.sqrt(4 * A / math.pi)
        piD = math.pi * self.D
        self.cp = p["gamma"] * p["R"] / (p["gamma"] - 1)
        self.V0 = np.array([p["Vh0"]] + [p["Vr"] / n] * n + [p["Vc0"]])
        self.ax = np.zeros(ncv); self.ax[0] = -A; self.ax[-1] = A - Ar
        self.ay = np.zeros(ncv); self.ay[-1] = -(A - Ar)
        j = np.arange(n)
        self.Tw = np.concatenate([[p["Th"]], p["Th"] - (j + 0.5) * (p["Th"] - p["Tk"]) / n, [p["Tk"]]])
        self.h = np.concatenate([[p["hh"]], np.full(n, p["hr"]), [p["hk"]]])
        self.Aw0 = np.concatenate([[p["Awh0"]], np.full(n, p["Awr"] / n), [p["Awc0"]]])
        self.dAx = np.zeros(ncv); self.dAx[0] = -piD; self.dAx[-1] = piD
        self.dAy = np.zeros(ncv); self.dAy[-1] = -piD
        self.Rl = np.concatenate([[p["Rf"] / (2 * n)], np.full(n - 1, p["Rf"] / n), [p["Rf"] / (2 * n)]])
        # bounce-space forces
        self.Fx0 = Ar * p["Pb"]
        self.Fy0 = (A - Ar) * p["Pb"]

    # ---------------------------------------------------------------- states
    def equilibrium(self):
        p = self.p
        z = np.zeros(self.nx)
        z[4:4 + self.ncv] = p["Pmean"]
        z[4 + self.ncv:] = p["Pmean"] * self.V0 / (p["R"] * self.Tw)  # one port per CV: T0 = Tw
        return z

    def fairness_state(self):
        """Same recipe as `examples/bench_native.rs`."""
        z = self.equilibrium()
        z[0], z[1], z[2], z[3] = 3e-3, 0.2, -2e-3, -0.1
        for i in range(4, 4 + self.ncv):
            z[i] *= 1.0 + 1e-3 * (i % 7)
        return z

    def sim_start(self):
        z = self.equilibrium()
        z[0] += 5e-3
        return z

    def scale(self):
        """Typical magnitudes (as `stirling_models::sim::state_scale`): atol_i = atol * scale_i."""
        s = np.abs(self.equilibrium())
        s[0] = s[2] = 1e-2
        s[1] = s[3] = 1.0
        return s


def median_time(fn, min_batch_s=2e-3, reps=21, budget_s=3.0):
    """Median seconds per call of `fn()`, timed in batches long enough for the clock."""
    t0 = time.perf_counter(); fn(); one = max(time.perf_counter() - t0, 1e-9)
    k = max(1, int(math.ceil(min_batch_s / one)))
    reps = max(1, min(reps, int(budget_s / (one * k))))
    v = []
    for _ in range(reps):
        t = time.perf_counter()
        for _ in range(k):
            fn()
        v.append((time.perf_counter() - t) / k)
    return float(np.median(v))
