#!/usr/bin/env bash
# A one-node Slurm from Debian's packages (munge, slurmctld, slurmd), started by hand as
# root (no systemd), then the example sweep through `sbatch --array`: planned, run by the
# real daemons, merged and checked. docs/SWEEPS.md records a run of it.
#
#     sudo scripts/slurm-local.sh [GRID]     # default: assets/sweep_example.ron
set -euo pipefail
cd "$(dirname "$0")/.."
grid=${1:-assets/sweep_example.ron}

[ "$(id -u)" -eq 0 ] || { echo "run as root: it configures and starts munge and Slurm" >&2; exit 1; }
if ! command -v sbatch >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq munge slurmctld slurmd slurm-client >/dev/null
fi

host=$(hostname -s)
cpus=$(nproc)
memory=$(awk '/MemTotal/ { print int($2 / 1024) }' /proc/meminfo)
mkdir -p /etc/slurm /var/spool/slurmctld /var/spool/slurmd /var/log/slurm
cat > /etc/slurm/slurm.conf <<EOF
ClusterName=sapnet
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SlurmctldPidFile=/run/slurmctld.pid
SlurmdPidFile=/run/slurmd.pid
SlurmdSpoolDir=/var/spool/slurmd
StateSaveLocation=/var/spool/slurmctld
SlurmctldLogFile=/var/log/slurm/slurmctld.log
SlurmdLogFile=/var/log/slurm/slurmd.log
NodeName=$host CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF

# munge: a key, its run directory, the daemon as its own user.
if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 2>/dev/null
fi
chown munge:munge /etc/munge/munge.key && chmod 400 /etc/munge/munge.key
mkdir -p /run/munge && chown munge:munge /run/munge
pgrep -x munged >/dev/null || runuser -u munge -- /usr/sbin/munged
pgrep -x slurmctld >/dev/null || slurmctld
pgrep -x slurmd >/dev/null || slurmd
for _ in $(seq 60); do
    sinfo -h -o %T 2>/dev/null | grep -qE '^(idle|mixed|allocated)' && break
    sleep 1
done
sinfo

cargo build --release --quiet
sapnet=$PWD/target/release/sapnet
sweep=$(mktemp -d)/sweep
"$sapnet" sweep plan --grid "$grid" --out "$sweep"
started=$(date +%s)
job=$(sbatch --parsable "$sweep/slurm.sbatch")
echo "submitted array job $job"
while squeue -h -j "$job" 2>/dev/null | grep -q .; do sleep 1; done
echo "the array ran in $(( $(date +%s) - started )) s"
sacct -j "$job" 2>/dev/null || true
"$sapnet" sweep status "$sweep"
"$sapnet" sweep merge "$sweep"
if "$sapnet" sweep status "$sweep" | head -1 | grep -qE '^([0-9]+) cells: \1 done'; then
    echo "OK: every cell of $sweep ran under Slurm and merged into $sweep/merged"
else
    echo "FAILED: not every cell is done (logs in $sweep/logs)" >&2
    exit 1
fi
