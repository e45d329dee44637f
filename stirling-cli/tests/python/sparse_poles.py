"""The sparse export of a large model read back with SciPy and python-control.

Usage: python sparse_poles.py SS_FILE REPORT_FILE
SS_FILE is what `stirling linearize MODEL --ss SS_FILE` wrote, REPORT_FILE what `--json` printed.
Builds A, B, C, D of the broken and the closed loop from their triplets (scipy.sparse.coo_matrix),
then per loop: each pole the report prints against the eigenvalue of A nearest to it by
shift-invert Arnoldi (scipy.sparse.linalg.eigs, sigma = the pole), the closed loop against A - B C, the dense
fields against the triplets, and control.ss built from the matrices: its poles (dense eig of A)
against the report's, the count of them at least as far right as the report's leftmost (the
report's poles are the rightmost), L(jw) against the file's Bode data.
Prints one JSON object of the measured errors and counts.
"""
import json
import sys

import control
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla


def coo(t):
    assert t["format"].startswith("triplets, 0-based"), t["format"]
    return sp.coo_matrix((t["v"], (t["i"], t["j"])), shape=(t["rows"], t["cols"]))


def matrices(s):
    return tuple(coo(s[k + "_sparse"]).tocsc() for k in "abcd")


def nearest_rel(a, poles):
    """Largest |lambda - p| / |p| over the poles, lambda the eigenvalue of a nearest p."""
    ac = a.astype(complex)
    worst = 0.0
    for p in poles:
        lam = spla.eigs(ac, k=1, sigma=p, return_eigenvectors=False)[0]
        worst = max(worst, abs(lam - p) / abs(p))
    return worst


def rightmost_count(eig, poles):
    """Dense eigenvalues at least as far right as the leftmost pole (with a margin)."""
    edge = min(p.real for p in poles)
    return int(np.sum(eig.real >= edge - 1e-6 * max(abs(p) for p in poles)))


def loop(s, reported):
    a, b, c, d = matrices(s)
    poles = [complex(p["re"], p["im"]) for p in reported]
    dense = np.asarray(s["a"]) if s["a"] is not None else None
    sys_ = control.ss(a.toarray(), b.toarray(), c.toarray(), d.toarray())
    ctl = np.asarray(sys_.poles())  # dense eig of A: every pole
    return {
        "states": a.shape[0],
        "shapes": [list(m.shape) for m in (a, b, c, d)],
        "poles": len(poles),
        "shift_invert_rel": nearest_rel(a, poles),
        "rightmost_count": rightmost_count(ctl, poles),
        "control_rel": max(float(np.min(abs(ctl - p)) / abs(p)) for p in poles),
        "dense_vs_sparse": float(abs(dense - a.toarray()).max()) if dense is not None else None,
    }, (a, b, c, sys_)


def main():
    with open(sys.argv[1]) as f:
        e = json.load(f)
    with open(sys.argv[2]) as f:
        r = json.load(f)
    out = {}
    out["broken"], (a0, b, c, sys_) = loop(e["broken_loop"], r["loop"]["open_loop_poles"])
    out["closed"], (a, _, _, _) = loop(e["closed_loop"], r["poles"])
    out["closed_minus_a0_bc"] = float(abs(a - (a0 - b @ c)).max()) / float(abs(a).max())
    bode = e["bode"]
    k = len(bode["w_rad_s"]) // 2
    w = bode["w_rad_s"][k]
    l_w = complex(np.squeeze(sys_(1j * w)))
    out["bode_rel"] = abs(abs(l_w) - bode["magnitude"][k]) / bode["magnitude"][k]
    out["control"] = control.__version__
    print(json.dumps(out))


main()
