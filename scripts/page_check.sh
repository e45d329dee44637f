#!/usr/bin/env bash
# Load the page of `stirling serve` in headless Chromium: check the poles it shows equal
# `stirling linearize`'s (to the digits printed), that a parameter change moves them as
# `--set` does, and take screenshots to review (target/page_check/*.png).
# Installs nothing: without chromium it says so and exits 0 (CI has none).
#   scripts/page_check.sh            # uses target/release/stirling (built if missing)
set -euo pipefail
cd "$(dirname "$0")/.."
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
    echo "page_check: no chromium on this machine (apt-get install chromium); skipped"
    exit 0
fi
TARGET=${CARGO_TARGET_DIR:-target}
cargo build --release -q -p stirling-cli
BIN="$TARGET/release/stirling"
OUT="$TARGET/page_check"
mkdir -p "$OUT"
"$BIN" serve --port 0 2> "$OUT/serve.err" &
PID=$!
trap 'kill $PID 2>/dev/null || true' EXIT
for _ in $(seq 50); do grep -q http "$OUT/serve.err" 2>/dev/null && break; sleep 0.1; done
ADDR=$(grep -o 'http://[0-9.:]*' "$OUT/serve.err")
# the page reads its sliders from the URL fragment: #Th=700 sets Th before the first update
check() { # $1: fragment, $2: --set args for the CLI, $3: screenshot name
    local dom="$OUT/$3.html"
    "$CHROMIUM" --headless --no-sandbox --disable-gpu --virtual-time-budget=15000 \
        --dump-dom "$ADDR/#$1" > "$dom" 2>/dev/null
    "$CHROMIUM" --headless --no-sandbox --disable-gpu --virtual-time-budget=15000 \
        --window-size=1400,1300 --screenshot="$OUT/$3.png" "$ADDR/#$1" > /dev/null 2>&1
    # the poles as the page prints them, and as the command line prints them
    sed -n '/<pre id="poletext">/,/<\/pre>/p' "$dom" | grep -Eo -- '-?[0-9]+\.[0-9]{6} [+-][0-9]+\.[0-9]{6}j' > "$OUT/$3.page"
    # shellcheck disable=SC2086
    "$BIN" linearize cv2 $2 | sed -n '/^closed-loop poles/,/^loop broken/p' \
        | awk '/rad\/s/ {print $1, $2}' > "$OUT/$3.cli"
    if [ -s "$OUT/$3.page" ] && diff -q "$OUT/$3.page" "$OUT/$3.cli" > /dev/null; then
        echo "page_check: $3: $(wc -l < "$OUT/$3.page") poles equal the CLI's; screenshot $OUT/$3.png"
    else
        echo "page_check: $3: the page's poles differ from the CLI's:"; diff "$OUT/$3.page" "$OUT/$3.cli" || true
        exit 1
    fi
}
check "model=cv2" "" default
check "model=cv2&Th=700" "--set Th=700" th700
if diff -q "$OUT/default.page" "$OUT/th700.page" > /dev/null; then
    echo "page_check: moving Th did not move the poles"; exit 1
fi
echo "page_check: Th 600 -> 700 moved the poles as \`stirling linearize --set Th=700\` does"
