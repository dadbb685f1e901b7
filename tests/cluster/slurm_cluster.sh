#!/usr/bin/env bash
# A single-node Slurm cluster on this machine, for the tests of the cluster
# path (docs/sweep.md, "Cluster mode"): munged with a key of its own, then
# slurmctld and slurmd on free ports, everything (key, sockets, state,
# spool, logs, slurm.conf) inside DIR. Needs root and Debian's slurm-wlm and
# munge (scripts/install-deps.sh).
#
#   slurm_cluster.sh start DIR   start it; DIR/env holds SLURM_CONF to source
#   slurm_cluster.sh stop DIR    stop what start started (by its pid files)
#
# start exits 77 (CTest's skip code here) with the reason when it cannot run:
# not root, or a program missing. Any other failure prints the daemons' logs.
set -euo pipefail

SKIP=77
cmd=${1:-}
dir=${2:-}
if [ -z "$cmd" ] || [ -z "$dir" ]; then
  echo "usage: $0 start|stop DIR" >&2
  exit 2
fi

stop_daemons() {
  local name pid pids=()
  # SIGTERM to all three at once, then up to 10 s for each before SIGKILL
  for name in slurmd slurmctld munged; do
    [ -f "$dir/$name.pid" ] || continue
    pid=$(cat "$dir/$name.pid")
    rm -f "$dir/$name.pid"
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
      kill -TERM "$pid" 2>/dev/null || true
      pids+=("$pid")
    fi
  done
  for pid in "${pids[@]}"; do
    for _ in $(seq 100); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null || true
  done
}

show_logs() {
  local f
  for f in "$dir"/log/*.log; do
    [ -f "$f" ] || continue
    echo "---- $f (last 30 lines)" >&2
    tail -n 30 "$f" >&2
  done
}

if [ "$cmd" = stop ]; then
  [ -d "$dir" ] || exit 0
  stop_daemons
  rm -f "$dir/env"  # no cluster to use any more
  echo "slurm_cluster: stopped ($dir)"
  exit 0
fi
[ "$cmd" = start ] || { echo "$0: unknown command '$cmd'" >&2; exit 2; }

# not startable here: the reason in DIR/skip (the tests that need the
# cluster skip with it), no DIR/env
skip() {
  mkdir -p "$dir"
  rm -f "$dir/env"
  echo "$1" > "$dir/skip"
  echo "slurm_cluster: SKIP: $1"
  exit $SKIP
}
if [ "$(id -u)" -ne 0 ]; then
  skip "not root (slurmd runs each job as its user: it needs root)"
fi
for p in munged mungekey slurmctld slurmd sbatch squeue sinfo scancel; do
  if ! command -v "$p" >/dev/null && [ ! -x "/usr/sbin/$p" ]; then
    skip "'$p' is not installed (Debian's slurm-wlm and munge: scripts/install-deps.sh)"
  fi
done
export PATH="$PATH:/usr/sbin"

# an earlier cluster of this folder is stopped, its files replaced
stop_daemons
rm -rf "$dir"
mkdir -p "$dir"/{log,state,spool,munge}
dir=$(cd "$dir" && pwd)
# munged refuses group- or world-writable folders on the way to its files
chmod 0700 "$dir" "$dir/munge"

free_port() {
  /usr/bin/python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}

mungekey --create --keyfile="$dir/munge/munge.key" >/dev/null
chmod 0400 "$dir/munge/munge.key"
munged --force --key-file="$dir/munge/munge.key" \
  --socket="$dir/munge/munge.socket" --pid-file="$dir/munged.pid" \
  --log-file="$dir/log/munged.log" --seed-file="$dir/munge/munged.seed" \
  || { echo "slurm_cluster: munged did not start" >&2; show_logs; exit 1; }

ctld_port=$(free_port)
slurmd_port=$(free_port)
while [ "$slurmd_port" = "$ctld_port" ]; do slurmd_port=$(free_port); done
cluster="bims$$"
cat > "$dir/slurm.conf" <<CONF
ClusterName=$cluster
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool/%n
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
ReturnToService=2
MaxArraySize=10000
SlurmdTimeout=60
InactiveLimit=0
KillWait=5
NodeName=localhost NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=bims Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
echo "export SLURM_CONF=$dir/slurm.conf" > "$dir/env"
export SLURM_CONF="$dir/slurm.conf"

slurmctld -i -f "$dir/slurm.conf" \
  || { echo "slurm_cluster: slurmctld did not start" >&2; show_logs; stop_daemons; exit 1; }
slurmd -N localhost -f "$dir/slurm.conf" \
  || { echo "slurm_cluster: slurmd did not start" >&2; show_logs; stop_daemons; exit 1; }

# ready: the node idle in the partition (bounded wait)
for _ in $(seq 300); do
  state=$(sinfo -h -N -o '%T' 2>/dev/null | head -n1 || true)
  case "$state" in
    idle*|mixed*) echo "slurm_cluster: up (node localhost $state; SLURM_CONF=$dir/slurm.conf)"; exit 0 ;;
  esac
  sleep 0.1
done
echo "slurm_cluster: the node did not become idle within 30 s (state '${state:-none}')" >&2
sinfo -N -l >&2 || true
show_logs
stop_daemons
exit 1
