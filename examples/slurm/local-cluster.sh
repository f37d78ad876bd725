#!/usr/bin/env bash
# A one-node Slurm cluster on this Debian machine, for trying `nbv sweep submit` locally and
# for CI: munged, slurmctld and slurmd started by hand (no systemd), state and logs under
# $SLURM_DIR (default /tmp/nbv-slurm), the configuration written to /etc/slurm/slurm.conf.
# Needs root and Debian's slurm-wlm and munge (`apt-get install -y slurm-wlm munge`).
#
#   examples/slurm/local-cluster.sh start    # start it (idempotent); waits until the node is idle
#   examples/slurm/local-cluster.sh stop     # shut it down
#   examples/slurm/local-cluster.sh status   # sinfo
set -euo pipefail
dir=${SLURM_DIR:-/tmp/nbv-slurm}
conf=/etc/slurm/slurm.conf
host=$(hostname -s)

start() {
    if sinfo -h >/dev/null 2>&1 && sinfo -h -o %T | grep -qE 'idle|mixed|alloc'; then
        echo "slurm: already up"; sinfo; return 0
    fi
    mkdir -p "$dir"/{spool,state,log} /etc/slurm /etc/munge /var/log/munge /run/munge /var/lib/munge
    cpus=$(nproc)
    mem=$(( $(free -m | awk '/^Mem:/ {print $2}') * 9 / 10 ))
    cat > "$conf" <<CONF
ClusterName=local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
KillWait=5
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=main Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
    if [ ! -f /etc/munge/munge.key ]; then
        dd if=/dev/urandom bs=1 count=1024 of=/etc/munge/munge.key 2>/dev/null
    fi
    chown -R munge:munge /etc/munge /var/log/munge /run/munge /var/lib/munge
    chmod 400 /etc/munge/munge.key
    if ! pgrep -x munged >/dev/null; then
        su -s /bin/sh munge -c "munged --force"
    fi
    pgrep -x slurmctld >/dev/null || slurmctld
    sleep 2
    pgrep -x slurmd >/dev/null || slurmd
    for _ in $(seq 1 30); do
        if sinfo -h -o %T 2>/dev/null | grep -qE 'idle|mixed|alloc'; then
            sinfo; return 0
        fi
        sleep 1
    done
    echo "slurm: the node did not come up; logs in $dir/log" >&2
    tail -n 20 "$dir"/log/*.log >&2 || true
    return 1
}

stop() {
    scontrol shutdown 2>/dev/null || true
    pkill -x munged 2>/dev/null || true
}

case "${1:-start}" in
    start) start ;;
    stop) stop ;;
    status) sinfo ;;
    *) echo "usage: $0 start|stop|status" >&2; exit 2 ;;
esac
