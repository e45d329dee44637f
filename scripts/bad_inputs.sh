#!/usr/bin/env bash
# Bad inputs a new user might give the command line (issue 38, second round), each run and
# classed by what it did:
#   clear      refused (non-zero exit, no panic) with a message naming the cause (the case's
#              needle, a word of the cause, is in stderr)
#   right      a valid but unusual input answered (exit 0), as expected
#   wrong      exit 0 where the input should have been refused (a wrong answer)
#   half       a cut file (`*.part` left, or a CSV not ending in a newline) after the run
#   overwrite  a file the case must keep (keep.csv, keep/selfcheck.json) changed
#   runaway    still running after the time limit (TIMEOUT, default 60 s)
#   unclear    refused, but without the cause in the message (or a panic)
# Usage: scripts/bad_inputs.sh [path/to/stirling] (default target/debug/stirling); prints one
# line per case and the count per class; the exit status is 1 when any case is in a bad class.
set -u
BIN=${1:-${CARGO_TARGET_DIR:-target}/debug/stirling}
BIN=$(realpath "$BIN")
TIMEOUT=${TIMEOUT:-60}
W=$(mktemp -d)
trap 'rm -rf "$W"' EXIT
cd "$W" || exit 2
declare -A COUNT
N=0

# ---- the files the cases read --------------------------------------------------------
python3 - <<'PY'
import math
def rec(name, n=4000, dt=5e-4, f=13.4, edit=None, header="t,p,x,y", sep=",", end="\n", tscale=1.0):
    rows = [header]
    for k in range(n):
        t = k * dt
        w = math.sin(2 * math.pi * f * t)
        v = math.sin(2 * math.pi * f * t + 1.4)
        r = [t * tscale, 101325 + 5800 * w, 0.0079 * v, 0.0062 * w]
        if edit: r = edit(k, r)
        rows.append(sep.join(str(x) for x in r))
    open(name, "w", newline="").write(end.join(rows) + end)
rec("good.csv"); rec("keep.csv"); rec("old.csv")
rec("bar.csv", edit=lambda k, r: [r[0], r[1] / 1e5, r[2], r[3]])
rec("kpa.csv", edit=lambda k, r: [r[0], r[1] / 1e3, r[2], r[3]])
rec("gauge.csv", edit=lambda k, r: [r[0], r[1] - 2e5, r[2], r[3]])
rec("mm.csv", edit=lambda k, r: [r[0], r[1], r[2] * 1e3, r[3] * 1e3])
rec("negp.csv", edit=lambda k, r: [r[0], -5.0 if k == 700 else r[1], r[2], r[3]])
rec("hugep.csv", edit=lambda k, r: [r[0], 5e9 if k == 700 else r[1], r[2], r[3]])
rec("outx.csv", edit=lambda k, r: [r[0], r[1], 0.4 if k == 1500 else r[2], r[3]])
rec("outp.csv", edit=lambda k, r: [r[0], 4e5 if k == 1500 else r[1], r[2], r[3]])
rec("back.csv", edit=lambda k, r: [r[0] - (2e-3 if k == 900 else 0), r[1], r[2], r[3]])
rec("dupt.csv", edit=lambda k, r: [r[0] - (5e-4 if k == 900 else 0), r[1], r[2], r[3]])
rec("nan.csv", edit=lambda k, r: [r[0], "NaN" if k == 10 else r[1], r[2], r[3]])
rec("inf.csv", edit=lambda k, r: [r[0], r[1], "inf" if k == 10 else r[2], r[3]])
rec("big.csv", edit=lambda k, r: [r[0], r[1], r[2], "1e400" if k == 10 else r[3]])
rec("emptycell.csv", edit=lambda k, r: [r[0], "" if k == 10 else r[1], r[2], r[3]])
rec("text.csv", edit=lambda k, r: [r[0], "abc" if k == 10 else r[1], r[2], r[3]])
rec("comma_dec.csv", edit=lambda k, r: [r[0], str(r[1]).replace(".", ";"), r[2], r[3]])
rec("semi.csv", header="t;p;x;y", sep=";")
rec("tab.csv", header="t\tp\tx\ty", sep="\t")
rec("cr.csv", end="\r")
rec("crlf.csv", end="\r\n", n=10)
rec("dupcol.csv", header="t,p,x,x")
rec("not.csv", header="time,p,x,y")
rec("other.csv", header="t,a,b,c")
rec("upper.csv", header="T,P,X,Y")
rec("ms.csv", tscale=1e3)
rec("ps.csv", tscale=1e-12 / 5e-4)
rec("coarse.csv", n=1200, dt=1 / 120)
rec("alias.csv", n=600, dt=1.0)
rec("short.csv", n=100)
rec("still.csv", f=0.0)
rec("jitter.csv", edit=lambda k, r: [r[0] + (2e-4 if k % 7 == 3 else 0), r[1], r[2], r[3]])
rec("fewcols.csv", edit=lambda k, r: r[:3] if k == 50 else r)
rec("quoted.csv", header='"t","p","x","y"', n=10)
rec("flip.csv", edit=lambda k, r: [r[0], r[1], -r[2], -r[3]])
rec("long.csv", n=60000)
open("empty.csv", "w").close()
open("header.csv", "w").write("t,p,x,y\n")
open("onerow.csv", "w").write("t,p,x,y\n0,101325,0.001,0.002\n")
open("json.csv", "w").write('{"t": [0, 1], "p": [1, 2]}\n')
open("comments.csv", "w").write("# only\n# comments\n")
open("binary.csv", "wb").write(bytes(range(256)) * 4)
open("utf16.csv", "wb").write("t,p,x,y\n0,1,2,3\n".encode("utf-16"))
open("bad.toml", "w").write("kd = [1, 2\n")
open("unknown.toml", "w").write("nosuch = 1.0\n")
open("negative.toml", "w").write("kd = -5.0\n")
open("params.json", "w").write('{"kd": "fast"}\n')
open("bounds.toml", "w").write("[kd]\nlo = 10\nhi = 1\n")
PY
mkdir -p keep dir.csv side/r.csv.truth.json
echo '{}' > keep/selfcheck.json
KEEP_SUM=$(cat keep.csv keep/selfcheck.json | md5sum)

