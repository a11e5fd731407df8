#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for the tests of `rigc sweep --executor slurm`:
#   bash scripts/slurm_cluster.sh start   # munge, slurmctld and slurmd in the background
#   bash scripts/slurm_cluster.sh stop    # stops them by their pid files
# State, spool, logs and slurm.conf live under $RIGC_SLURM_DIR (default /tmp/rigc-slurm); clients
# need SLURM_CONF=$RIGC_SLURM_DIR/slurm.conf (`start` prints it). Runs as root (the Debian packages
# slurmctld, slurmd, slurm-client and munge; scripts/setup.sh installs them); no systemd needed.
set -euo pipefail

dir=${RIGC_SLURM_DIR:-/tmp/rigc-slurm}
conf=$dir/slurm.conf
host=$(hostname -s)

write_conf() {
  mkdir -p "$dir/state" "$dir/spool" "$dir/log"
  cat >"$conf" <<CONF
ClusterName=rigc-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldPort=6817
SlurmdPort=6818
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SchedulerType=sched/backfill
SchedulerParameters=sched_interval=1
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MinJobAge=600
NodeName=$host CPUs=2 State=UNKNOWN
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
}

start_munge() {
  local key=/etc/munge/munge.key
  if [[ ! -s $key ]]; then
    mkdir -p /etc/munge
    dd if=/dev/urandom of=$key bs=1024 count=1 status=none
  fi
  chown munge:munge $key
  chmod 400 $key
  mkdir -p /run/munge /var/log/munge /var/lib/munge
  chown munge:munge /run/munge /var/log/munge /var/lib/munge
  if ! munge -n >/dev/null 2>&1; then
    runuser -u munge -- /usr/sbin/munged --pid-file="/run/munge/munged.pid"
    touch "$dir/started-munged"
  fi
}

running() { [[ -s $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null; }

start() {
  if [[ $(id -u) -ne 0 ]]; then
    echo "slurm_cluster: run as root (the daemons run as root here)" >&2
    exit 1
  fi
  write_conf
  start_munge
  export SLURM_CONF=$conf
  running "$dir/slurmctld.pid" || slurmctld -f "$conf"
  running "$dir/slurmd.pid" || slurmd -f "$conf"
  for _ in $(seq 1 60); do
    if sinfo -h -N -o '%T' 2>/dev/null | grep -qx idle; then
      echo "slurm_cluster: up on $host (2 CPUs); export SLURM_CONF=$conf"
      return 0
    fi
    sleep 0.5
  done
  echo "slurm_cluster: the node did not come up; see $dir/log/" >&2
  exit 2
}

stop_pid() {
  local file=$1
  if running "$file"; then
    local pid
    pid=$(cat "$file")
    kill "$pid"
    for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  fi
  rm -f "$file"
}

stop() {
  stop_pid "$dir/slurmd.pid"
  stop_pid "$dir/slurmctld.pid"
  if [[ -e $dir/started-munged ]]; then
    stop_pid /run/munge/munged.pid
    rm -f "$dir/started-munged"
  fi
  echo "slurm_cluster: stopped"
}

case ${1:-} in
  start) start ;;
  stop) stop ;;
  *)
    echo "usage: $0 start|stop" >&2
    exit 1
    ;;
esac
