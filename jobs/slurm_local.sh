#!/usr/bin/env bash
# A one-node Slurm on this machine, to try the job scripts on and for the test that submits them
# (tests/jobs/test_slurm.sh). munged, slurmctld and slurmd run as root from DIR, with a key and a
# configuration written there: nothing under /etc is read or changed, no system service is used.
#   jobs/slurm_local.sh start DIR   start them, wait until the node takes jobs
#   jobs/slurm_local.sh stop DIR    stop them
# Then: export SLURM_CONF=DIR/slurm.conf; sbatch ...
# Needs Debian's slurmd, slurmctld, slurm-client and munge (quickstart.sh test installs them).
# Exit status 3, with the reason, where Slurm cannot start here; 2 for bad arguments.
set -euo pipefail
if [[ $# -ne 2 || ( $1 != start && $1 != stop ) ]]; then
  sed -n '2,9p' "$0"
  exit 2
fi
action=$1
dir=$(mkdir -p "$2" && cd "$2" && pwd)

stop() {
  for daemon in slurmd slurmctld munged; do
    local pid_file=$dir/$daemon.pid
    [[ -f $pid_file ]] || continue
    local pid
    pid=$(cat "$pid_file")
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
    kill -9 "$pid" 2>/dev/null || true
    rm -f "$pid_file"
  done
}

cannot() {
  echo "slurm_local.sh: Slurm cannot start here: $*" >&2
  stop
  exit 3
}

if [[ $action == stop ]]; then
  stop
  exit 0
fi

for tool in munged munge slurmctld slurmd sbatch sinfo; do
  command -v "$tool" >/dev/null ||
    cannot "$tool not found (Debian: apt-get install slurmd slurmctld slurm-client munge)"
done
[[ $(id -u) == 0 ]] || cannot "the daemons run as root here, and this is $(id -un)"
stop
mkdir -p "$dir/state" "$dir/spool"
if [[ ! -f $dir/munge.key ]]; then
  (umask 077 && head -c 1024 /dev/urandom >"$dir/munge.key")
fi
# --force: munged refuses root and a key outside /etc/munge without it.
munged --force --socket="$dir/munge.socket" --key-file="$dir/munge.key" \
  --log-file="$dir/munged.log" --pid-file="$dir/munged.pid" --seed-file="$dir/munged.seed" ||
  cannot "munged did not start ($dir/munged.log)"

host=$(hostname -s)
# The node as Slurm will find it: the CPUs, and the sockets, cores and hardware threads they
# are made of (a node configured otherwise than it is is drained).
sockets=$(lscpu -p=SOCKET | grep -v '^#' | sort -u | wc -l)
cores=$(lscpu -p=SOCKET,CORE | grep -v '^#' | sort -u | wc -l)
cpus=$(lscpu -p=CPU | grep -cv '^#')
cat >"$dir/slurm.conf" <<CONF
# Written by jobs/slurm_local.sh: a one-node cluster on $host.
ClusterName=cosserat-local
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$dir/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
# Containers and CI machines have no cgroup hierarchy of their own to give Slurm: processes are
# tracked by their parent, and bound by srun's --cpu-bind alone.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/affinity
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host CPUs=$cpus Sockets=$sockets CoresPerSocket=$((cores / sockets)) ThreadsPerCore=$((cpus / cores)) State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$dir/slurm.conf
slurmctld || cannot "slurmctld did not start ($dir/slurmctld.log)"
slurmd || cannot "slurmd did not start ($dir/slurmd.log)"
for _ in $(seq 100); do
  state=$(sinfo -h -n "$host" -o %T 2>/dev/null || true)
  [[ $state == idle ]] && { echo "Slurm is up: export SLURM_CONF=$dir/slurm.conf"; exit 0; }
  sleep 0.2
done
cannot "the node is '${state:-unknown}', not idle, after 20 s ($dir/slurmd.log, $dir/slurmctld.log)"
