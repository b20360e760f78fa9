#!/bin/bash
# Starts a private one-node Slurm cluster for tests: its own munged, slurmctld and slurmd, all
# configured, keyed, logged and pid-filed under one state directory; /etc/slurm and /etc/munge
# are not used. Usage:
#   eval "$(scripts/slurm/start.sh [STATE_DIR])"   # STATE_DIR: else $EMAKI_SLURM_DIR, else build/slurm
# On success the only line on stdout is `export SLURM_CONF=STATE_DIR/slurm.conf`: sbatch, squeue,
# scontrol, scancel and sinfo reach this cluster through it. Returns once `sinfo` shows the node
# idle (at most $EMAKI_SLURM_START_TIMEOUT s, default 30); on failure prints the logs' tails, stops
# what it started and exits 1. Already running for STATE_DIR: prints the line again and exits 0;
# stale pid files (after a crash) are cleared. scripts/slurm/stop.sh STATE_DIR stops it all.
# Node `localhost`, partition `emaki` (the default), CPUs and memory of this machine, one CPU
# and RealMemory/CPUs MB per task unless a job asks for more.
set -u
# shellcheck source=scripts/slurm/common.sh
. "$(dirname "$0")/common.sh"
timeout=${EMAKI_SLURM_START_TIMEOUT:-30}

if [ "$(id -u)" -ne 0 ]; then
  log "needs root: slurmd starts jobs as their users (SlurmdUser=root)"
  exit 1
fi
for b in munged slurmctld slurmd sbatch sinfo scontrol; do
  command -v "$b" >/dev/null || { log "'$b' not found: install slurm-wlm and munge (scripts/setup.sh)"; exit 1; }
done

m_pid=$(daemon_pid munged "$dir/munged.pid")
c_pid=$(daemon_pid slurmctld "$dir/slurmctld.pid")
d_pid=$(daemon_pid slurmd "$dir/slurmd.pid")
if [ -n "$m_pid" ] && [ -n "$c_pid" ] && [ -n "$d_pid" ] && [ "$m_pid $c_pid $d_pid" = "${m_pid%% *} ${c_pid%% *} ${d_pid%% *}" ]; then
  case "$(sinfo -h -n localhost -o %t 2>/dev/null)" in
  idle | mix | alloc | comp)
    log "already running in $dir"
    echo "export SLURM_CONF=$conf"
    exit 0
    ;;
  esac
fi
if [ -n "$m_pid$c_pid$d_pid" ]; then
  log "partly running in $dir: restarting"
  "$(dirname "$0")/stop.sh" "$dir" || exit 1
fi

fail() {
  log "$*"
  log_tails 30
  "$slurm_here/stop.sh" "$dir" >/dev/null 2>&1
  exit 1
}

# A fresh cluster each start: no job state carries over.
if [ -s "$dir/rundir" ]; then
  case "$(cat "$dir/rundir")" in /tmp/emaki-slurm.*) rm -rf "$(cat "$dir/rundir")" ;; esac