# ---- running and classing one case ---------------------------------------------------
# err NEEDLE ARGS...: a clear error expected, NEEDLE in stderr; ok ARGS...: exit 0 expected.
run() {
    local expect=$1 needle=$2
    shift 2
    N=$((N + 1))
    rm -rf out && mkdir -p out
    local err code class
    err=$(timeout "$TIMEOUT" "$BIN" "$@" 2>&1 >/dev/null)
    code=$?
    if [ $code -eq 124 ]; then
        class=runaway
    elif [ -n "$(find . -name '*.part' -print -quit)" ] ||
        [ -n "$(find out -name '*.csv' -size +0 -exec sh -c '[ "$(tail -c1 "$1" | od -An -tx1 | tr -d " ")" != 0a ]' _ {} \; -print -quit)" ]; then
        class=half
    elif [ "$(cat keep.csv keep/selfcheck.json | md5sum)" != "$KEEP_SUM" ]; then
        class=overwrite
        cp good.csv keep.csv
        echo '{}' > keep/selfcheck.json
    elif [ $code -eq 0 ]; then
        if [ "$expect" = ok ]; then class=right; else class=wrong; fi
    elif [ $code -eq 101 ] || grep -q panicked <<<"$err"; then
        class=unclear
    elif [ "$expect" = err ] && grep -qiF -- "$needle" <<<"$err"; then
        class=clear
    else
        class=unclear
    fi
    COUNT[$class]=$((${COUNT[$class]:-0} + 1))
    printf '%-9s %3d  stirling %s\n' "$class" "$N" "$*"
    if [ "$class" != clear ] && [ "$class" != right ]; then
        printf '          exit %d: %s\n' "$code" "$(tail -n 3 <<<"$err" | tr '\n' ' ' | cut -c1-300)"
    fi
}
err() { run err "$@"; }
ok() { run ok "" "$@"; }

