"""Margins of the broken loop exported by `stirling linearize MODEL --ss FILE`, by python-control.

Usage: python margins.py FILE
Prints one JSON line: {"gm_db", "w_pc", "pm_deg", "w_gc", "control"}.
control.margin assumes negative unity feedback, as the export does (closed = A - B C), and reads
the margins as MATLAB's margin does; the gain margin is a factor, so its dB value is 20 log10(gm).
"""
import json
import math
import sys

import control

with open(sys.argv[1]) as f:
    e = json.load(f)["broken_loop"]
L = control.ss(e["a"], e["b"], e["c"], e["d"])
gm, pm, w_pc, w_gc = control.margin(L)
print(json.dumps({
    "gm_db": 20.0 * math.log10(gm),
    "w_pc": float(w_pc),
    "pm_deg": float(pm),
    "w_gc": float(w_gc),
    "control": control.__version__,
}))