fi
rm -rf "$dir/state" "$dir/run" "$dir/log" "$dir/rundir" "$dir"/*.pid "$conf"
mkdir -p "$dir/state" && chmod 0700 "$dir/state" || exit 1
mkdir -p "$dir/log" && chmod 0755 "$dir/log" || exit 1
chmod 0755 "$dir"
# Unix sockets (munged's; slurmstepd's in the spool dir, NODE_JOBID.STEPID) must fit the 108
# bytes of a sockaddr_un: under a long state dir they go to a short private dir in /tmp.
run=$dir/run
if [ ${#dir} -gt 48 ]; then
  run=$(mktemp -d /tmp/emaki-slurm.XXXXXX) && chmod 0755 "$run" || exit 1
  echo "$run" >"$dir/rundir"
fi
mkdir -p "$run/munge" && chmod 0755 "$run/munge" || exit 1
mkdir -p "$run/spool" && chmod 0755 "$run/spool" || exit 1
sock=$run/munge/munge.socket

# Two free TCP ports (below the ephemeral range), the same ones for the same dir when free.
port_used() {
  local hex
  hex=$(printf ':%04X ' "$1")
  # Listening sockets only (state 0A): slurmctld and slurmd bind with SO_REUSEADDR.
  cat /proc/net/tcp /proc/net/tcp6 2>/dev/null | awk '$4 == "0A" { print $2 " " }' | grep -qF "$hex"
}
port=$((10000 + ($(echo "$dir" | cksum | cut -d' ' -f1) % 10000) * 2))
for _ in $(seq 200); do
  port_used "$port" || port_used "$((port + 1))" || break
  port=$((port + 2))
  [ "$port" -ge 30000 ] && port=10000
done

# munge key and daemon.
key=$run/munge/munge.key
if command -v mungekey >/dev/null; then
  mungekey --create --keyfile="$key" 2>/dev/null || dd if=/dev/urandom of="$key" bs=1024 count=1 2>/dev/null
else
  dd if=/dev/urandom of="$key" bs=1024 count=1 2>/dev/null
fi
chmod 0600 "$key"
# --force: the state dir may sit under a group-writable path, which munged's checks refuse.
munged 9>&- --force --socket="$sock" --key-file="$key" --pid-file="$dir/munged.pid" \
  --log-file="$dir/log/munged.log" --seed-file="$run/munge/munged.seed" ||
  fail "munged failed to start"
for _ in $(seq 50); do
  munge -n -S "$sock" 2>/dev/null | unmunge -S "$sock" >/dev/null 2>&1 && break
  sleep 0.1
done
munge -n -S "$sock" 2>/dev/null | unmunge -S "$sock" >/dev/null 2>&1 ||
  fail "munged does not answer on $sock"

# The node: this machine's CPUs and memory (slurmd -C sees what slurmd will check against).
cpus=$(nproc)
mem=$(($(awk '/^MemTotal:/ { print $2 }' /proc/meminfo) / 1024))
hw=$(slurmd -C 2>/dev/null | head -n 1)
hw_cpus=$(echo "$hw" | sed -n 's/.* CPUs=\([0-9]*\).*/\1/p')
hw_mem=$(echo "$hw" | sed -n 's/.* RealMemory=\([0-9]*\).*/\1/p')
[ -n "$hw_cpus" ] && [ "$hw_cpus" -lt "$cpus" ] && cpus=$hw_cpus
[ -n "$hw_mem" ] && [ "$hw_mem" -lt "$mem" ] && mem=$hw_mem
mem_per_cpu=$((mem / cpus))

# Knobs for bench/slurm_overhead.sh: EMAKI_SLURM_SCHED replaces SchedulerParameters,
# EMAKI_SLURM_EPILOG= (empty) drops the epilog.
sched=${EMAKI_SLURM_SCHED:-batch_sched_delay=0,sched_min_interval=0,sched_interval=1,bf_interval=1,default_queue_depth=1000}
epilog=${EMAKI_SLURM_EPILOG-/bin/true}
epilog_line="#Epilog="
[ -n "$epilog" ] && epilog_line="Epilog=$epilog"

cat >"$conf" <<EOF
# Generated by scripts/slurm/start.sh: a private one-node test cluster. Do not edit.
ClusterName=emaki
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$sock
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$dir/state
SlurmdSpoolDir=$run/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
PlugStackConfig=$dir/plugstack.conf
# No cgroups in a container: track job processes through /proc, no task binding.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$dir/log/jobcomp.txt
SwitchType=switch/none
MailProg=/bin/true
# With an epilog slurmd reports each job end (MESSAGE_EPILOG_COMPLETE), which runs the scheduler
# at once; without one the next pass waits for slurmctld's 1 s background tick.
$epilog_line
MpiDefault=none
ReturnToService=2
# One CPU and mem/CPUs MB per task by default, so tasks run side by side.
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU_Memory
DefMemPerCPU=$mem_per_cpu
SchedulerType=sched/backfill
SchedulerParameters=$sched
# A job whose afterok dependency failed is cancelled instead of pending forever.
DependencyParameters=kill_invalid_depend
# Finished jobs stay visible to squeue/scontrol for 10 minutes (no slurmdbd, so no sacct).
MinJobAge=600
MaxArraySize=100001
MaxJobCount=200000
MessageTimeout=10
SlurmctldTimeout=60
SlurmdTimeout=300
InactiveLimit=0
KillWait=5
Waittime=0
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=emaki Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
: >"$dir/plugstack.conf"

slurmctld -f "$conf" -i 9>&- || fail "slurmctld failed to start"
ok=""
for _ in $(seq $((timeout * 10))); do
  scontrol ping 2>/dev/null | grep -q UP && { ok=1; break; }
  sleep 0.1
done
[ -n "$ok" ] || fail "slurmctld does not answer (scontrol ping)"

slurmd -f "$conf" -N localhost 9>&- || fail "slurmd failed to start"
state=""
for _ in $(seq $((timeout * 10))); do
  state=$(sinfo -h -n localhost -o %t 2>/dev/null)
  [ "$state" = idle ] && break
  sleep 0.1
done
[ "$state" = idle ] || fail "node localhost not idle after ${timeout}s (state '$state')"
log "cluster up in $dir (ports $port,$((port + 1)); localhost: $cpus CPUs, $mem MB)"
echo "export SLURM_CONF=$conf"
