#!/usr/bin/env bash
# Side-by-side benchmark: ours (Rust) vs CasADi (generated C + CVODES) vs SciPy (BDF).
# Usage: bench/run.sh [--ns 2,10,100,1000] [other compare.py options]
# Env: BENCH_NATIVE=/path/to/bench_native  use a prebuilt binary instead of building one (e.g.
#      target/release/examples/bench_native, the portable build, without -C target-cpu=native).
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
venv="$here/.venv"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt"
if [ -z "${BENCH_NATIVE:-}" ]; then
    # built for this processor, as CasADi's C is (gcc -O3 -march=native), in a target
    # directory of its own so that the portable build in target/release stays as it is
    (cd "$root" && RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$root/target/native" \
        cargo build --release --example bench_native)
    BENCH_NATIVE="$root/target/native/release/examples/bench_native"
fi
cd "$here"
exec "$venv/bin/python" compare.py --native "$BENCH_NATIVE" "$@"
