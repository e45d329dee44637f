"""What a Python call costs around the Rust work: one RHS + Jacobian evaluation and one
simulated second of `nsection`, from Python (`import stirling`) against the same work timed in
Rust in one run of `examples/bench_native.rs` (same model, same state, same tolerances).

Run (after `pip install ./stirling-py`):

    cargo build --release --example bench_native
    python stirling-py/bench/overhead.py --ns 2,10,100 [--native target/release/examples/bench_native]

The Rust side's `rhs + jac_dense` is the same work as `Model.rhs_and_jacobian` (the Python call
returns the Jacobian as a dense numpy array); its simulated second starts from the same state
(`x0_sim`) with the same BDF and tolerances (rtol = atol = 1e-7). Times are medians.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import stirling


def median_call(fn, min_total=0.3, max_reps=200000):
    """Median time of one call of `fn`, timed in batches large enough for the clock."""
    fn()
    batch, t = 1, 0.0
    while t < 1e-3 and batch < max_reps:
        start = time.perf_counter()
        for _ in range(batch):
            fn()
        t = time.perf_counter() - start
        if t < 1e-3:
            batch *= 4
    times = []
    started = time.perf_counter()
    while len(times) < 5 or (time.perf_counter() - started < min_total and len(times) < 50):
        start = time.perf_counter()
        for _ in range(batch):
            fn()
        times.append((time.perf_counter() - start) / batch)
    return statistics.median(times)


def rust_side(native, n):
    out = subprocess.run([native, "--n", str(n), "--json", "--no-poles"], check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def python_side(doc, n):
    m = stirling.load("nsection", n=n)
    for k, v in doc["params"].items():
        if m.params[k] != v:
            raise SystemExit(f"parameter {k} differs: Rust {v}, Python {m.params[k]}")
    x = np.asarray(doc["x"])
    f, _ = m.rhs_and_jacobian(x)
    if not np.allclose(f, doc["f"], rtol=1e-12, atol=0):
        raise SystemExit("the Python RHS differs from the Rust RHS at the same state")
    t_call = median_call(lambda: m.rhs_and_jacobian(x))
    x0 = np.asarray(doc["x0_sim"])
    t_sim = []
    for _ in range(3):
        start = time.perf_counter()
        m.simulate(1.0, x0=x0, samples=2)
        t_sim.append(time.perf_counter() - start)
    return t_call, statistics.median(t_sim)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--ns", default="2,10,100", help="regenerator section counts (comma-separated)")
    ap.add_argument("--native", default=os.path.join("target", "release", "examples", "bench_native"),
                    help="the bench_native binary (cargo build --release --example bench_native)")
    ap.add_argument("--json", help="also write the table to this JSON file")
    a = ap.parse_args()
    if not os.path.exists(a.native):
        raise SystemExit(f"{a.native} not found: build it with `cargo build --release --example bench_native`")
    rows = []
    print(f"{'n':>5} {'rust rhs+jac':>13} {'python':>10} {'overhead':>10} {'ratio':>6}"
          f" | {'rust 1 s sim':>12} {'python':>9} {'ratio':>6}")
    for n in [int(s) for s in a.ns.split(",")]:
        doc = rust_side(a.native, n)
        t = doc["timings"]
        rust_call = t["rhs"] + t["jac_dense"]
        rust_sim = doc["sim"]["seconds"]
        py_call, py_sim = python_side(doc, n)
        rows.append({"n": n, "rust_rhs_jac_s": rust_call, "python_rhs_jac_s": py_call,
                     "rust_sim_s": rust_sim, "python_sim_s": py_sim})
        print(f"{n:>5} {rust_call * 1e6:>10.2f} us {py_call * 1e6:>7.2f} us {(py_call - rust_call) * 1e6:>7.2f} us"
              f" {py_call / rust_call:>6.2f} | {rust_sim:>10.3f} s {py_sim:>7.3f} s {py_sim / rust_sim:>6.2f}")
        sys.stdout.flush()
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(rows, fh, indent=1)


if __name__ == "__main__":
    main()
