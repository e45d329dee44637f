#!/usr/bin/env bash
# Side-by-side benchmark: ours (Rust) vs CasADi (generated C + CVODES) vs SciPy (BDF).
# Usage: bench/run.sh [--ns 2,10,100,1000] [other compare.py options]
# Env: BENCH_NATIVE=/path/to/bench_native  use a prebuilt binary instead of building one.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
venv="$here/.venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt"
if [ -z "${BENCH_NATIVE:-}" ]; then
    (cd "$root" && cargo build --release --example bench_native)
    BENCH_NATIVE="$root/target/release/examples/bench_native"
fi
cd "$here"
exec "$venv/bin/python" compare.py --native "$BENCH_NATIVE" "$@"