# ---- the cases ---------------------------------------------------------------------
# records: read by `fit cv1 --data FILE` (refused before any fitting)
err "the file is empty" fit cv1 --data empty.csv
err "no data rows" fit cv1 --data header.csv
err "only one data row" fit cv1 --data onerow.csv
err "the file is empty" fit cv1 --data comments.csv
err "JSON" fit cv1 --data json.csv
err "not a text file" fit cv1 --data binary.csv
err "UTF-8" fit cv1 --data utf16.csv
err "separators" fit cv1 --data semi.csv
err "tab-separated" fit cv1 --data tab.csv
err "carriage returns" fit cv1 --data cr.csv
err "appears twice" fit cv1 --data dupcol.csv
err "missing column \`t\`" fit cv1 --data not.csv
err "missing column \`t\`" fit cv1 --data upper.csv
err "none of its columns" fit cv1 --data other.csv
err "time goes backwards" fit cv1 --data back.csv
err "duplicate time" fit cv1 --data dupt.csv
err "NaN" fit cv1 --data nan.csv
err "infinite" fit cv1 --data inf.csv
err "64-bit number" fit cv1 --data big.csv
err "empty value" fit cv1 --data emptycell.csv
err "not a number" fit cv1 --data text.csv
err "not a number" fit cv1 --data comma_dec.csv
err "value of \`y\` missing" fit cv1 --data fewcols.csv
err "bar or MPa" fit cv1 --data bar.csv
err "kPa" fit cv1 --data kpa.csv
err "gauge pressure" fit cv1 --data gauge.csv
err "looks like mm" fit cv1 --data mm.csv
err "must be absolute" fit cv1 --data negp.csv
err "out of range" fit cv1 --data hugep.csv
err "outlier" fit cv1 --data outx.csv
err "outlier" fit cv1 --data outp.csv
err "milliseconds" fit cv1 --data ms.csv
err "time column's unit" fit cv1 --data ps.csv
err "samples per cycle" fit cv1 --data coarse.csv
err "alias" fit cv1 --data alias.csv
err "alias" diagnose cv1 --data alias.csv
err "fewer than two cycles" fit cv1 --data short.csv
err "does not move enough" fit cv1 --data still.csv
err "uniform" fit cv1 --data jitter.csv
err "too few to fit" fit cv1 --data crlf.csv --train 0:0.001 --holdout 0.001:0.002
err "No such file" fit cv1 --data nosuch.csv
err "directory" fit cv1 --data dir.csv
err "the file is empty" diagnose cv1 --data empty.csv
err "outlier" diagnose cv1 --data outx.csv
err "too short to diagnose" diagnose cv1 --data short.csv
STIRLING_MAX_RECORD_MB=20 err "limit of" fit cv1 --data long.csv
# blocks
err "--train" fit cv1 --data good.csv --train 1:0.5
err "outside the record" fit cv1 --data good.csv --train 0:100
err "overlaps" fit cv1 --data good.csv --train 0:1 --holdout 0.5:1.5
err "must follow" fit cv1 --data good.csv --train 1:1.5 --holdout 0:0.5
err "a:b" fit cv1 --data good.csv --train 0-1
err "finite number of seconds" fit cv1 --data good.csv --train a:b
err "inside the record" fit cv1 --data good.csv --train 10:11 --holdout 11:12
# fit and diagnose options
err "named twice" fit cv1 --data good.csv --free kd,kd
err "nosuch" fit cv1 --data good.csv --free nosuch
err "No such file" fit cv1 --data good.csv --bounds nosuch.toml
err "at least 1" fit cv1 --data good.csv --multiple-shooting 0.5
err "above 0" fit cv1 --data good.csv --restart-cycles 0
err "named twice" diagnose nsection --n 2 --data good.csv --effects leak,leak
err "nosuch" diagnose nsection --n 2 --data good.csv --effects nosuch
err "--prior" diagnose cv1 --data good.csv --prior -1
err "unknown model" fit cv9 --data good.csv
# parameters
err "not physical" linearize cv1 --set Pb=1e7
err "not physical" linearize cv1 --set Pb=1e7 --json
err "times its default" linearize cv1 --set kd=1e30
err "times its default" simulate cv1 --set kd=1e30 --t-end 0.1
err "unknown parameter" linearize cv1 --set nosuch=1
err "NAME=VALUE" linearize cv1 --set kd
err "kd" linearize cv1 --set kd=abc
err "kd" linearize cv1 --set kd=nan
err "kd" linearize cv1 --set kd=-5
err "No such file" linearize cv1 --params nosuch.toml
err "bad.toml" linearize cv1 --params bad.toml
err "nosuch" linearize cv1 --params unknown.toml
err "kd" linearize cv1 --params negative.toml
err "kd" linearize cv1 --params params.json
err "unknown model" linearize cv9
err "at least 1" linearize nsection --n 0
err "too large" linearize nsection --n 1e12
err "not a whole number" linearize nsection --n 2.5
err "times its default" linearize nsection --n 2 --set Rf=1e-9
# simulate and rig
err "t-end" simulate cv1 --t-end -1
err "t-end" simulate cv1 --t-end 0
err "between 2" simulate cv1 --samples 1
err "stable at rest" simulate cv1 --set Th=320 --limit-cycle --t-end 2
err "stable at rest" simulate cv1 --set Th=320 --limit-cycle --t-end 0.2
err "[1e-14, 0.1]" simulate cv1 --t-end 0.1 --atol 1e-30
err "[1e-14, 0.1]" simulate cv1 --t-end 0.1 --rtol 1e-20
err "between 2" simulate cv1 --samples 1e9
err "exists" simulate cv1 --t-end 0.1 --out keep.csv
err "exists" rig cv1 --t-end 0.5 --out keep.csv
err "is a folder" rig cv1 --t-end 0.5 --out side/r.csv --force
err "is a folder" rig cv1 --t-end 0.5 --out dir.csv --force
err "is a folder" simulate cv1 --t-end 0.1 --out dir.csv --force
err "rate" rig cv1 --rate 0 --out out/r.csv
err "rate" rig cv1 --rate -5 --out out/r.csv
err "rate" rig cv1 --rate nan --out out/r.csv
err "a seed is a whole number" rig cv1 --seed -1 --out out/r.csv
err "not a whole number" rig cv1 --seed 1.5 --out out/r.csv
err "too large" rig cv1 --seed 1e30 --out out/r.csv
err "noise" rig cv1 --noise x=-1 --out out/r.csv
err "foo" rig cv1 --channels foo --out out/r.csv
err "named twice" rig cv1 --channels x,x --out out/r.csv
err "named twice" rig cv1 --effect leak=1e-8 --effect leak=2e-8 --out out/r.csv
err "named twice" rig cv1 --noise x=1e-5 --noise x=2e-5 --out out/r.csv
err "named twice" diagnose --self-check --channels p,p,x --out out/sc
err "named twice" diagnose --self-check --strengths 1,1 --out out/sc
err "none of its columns" diagnose cv1 --data other.csv
ok rig cv1 --t-end 0.5 --out out/new/folder/r.csv
# sweeps
err "count k" sweep cv1 --grid Th=500:700:0 --out out/s
err "values on one axis" sweep cv1 --grid Th=500:700:1000000000 --poles-only --out out/s
err "NAME=a:b:k" sweep cv1 --grid Th --out out/s
err "nosuch" sweep cv1 --grid nosuch=1:2:3 --out out/s
err "not a finite number" sweep cv1 --grid Th=a:b:3 --out out/s
err "a:b:k" sweep cv1 --grid Th=1:2:3:4 --out out/s
err "--shard" sweep cv1 --grid Th=500:700:4 --grid Tk=280:320:4 --grid Pmean=1e5:2e5:1000000 --poles-only --out out/s
err "shard" sweep cv1 --grid Th=500:700:4 --shard 0/2 --out out/s
err "shard" sweep cv1 --grid Th=500:700:4 --shard 3/2 --out out/s
err "shard" sweep cv1 --grid Th=500:700:4 --shard a/b --out out/s
err "twice" sweep cv1 --grid Th=500:700:3 --grid Th=600:800:3 --out out/s
err "No such file" sweep-merge nosuch.json --out out/m
err "keep.csv" sweep-merge keep.csv --out out/m
# locus
err "at Pb = " locus cv1 --param Pb --from 1e5 --to 1e7 --steps 5
err "nosuch" locus cv1 --param nosuch --from 1 --to 2
err "steps" locus cv1 --param Th --from 500 --to 700 --steps 0
# self-check options (refused before any case runs)
err "pass --force" diagnose --self-check --out keep
err "evaluation set is empty" diagnose --self-check --seeds 1:0 --clean 10:0 --out out/sc
err "TUNE:EVAL" diagnose --self-check --seeds 1 --out out/sc
err "strengths" diagnose --self-check --strengths 0 --out out/sc
err "a seed is a whole number" diagnose --self-check --seed -1 --out out/sc
# the command line itself
err "unrecognized subcommand" frobnicate
err "unexpected argument" linearize cv1 --nosuch
err "unknown model" info nosuch
# unusual but valid: answered
ok linearize cv1
ok linearize cv1 --set kd=6.5e9
ok linearize cv1 --json
ok info cv1
ok models
ok --help
ok linearize nsection --n 3
ok rig cv1 --t-end 0.5 --seed 18446744073709551615 --out out/r.csv
ok simulate cv1 --t-end 0.1 --samples 2 --out out/s.csv
ok rig cv1 --t-end 0.5 --out old.csv --force

echo
echo "$N inputs:"
bad=0
for c in clear right wrong half overwrite runaway unclear; do
    printf '  %-9s %d\n' "$c" "${COUNT[$c]:-0}"
    case $c in clear | right) ;; *) bad=$((bad + ${COUNT[$c]:-0})) ;; esac
done
[ $bad -eq 0 ]
