#!/usr/bin/env bash
# Load the page of `stirling serve` in headless Chromium and check what it shows against the
# command line:
#   1. the poles of `cv2` equal `stirling linearize cv2`'s (to the 6 decimals printed);
#   2. a parameter change (Th 600 -> 700) moves them as `--set Th=700` does;
#   3. an engine declaration edited in the page (a default replaced and a load damper added
#      to cv2's declaration, compiled by the page) shows the poles of `stirling linearize`
#      on the same text saved as a file;
#   4. an edit with a mistake shows its line:column and the page keeps the last good model;
# and takes screenshots to review (target/page_check/*.png).
# Installs nothing: without chromium it says so and exits 0 (apt-get install chromium).
#   scripts/page_check.sh            # uses $CARGO_TARGET_DIR/release/stirling (built if needed)
#   STIRLING=path/to/stirling scripts/page_check.sh    # that binary, nothing built
set -euo pipefail
cd "$(dirname "$0")/.."
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
    echo "page_check: no chromium on this machine (apt-get install chromium); skipped"
    exit 0
fi
TARGET=${CARGO_TARGET_DIR:-target}
if [ -n "${STIRLING:-}" ]; then
    BIN=$STIRLING
else
    cargo build --release -q -p stirling-cli
    BIN="$TARGET/release/stirling"
fi
OUT="$TARGET/page_check"
mkdir -p "$OUT"
"$BIN" serve --port 0 2> "$OUT/serve.err" &
PID=$!
trap 'kill $PID 2>/dev/null || true' EXIT
for _ in $(seq 50); do grep -q http "$OUT/serve.err" 2>/dev/null && break; sleep 0.1; done
ADDR=$(grep -o 'http://[0-9.:]*' "$OUT/serve.err")

browse() { # $1: fragment, $2: name; the DOM after the page settled, and a screenshot
    "$CHROMIUM" --headless --no-sandbox --disable-gpu --virtual-time-budget=20000 \
        --dump-dom "$ADDR/#$1" > "$OUT/$2.html" 2>/dev/null
    "$CHROMIUM" --headless --no-sandbox --disable-gpu --virtual-time-budget=20000 \
        --window-size=1400,2000 --screenshot="$OUT/$2.png" "$ADDR/#$1" > /dev/null 2>&1
}
page_poles() { # the poles as the page prints them
    sed -n '/<pre id="poletext">/,/<\/pre>/p' "$OUT/$1.html" \
        | grep -Eo -- '-?[0-9]+\.[0-9]{6} [+-][0-9]+\.[0-9]{6}j' > "$OUT/$1.page" || true
}
cli_poles() { # $1: name, rest: the arguments of `stirling linearize`
    local name=$1; shift
    "$BIN" linearize "$@" | sed -n '/^closed-loop poles/,/^loop broken/p' \
        | awk '/rad\/s/ {print $1, $2}' > "$OUT/$name.cli"
}
same() { # $1: name; the page's poles equal the CLI's
    if [ -s "$OUT/$1.page" ] && diff -q "$OUT/$1.page" "$OUT/$1.cli" > /dev/null; then
        echo "page_check: $1: $(wc -l < "$OUT/$1.page") poles equal the CLI's; screenshot $OUT/$1.png"
    else
        echo "page_check: $1: the page's poles differ from the CLI's:"
        diff "$OUT/$1.page" "$OUT/$1.cli" || true
        exit 1
    fi
}
check() { # $1: fragment, $2: name, rest: linearize arguments
    local frag=$1 name=$2; shift 2
    browse "$frag" "$name"; page_poles "$name"; cli_poles "$name" "$@"; same "$name"
}
moved() { # $1, $2: names whose poles must differ
    if diff -q "$OUT/$1.page" "$OUT/$2.page" > /dev/null; then
        echo "page_check: $2: the poles did not move from $1's"; exit 1
    fi
}
# the text the page inserts before the declaration's last `}` (as a user would type it), the
# same text inserted into a file for the command line, and the fragment carrying it
edited() { # $1: text, $2: file written
    python3 - "$1" "$2" <<'PY'
import sys, urllib.parse
src = open("examples/engines/cv2.stirling").read()
end = src.rindex("}")
open(sys.argv[2], "w").write(src[:end] + sys.argv[1] + "\n" + src[end:])
print(urllib.parse.quote(sys.argv[1], safe=""))
PY
}

check "model=cv2" default cv2
check "model=cv2&Th=700" th700 cv2 --set Th=700
moved default th700
echo "page_check: Th 600 -> 700 moved the poles as \`stirling linearize --set Th=700\` does"

EDIT='    replace params { Th: 650.0 "K" }
    params { /// a load on the piston
        c_load: 2.0 "N s/m" }
    modify body piston { force: -c_load * w }'
FRAG=$(edited "$EDIT" "$OUT/edited.stirling")
check "model=cv2&insert=$FRAG" edited "$OUT/edited.stirling"
moved default edited
grep -q 'compiled `cv2`' "$OUT/edited.html" || { echo "page_check: edited: no 'compiled' status"; exit 1; }
echo "page_check: the declaration edited in the page (Th 650, a load damper) shows the poles of \`stirling linearize $OUT/edited.stirling\`"

BAD='    sensor p_cold2: P_colt "Pa";'
FRAG=$(edited "$BAD" "$OUT/broken.stirling")
browse "model=cv2&insert=$FRAG" broken
page_poles broken
LINE=$(grep -n 'P_colt' "$OUT/broken.stirling" | cut -d: -f1)
if ! grep -q "$LINE:[0-9]*: sensor \`p_cold2\`: no state \`P_colt\`" "$OUT/broken.html"; then
    echo "page_check: broken: no diagnostic at line $LINE"; exit 1
fi
cp "$OUT/default.cli" "$OUT/broken.cli"
same broken
echo "page_check: a mistake at line $LINE is shown at its line:column; the page keeps cv2's poles"
