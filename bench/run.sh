#!/usr/bin/env bash
# Side-by-side benchmarks, in one run:
#  1. ours (Rust) vs CasADi (generated C + CVODES) vs SciPy (BDF): compare.py;
#  2. engines from files (issue 35): the load and compile time of nsection.stirling, the JIT's
#     RHS + Jacobian against the macro's at n = 2, 10, 100, 1000, and the JIT with the
#     parameters folded in against CasADi's literal-parameter C and its parameter-input C at
#     n = 2, 10, 100: files_compare.py.
# Usage: bench/run.sh [--files-only | --no-files] [--ns 2,10,100,1000] [other compare.py options]
# Env: BENCH_NATIVE=/path/to/bench_native  use a prebuilt binary instead of building one (e.g.
#      target/release/examples/bench_native, the portable build, without -C target-cpu=native);
#      BENCH_FILES_SPEED=/path/to/files_speed  likewise for the files benchmark.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$here")"
venv="$here/.venv"
compare=1
files=1
args=()
for a in "$@"; do
    case "$a" in
        --files-only) compare=0 ;;
        --no-files) files=0 ;;
        *) args+=("$a") ;;
    esac
done
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q --disable-pip-version-check -r "$here/requirements.txt"
# built for this processor, as CasADi's C is (gcc -O3 -march=native), in a target directory of
# its own so that the portable build in target/release stays as it is
native_dir="$root/target/native/release/examples"
build() {
    (cd "$root" && RUSTFLAGS="-C target-cpu=native" CARGO_TARGET_DIR="$root/target/native" \
        cargo build --release --example "$1")
}
if [ "$compare" = 1 ] && [ -z "${BENCH_NATIVE:-}" ]; then
    build bench_native
    BENCH_NATIVE="$native_dir/bench_native"
fi
if [ "$files" = 1 ] && [ -z "${BENCH_FILES_SPEED:-}" ]; then
    build files_speed
    BENCH_FILES_SPEED="$native_dir/files_speed"
fi
cd "$here"
if [ "$compare" = 1 ]; then
    "$venv/bin/python" compare.py --native "$BENCH_NATIVE" ${args[@]+"${args[@]}"}
fi
if [ "$files" = 1 ]; then
    "$venv/bin/python" files_compare.py --speed "$BENCH_FILES_SPEED"
fi
