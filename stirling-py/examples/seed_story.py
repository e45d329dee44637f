"""The seed's story in Python, cell by cell (run it as a script, or paste the cells into
Jupyter): the 8th-order model, its poles and the Bode diagram of its broken loop with the
margins, the limit cycle's p-V loops, a record from the virtual rig, the two-stage fit and a
diagnosis of what the nominal model leaves out.

    python stirling-py/examples/seed_story.py --out figures/

Figures go to --out (PNG, matplotlib's Agg backend; existing figures are kept unless --force).
Needs the module (pip install ./stirling-py) and matplotlib.
"""

# %% set-up
import argparse
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import stirling  # noqa: E402

FIGURES = ["poles.png", "bode.png", "pv.png", "record.png", "fit.png"]

args = argparse.ArgumentParser(description=__doc__.splitlines()[0])
args.add_argument("--out", type=Path, default=Path("seed_story"), help="folder of the figures")
args.add_argument("--force", action="store_true", help="overwrite existing figures")
opts = args.parse_args()
opts.out.mkdir(parents=True, exist_ok=True)
taken = [f for f in FIGURES if (opts.out / f).exists()]
if taken and not opts.force:
    sys.exit(f"{opts.out}: {', '.join(taken)} exist; pass --force to overwrite")
clock = time.perf_counter()


def save(fig, name):
    path = opts.out / name
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {path}")


# %% the 8th-order model: nsection with 2 regenerator sections (12 states with the mass
# states of the full closure; closure="frozen" gives the seed's 8)
model = stirling.load("order8")
print(model)
for s in model.states:
    print(f"  {s.name:>10} [{s.unit}] {s.meaning}")

# %% its poles at rest: the engine is unstable, a pair in the right half plane near 85 rad/s
lin = model.linearize()
print(lin)
for p in lin.pole_table[:4]:
    print(" ", p)

fig, ax = plt.subplots(figsize=(5, 4))
ax.scatter(lin.poles.real, lin.poles.imag, marker="x", label="closed loop (the engine)")
ax.scatter(lin.open_loop_poles.real, lin.open_loop_poles.imag, marker="o", facecolors="none", edgecolors="C1", label=f"loop broken at the {lin.channel}")
ax.axvline(0.0, color="0.6", lw=0.8)
ax.set_xlabel("Re s (1/s)")
ax.set_ylabel("Im s (rad/s)")
ax.set_xscale("symlog", linthresh=10.0)
ax.set_title("poles of order8")
ax.legend(fontsize=8)
save(fig, "poles.png")

# %% Bode diagram of the broken loop with its margins
b, m = lin.bode, lin.margins
print(m)
fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(6, 5))
top.semilogx(b.w, b.magnitude_db)
top.axhline(0.0, color="0.6", lw=0.8)
bottom.semilogx(b.w, b.phase_deg)
bottom.axhline(-180.0, color="0.6", lw=0.8)
band = (b.w >= 1.0) & (b.w <= 1e4)  # the decades around the crossovers
top.set_xlim(1.0, 1e4)
top.set_ylim(b.magnitude_db[band].min() - 5, b.magnitude_db[band].max() + 5)
bottom.set_ylim(b.phase_deg[band].min() - 20, b.phase_deg[band].max() + 20)
if m.phase_crossover_rad_s is not None:
    w = m.phase_crossover_rad_s
    top.plot([w, w], [0.0, -m.gain_db], color="C3", lw=2, label=f"Gm {m.gain_db:.2f} dB at {w:.1f} rad/s")
if m.gain_crossover_rad_s is not None:
    w = m.gain_crossover_rad_s
    ph = np.interp(np.log(w), np.log(b.w), b.phase_deg)
    bottom.plot([w, w], [ph - m.phase_deg, ph], color="C2", lw=2, label=f"Pm {m.phase_deg:.1f} deg at {w:.1f} rad/s")
