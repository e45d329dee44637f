"""`nsection` (full closure) in NumPy: vectorized RHS and a hand-written analytic Jacobian,
integrated with `scipy.integrate.solve_ivp(method='BDF', jac=...)`.

This is what a careful SciPy user would write: no Python loops over control volumes, the
Jacobian assembled from its tridiagonal pieces, dense for small systems and `scipy.sparse`
(CSC, so BDF factorizes it with SuperLU) from `SPARSE_FROM` states on.

Run alone: `python scipy_model.py --n 10` prints timings as JSON.
"""
import argparse
import json
import time

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp

from common import Topology, median_time

SPARSE_FROM = 60  # states; below this a dense Jacobian is faster in solve_ivp


class NumpyModel:
    def __init__(self, topo: Topology):
        self.t = topo
        p = topo.p
        self.g = p["gamma"]
        self.k = p["gamma"] - 1
        self.R = p["R"]
        self.eps = p["mdot_eps"]
        ncv = topo.ncv
        self.iP = 4 + np.arange(ncv)
        self.im = 4 + ncv + np.arange(ncv)
        self._build_pattern()

    # ------------------------------------------------------------------ RHS
    def _parts(self, z):
        t = self.t
        ncv = t.ncv
        x, v, y, w = z[0], z[1], z[2], z[3]
        P = z[4:4 + ncv]
        m = z[4 + ncv:]
        V = t.V0 + t.ax * x + t.ay * y
        Vd = t.ax * v + t.ay * w
        T = P * V / (m * self.R)
        Aw = t.Aw0 + t.dAx * x + t.dAy * y
        Q = t.h * Aw * (t.Tw - T)
        mdot = (P[:-1] - P[1:]) / t.Rl
        th = np.tanh(mdot / self.eps)
        s = 0.5 * (1 + th)
        Tup = s * T[:-1] + (1 - s) * T[1:]
        H = t.cp * mdot * Tup
        return x, v, y, w, P, m, V, Vd, T, Aw, Q, mdot, th, s, Tup, H

    def rhs(self, z):
        t, p = self.t, self.t.p
        x, v, y, w, P, m, V, Vd, T, Aw, Q, mdot, th, s, Tup, H = self._parts(z)
        Hn = np.zeros(t.ncv)
        Hn[:-1] -= H
        Hn[1:] += H
        Mn = np.zeros(t.ncv)
        Mn[:-1] -= mdot
        Mn[1:] += mdot
        Pd = (self.k * (Q + Hn) - self.g * P * Vd) / V
        Fx = t.Fx0 + t.ax @ P
        Fy = t.Fy0 + t.ay @ P
        vd = (Fx - p["kd"] * x - p["bd"] * v - p["b"] * (v - w) - p["bqd"] * v * abs(v)) / p["md"]
        wd = (Fy - p["kp"] * y - p["bp"] * w - p["b"] * (w - v) - p["bqp"] * w * abs(w)) / p["mp"]
        out = np.empty(t.nx)
        out[0], out[1], out[2], out[3] = v, vd, w, wd
        out[4:4 + t.ncv] = Pd
        out[4 + t.ncv:] = Mn
        return out

    # ------------------------------------------------------------- Jacobian
    def _build_pattern(self):
        """Fixed (row, col) list of every nonzero; `jac_values` fills the values in this order."""
        t = self.t
        ncv = t.ncv
        iP, im = self.iP, self.im
        i = np.arange(ncv)
        lo, up = np.arange(1, ncv), np.arange(ncv - 1)  # rows with a left / right neighbour
        rows, cols = [], []

        def add(r, c):
            rows.append(np.atleast_1d(r)); cols.append(np.atleast_1d(c))
        add(0, 1); add(2, 3)
        add([1, 1, 1], [0, 1, 3]); add([3, 3, 3], [1, 2, 3])
        add(np.ones(ncv, int), iP); add(np.full(ncv, 3), iP)
        # pressure rows: P (tridiagonal), m (tridiagonal), x, y, v, w
        add(iP[i], iP[i]); add(iP[lo], iP[lo - 1]); add(iP[up], iP[up + 1])
        add(iP[i], im[i]); add(iP[lo], im[lo - 1]); add(iP[up], im[up + 1])
        add(iP, np.zeros(ncv, int)); add(iP, np.full(ncv, 2)); add(iP, np.ones(ncv, int)); add(iP, np.full(ncv, 3))
        # mass rows: P tridiagonal
        add(im[i], iP[i]); add(im[lo], iP[lo - 1]); add(im[up], iP[up + 1])
        self.rows = np.concatenate(rows)
        self.cols = np.concatenate(cols)

    def jac_values(self, z):
        t, p = self.t, self.t.p
        g, k, cp = self.g, self.k, t.cp
        x, v, y, w, P, m, V, Vd, T, Aw, Q, mdot, th, s, Tup, H = self._parts(z)
        Hn = np.zeros(t.ncv); Hn[:-1] -= H; Hn[1:] += H
        N = k * (Q + Hn) - g * P * Vd
        # link derivatives: dH_l/dmdot_l, dH_l/dT_l (upstream side), dH_l/dT_{l+1}
        ds = 0.5 * (1 - th * th) / self.eps
        c = cp * (Tup + mdot * ds * (T[:-1] - T[1:]))
        hA = cp * mdot * s
        hB = cp * mdot * (1 - s)
        # dE_i/dT_j with E = Q + Hnet (diag, lower j=i-1, upper j=i+1)
        dT_d = -t.h * Aw
        dT_d[1:] += hB
        dT_d[:-1] -= hA
        dT_l = hA            # row i = l+1, col l
        dT_u = -hB           # row i = l,   col l+1
        # dE_i/dP_j directly through the link flows
        cR = c / t.Rl
        dP_d = np.zeros(t.ncv)
        dP_d[1:] -= cR
        dP_d[:-1] -= cR
        dP_l = cR
        dP_u = cR
        # chain through T = P V / (m R): dT/dP = T/P, dT/dm = -T/m, dT/dx = T ax / V, dT/dy = T ay / V
        TP, Tm, Tx, Ty = T / P, -T / m, T * t.ax / V, T * t.ay / V
        kV = k / V
        jPP_d = kV * (dP_d + dT_d * TP) - g * Vd / V
        jPP_l = kV[1:] * (dP_l + dT_l * TP[:-1])
        jPP_u = kV[:-1] * (dP_u + dT_u * TP[1:])
        jPm_d = kV * dT_d * Tm
        jPm_l = kV[1:] * dT_l * Tm[:-1]
        jPm_u = kV[:-1] * dT_u * Tm[1:]
        dEx = t.h * t.dAx * (t.Tw - T) + dT_d * Tx
        dEx[1:] += dT_l * Tx[:-1]
        dEx[:-1] += dT_u * Tx[1:]
        dEy = t.h * t.dAy * (t.Tw - T) + dT_d * Ty
        dEy[1:] += dT_l * Ty[:-1]
        dEy[:-1] += dT_u * Ty[1:]
        jPx = kV * dEx - N * t.ax / (V * V)
        jPy = kV * dEy - N * t.ay / (V * V)
        jPv = -g * P * t.ax / V
        jPw = -g * P * t.ay / V
        iR = 1.0 / t.Rl
        jmP_d = np.zeros(t.ncv); jmP_d[1:] -= iR; jmP_d[:-1] -= iR
        md, mp, b = p["md"], p["mp"], p["b"]
        mech = [
            [1.0], [1.0],
            [-p["kd"] / md, (-p["bd"] - b - 2 * p["bqd"] * abs(v)) / md, b / md],
            [b / mp, -p["kp"] / mp, (-p["bp"] - b - 2 * p["bqp"] * abs(w)) / mp],
            t.ax / md, t.ay / mp,
        ]
        return np.concatenate(mech + [jPP_d, jPP_l, jPP_u, jPm_d, jPm_l, jPm_u, jPx, jPy, jPv, jPw,
                                      jmP_d, iR, iR])

    def jac_sparse(self, z):
        n = self.t.nx
        return sp.csc_matrix((self.jac_values(z), (self.rows, self.cols)), shape=(n, n))

    def jac_dense(self, z):
        n = self.t.nx
        J = np.zeros((n, n))
        np.add.at(J, (self.rows, self.cols), self.jac_values(z))
        return J

    def jac_dense_fast(self, z):
        """Dense Jacobian without `np.add.at` (the pattern has no duplicate entries)."""
        n = self.t.nx
        J = np.zeros((n, n))
        J[self.rows, self.cols] = self.jac_values(z)
        return J

    def jac(self, z):
        return self.jac_sparse(z) if self.t.nx >= SPARSE_FROM else self.jac_dense_fast(z)

    def jac_triplets(self, z):
        return self.rows, self.cols, self.jac_values(z)


