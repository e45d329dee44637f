#!/bin/bash
# A sharded sweep through a real scheduler: stand up a single-node Slurm on this machine
# (Debian's slurm-wlm: slurmctld and slurmd, munge), run the sweep of
# scripts/slurm/sweep_array.sbatch as a job array, merge the shards with
# scripts/slurm/merge.sbatch as a job that depends on the array, and compare the merged sweep
# with the same sweep run unsharded. The recipe in docs/user-guide.md is these two files.
#
# Usage: STIRLING=path/to/stirling scripts/slurm_test.sh
#   (default: target/release/stirling). Needs root (apt-get, the daemons); installs slurm-wlm
#   and munge when they are missing. Exit 0: the merged sweep equals the unsharded one.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
STIRLING="$(realpath "${STIRLING:-$here/../target/release/stirling}")"
export STIRLING
SHARDS=4
say() { echo "slurm_test: $*" >&2; }

if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    say "installing slurm-wlm and munge (Debian)"
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

work="$(mktemp -d /tmp/stirling-slurm.XXXXXX)"
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
    wait 2>/dev/null || true
}
trap cleanup EXIT

# munge: a key of our own, the daemon on a socket of our own
mkdir -p "$work/munge"
chmod 700 "$work/munge"
mungekey --create --keyfile "$work/munge/munge.key" --force
chmod 400 "$work/munge/munge.key"
# the daemons log to files of their own (and, in the foreground, to stderr: kept there too)
log="$work/daemons.log"
munged --foreground --force --key-file "$work/munge/munge.key" \
    --socket "$work/munge/socket" --pid-file "$work/munge/munged.pid" \
    --log-file "$work/munge/munged.log" --seed-file "$work/munge/seed" 2>>"$log" &
pids+=($!)

host="$(hostname -s)"
cpus="$(nproc)"
mem=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 - 512 ))
mkdir -p "$work/spool" "$work/state" "$work/run"
cat > "$work/slurm.conf" <<EOF
ClusterName=stirling
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$work/munge/socket
CredType=cred/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
SlurmctldPidFile=$work/run/slurmctld.pid
SlurmdPidFile=$work/run/slurmd.pid
SlurmdSpoolDir=$work/spool
StateSaveLocation=$work/state
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF="$work/slurm.conf"

slurmctld -D -f "$SLURM_CONF" 2>>"$log" &
pids+=($!)
slurmd -D -f "$SLURM_CONF" 2>>"$log" &
pids+=($!)

say "waiting for the node"
up=no
for _ in $(seq 60); do
    if sinfo -h -N -o "%t" 2>/dev/null | grep -q -E "^(idle|mix|alloc)"; then up=yes; break; fi
    sleep 1
done
if [ "$up" != yes ]; then
    say "the node did not come up:"
    sinfo -N >&2 || true
    tail -20 "$log" >&2 || true
    exit 1
fi

# the array, then the merge as a job that depends on it, from the folder the shards go to
mkdir -p "$work/sharded"
cd "$work/sharded"
array=$(sbatch --parsable --array=1-$SHARDS "$here/slurm/sweep_array.sbatch")
say "array job $array ($SHARDS shards)"
merge=$(sbatch --parsable --dependency=afterok:"$array" "$here/slurm/merge.sbatch")
say "merge job $merge (after $array)"
for _ in $(seq 600); do
    if [ -z "$(squeue -h -j "$array,$merge" 2>/dev/null)" ]; then break; fi
    sleep 1
done
state=$(sacct -n -X -j "$merge" -o State 2>/dev/null | tr -d ' ' || true)
if [ ! -f sweep/sweep.csv ]; then
    say "no merged sweep (merge job state: ${state:-unknown}); logs:"
    tail -5 shard_*.log merge.log "$log" >&2 || true
    exit 1
fi

# the same sweep unsharded, outside the scheduler
mkdir -p "$work/whole"
cd "$work/whole"
grid=$(grep -o -- '--grid [^ ]*' "$here/slurm/sweep_array.sbatch" | tr '\n' ' ')
# shellcheck disable=SC2086
"$STIRLING" sweep nsection --n 2 $grid --threads 1 --out whole >/dev/null 2>&1

python3 - "$work/sharded/sweep/sweep.csv" "$work/whole/whole/sweep.csv" <<'PY'
import csv, math, sys
a = list(csv.reader(open(sys.argv[1])))
b = list(csv.reader(open(sys.argv[2])))
assert a[0] == b[0], f"headers differ: {a[0]} vs {b[0]}"
assert len(a) == len(b), f"{len(a) - 1} merged rows against {len(b) - 1} unsharded"
worst = 0.0
for ra, rb in zip(a[1:], b[1:]):
    for x, y in zip(ra, rb):
        try:
            fx, fy = float(x), float(y)
        except ValueError:
            assert x == y, f"{x!r} vs {y!r}"
            continue
        if math.isnan(fx) and math.isnan(fy):
            continue
        d = abs(fx - fy) / max(abs(fx), abs(fy), 1e-300)
        worst = max(worst, d)
assert worst <= 1e-12, f"largest relative difference {worst:.3e}"
print(f"slurm_test: merged sweep of {len(a) - 1} points equals the unsharded one "
      f"(largest relative difference {worst:.1e})")
PY
