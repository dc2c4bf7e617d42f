#!/usr/bin/env bash
# Stops what tests/slurm/setup.sh started (the pids it recorded in $STATE/pids: slurmd,
# slurmctld, munged), in that order, and nothing else. Packages stay installed.
set -uo pipefail
STATE=${CADMORPH_SLURM_STATE:-/tmp/cadmorph-slurm}
[ -f "$STATE/pids" ] || exit 0
for name in slurmd slurmctld munged; do
    pid=$(awk -v n="$name" '$1 == n { print $2 }' "$STATE/pids" | tail -1)
    [ -n "$pid" ] || continue
    if kill -0 "$pid" 2>/dev/null; then
        kill -TERM "$pid"
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -0 "$pid" 2>/dev/null && kill -KILL "$pid"
    fi
done
rm -f "$STATE/pids"