def simulate(model: NumpyModel, t_end=1.0, rtol=1e-7, atol=1e-7):
    topo = model.t
    z0 = topo.sim_start()
    atol_v = atol * topo.scale()
    t0 = time.perf_counter()
    sol = solve_ivp(lambda t, z: model.rhs(z), (0.0, t_end), z0, method="BDF", jac=lambda t, z: model.jac(z),
                    rtol=rtol, atol=atol_v, t_eval=[t_end])
    el = time.perf_counter() - t0
    return {
        "ok": bool(sol.success), "message": sol.message, "seconds": el, "t_end": t_end,
        "steps": int(len(sol.t)) if False else None,
        "rhs_calls": int(sol.nfev), "jacobian_calls": int(sol.njev), "lu_factorizations": int(sol.nlu),
        "x_end": sol.y[:, -1].tolist(), "jac_kind": "sparse (SuperLU)" if topo.nx >= SPARSE_FROM else "dense (LAPACK)",
    }


def run(n, params=None, do_sim=True, t_end=1.0, rtol=1e-7, atol=1e-7, sim_max_s=None):
    topo = Topology(n, params)
    m = NumpyModel(topo)
    z = topo.fairness_state()
    r, c, vals = m.jac_triplets(z)
    out = {
        "n": n, "n_states": topo.nx,
        "x": z.tolist(), "f": m.rhs(z).tolist(), "jac": [[int(a), int(b), float(v)] for a, b, v in zip(r, c, vals)],
        "timings": {
            "rhs": median_time(lambda: m.rhs(z)),
            "jac": median_time(lambda: m.jac(z)),
            "jac_values": median_time(lambda: m.jac_values(z)),
        },
    }
    if do_sim:
        out["sim"] = simulate(m, t_end, rtol, atol)
    return out


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=10)
    ap.add_argument("--no-sim", action="store_true")
    ap.add_argument("--t-end", type=float, default=1.0)
    a = ap.parse_args()
    res = run(a.n, do_sim=not a.no_sim, t_end=a.t_end)
    res.pop("jac"); res.pop("x"); res.pop("f")
    if "sim" in res:
        res["sim"].pop("x_end")
    print(json.dumps(res, indent=1))