top.set_ylabel("|L| (dB)")
bottom.set_ylabel("phase (deg)")
bottom.set_xlabel("w (rad/s)")
top.set_title(f"order8: loop broken at the {lin.channel} force")
top.legend(fontsize=8)
bottom.legend(fontsize=8)
save(fig, "bode.png")

# python-control reads the same loop
try:
    import control

    gm, pm, wpc, wgc = control.margin(lin.broken_loop.to_control())
    print(f"python-control: Gm {20 * np.log10(gm):.2f} dB at {wpc:.1f} rad/s, Pm {pm:.1f} deg at {wgc:.1f} rad/s")
except ImportError:
    print("python-control is not installed: pip install control")

# %% the limit cycle: frequency, strokes, work and power; the p-V loop of every vessel
lc = model.limit_cycle(t_max=20.0)
print(lc)
print("  Floquet multipliers:", np.round(lc.floquet[:4], 5))
fig, ax = plt.subplots(figsize=(6, 4.5))
for name, (v, p) in lc.pv.items():
    if np.ptp(v) > 0 and np.ptp(p) > 0:  # a given-pressure space draws no loop
        ax.plot(1e6 * v, 1e-3 * p, label=f"{name}: {lc.work_per_vessel[name]:+.4f} J")
ax.set_xlabel("V (cm^3)")
ax.set_ylabel("p (kPa)")
ax.set_title(f"p-V loops, {lc.frequency_hz:.2f} Hz, {lc.work:.4f} J per cycle, {lc.power:.2f} W")
ax.legend(fontsize=8)
save(fig, "pv.png")

# %% a record from the virtual rig: the truth has a 2 ms lag on the pressure transducer,
# which the nominal model does not know; noise on every channel
rec = model.rig(settle=3.0, t_end=1.5, effects={"sensor_lag": 0.002}, seed=11)
print(rec)
try:  # the record as a DataFrame, when pandas is installed
    print(rec.to_pandas().describe().loc[["mean", "std"]])
except ImportError:
    pass
fig, axes = plt.subplots(3, 1, sharex=True, figsize=(7, 5))
for ax, (c, scale, unit) in zip(axes, [("p", 1e-3, "kPa"), ("x", 1e3, "mm"), ("y", 1e3, "mm")]):
    ax.plot(rec.t, scale * rec[c], lw=0.6)
    ax.set_ylabel(f"{c} ({unit})")
axes[-1].set_xlabel("t (s)")
axes[0].set_title("rig record (truth: nsection with a 2 ms pressure-sensor lag)")
save(fig, "record.png")

# %% the two-stage fit: mechanics driven by the measured pressure, then the gas driven by
# the measured positions; estimates with 95 % intervals
fit = model.fit(rec)
print(fit)
for name, e in fit.estimates.items():
    if e.raw["model_param"]:
        print(f"  {name:>6} = {e.value:12.5g}  95 % [{e.raw['ci_low']:.5g}, {e.raw['ci_high']:.5g}]")
series = fit.series["stage1"][:1] + fit.series["stage2"][:1]
fig, axes = plt.subplots(len(series), 1, figsize=(7, 2.4 * len(series)))
for ax, (stage, s) in zip(np.atleast_1d(axes), zip(["stage 1", "stage 2"], series)):
    k = slice(0, min(len(s.t), 400))
    ax.plot(s.t[k], s.measured[k], lw=0.8, label="measured")
    ax.plot(s.t[k], s.model[k], lw=0.8, label="model")
    ax.set_ylabel(f"{s.channel} ({'Pa' if s.channel.startswith('p') else 'm'})")
    ax.set_title(f"{stage}: {s.channel} measured vs model", fontsize=9)
    ax.legend(fontsize=7)
np.atleast_1d(axes)[-1].set_xlabel("t (s)")
fig.tight_layout()
save(fig, "fit.png")

# %% the diagnosis: which omitted effect explains the gap, and how far it closes it
diag = model.diagnose(rec)
print(diag.verdict)
for r in diag.ranking[:4]:
    print(" ", r)
assert diag.effect == "sensor_lag", diag.verdict
print(f"done in {time.perf_counter() - clock:.1f} s")
