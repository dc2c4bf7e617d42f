#!/usr/bin/env bash
# A real single-node Slurm for the campaign tests (issue 16): installs Debian's slurm-wlm
# and munge if missing, writes a one-node slurm.conf for this host (2 CPUs, no cgroup
# plugins: proctrack/linuxproc, task/none, select/cons_tres), starts munged, slurmctld and
# slurmd in the background and waits until `sinfo` shows the node idle.
#
# Idempotent: a second run with everything up only checks `sinfo`. Everything it starts
# is recorded in $STATE/pids; tests/slurm/stop.sh stops exactly those processes.
# Needs root (apt-get, /etc/slurm). State and logs: $STATE (default /tmp/cadmorph-slurm).
set -euo pipefail
STATE=${CADMORPH_SLURM_STATE:-/tmp/cadmorph-slurm}
mkdir -p "$STATE"
log() { echo "slurm setup: $*" >&2; }

node_idle() {
    sinfo -h -N -o '%t' 2>/dev/null | grep -qE '^(idle|mix|alloc)'
}

if command -v sinfo >/dev/null && [ -f "$STATE/pids" ] && node_idle; then
    log "already up"; exit 0
fi

# 1. Packages (dpkg may be locked by another engineer's install: wait and retry).
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null \
    || ! command -v sbatch >/dev/null; then
    log "installing slurm-wlm and munge"
    for attempt in 1 2 3 4 5 6 7 8 9 10; do
        if DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=300 install -y --no-install-recommends \
            slurm-wlm munge >"$STATE/apt.log" 2>&1; then
            break
        fi
        [ "$attempt" = 10 ] && { cat "$STATE/apt.log" >&2; exit 1; }
        # A machine whose package lists are missing or stale: update them once.
        if [ "$attempt" = 1 ] && grep -qE "Unable to locate package|has no installation candidate|404" "$STATE/apt.log"; then
            log "updating the package lists"; apt-get -o DPkg::Lock::Timeout=300 update >>"$STATE/apt.log" 2>&1 || true
        fi
        log "apt-get failed (attempt $attempt), retrying in 10 s"; sleep 10
    done
fi

# 2. munge: a key, its run directory, the daemon.
if [ ! -s /etc/munge/munge.key ]; then
    log "creating the munge key"
    if command -v mungekey >/dev/null; then mungekey --create --keyfile=/etc/munge/munge.key --force
    else dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=1024 status=none; fi
fi
chown munge:munge /etc/munge/munge.key 2>/dev/null || true
chmod 0400 /etc/munge/munge.key
mkdir -p /run/munge /var/log/munge /var/lib/munge
chown munge:munge /run/munge /var/log/munge /var/lib/munge 2>/dev/null || true
chmod 0755 /run/munge

touch "$STATE/pids"
running() { [ -n "$1" ] && kill -0 "$1" 2>/dev/null; }
recorded() { awk -v n="$1" '$1 == n { print $2 }' "$STATE/pids" | tail -1; }
record() { grep -v "^$1 " "$STATE/pids" >"$STATE/pids.new" || true; echo "$1 $2" >>"$STATE/pids.new"; mv "$STATE/pids.new" "$STATE/pids"; }

if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    log "starting munged"
    # Foreground mode under setsid, so that $! is the daemon itself.
    setsid runuser -u munge -- /usr/sbin/munged --foreground --force >"$STATE/munged.log" 2>&1 &
    record munged $!
    for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.2; done
    munge -n | unmunge >/dev/null || { cat "$STATE/munged.log" >&2; exit 1; }
fi

# 3. slurm.conf for this one node.
HOST=$(hostname -s)
MEM=$(awk '/MemTotal/ { print int($2 / 1024 * 0.9) }' /proc/meminfo)
mkdir -p /etc/slurm "$STATE/ctld" "$STATE/slurmd"
CONF=/etc/slurm/slurm.conf
cat >"$CONF.new" <<CONF
# Written by cadmorph tests/slurm/setup.sh: one node, no cgroups, no accounting daemon.
ClusterName=cadmorph
SlurmctldHost=$HOST
AuthType=auth/munge
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
SlurmctldPort=6817
SlurmdPort=6818
StateSaveLocation=$STATE/ctld
SlurmdSpoolDir=$STATE/slurmd
SlurmctldPidFile=$STATE/slurmctld.pid
SlurmdPidFile=$STATE/slurmd.pid
SlurmctldLogFile=$STATE/slurmctld.log
SlurmdLogFile=$STATE/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$STATE/jobcomp.txt
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SlurmctldTimeout=30
SlurmdTimeout=30
MinJobAge=600
NodeName=$HOST CPUs=2 RealMemory=$MEM State=UNKNOWN
PartitionName=debug Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
mv "$CONF.new" "$CONF"

# 4. The daemons, in the foreground under setsid (their pids are $!).
if ! running "$(recorded slurmctld)"; then
    log "starting slurmctld"
    setsid /usr/sbin/slurmctld -D -i >"$STATE/slurmctld.out" 2>&1 &
    record slurmctld $!
fi
for _ in $(seq 100); do scontrol ping 2>/dev/null | grep -q UP && break; sleep 0.2; done
if ! running "$(recorded slurmd)"; then
    log "starting slurmd"
    setsid /usr/sbin/slurmd -D >"$STATE/slurmd.out" 2>&1 &
    record slurmd $!
fi

# 5. Wait (bounded) for the node to be idle.
for _ in $(seq 150); do
    if node_idle; then log "node $HOST idle"; sinfo >&2; exit 0; fi
    sleep 0.2
done
# A node left down by an earlier run comes back.
scontrol update nodename="$HOST" state=resume 2>/dev/null || true
for _ in $(seq 100); do node_idle && { log "node $HOST idle"; exit 0; }; sleep 0.2; done
log "node did not become idle:"; sinfo -N -l >&2 || true
tail -20 "$STATE/slurmctld.log" "$STATE/slurmd.log" "$STATE/slurmctld.out" "$STATE/slurmd.out" >&2 || true
exit 1
