# Shared by scripts/slurm/start.sh and stop.sh (sourced, not run). Sets $dir to the absolute
# state directory: the first argument, else $EMAKI_SLURM_DIR, else <repo>/build/slurm.
slurm_here=$(cd "$(dirname "$0")" && pwd)
dir=${1:-${EMAKI_SLURM_DIR:-$slurm_here/../../build/slurm}}
mkdir -p "$dir" || exit 1
dir=$(cd "$dir" && pwd)
conf=$dir/slurm.conf
export SLURM_CONF=$conf

# One start.sh or stop.sh at a time per state dir (stop.sh run by a start.sh that holds the
# lock inherits it).
if [ "${EMAKI_SLURM_LOCKED:-}" != "$dir" ] && command -v flock >/dev/null; then
  exec 9>"$dir/lock"
  flock -w 120 9 || { echo "slurm: $dir/lock held for 120 s by another start.sh/stop.sh" >&2; exit 1; }
  export EMAKI_SLURM_LOCKED=$dir
fi

log() { echo "slurm: $*" >&2; }

# Prints the pids of daemon $1 (munged, slurmctld or slurmd) started for this state dir: the pid
# in its pid file $2 when that process is alive and is the daemon, plus any such process whose
# arguments name this dir's pid file (munged) or slurm.conf (slurmctld, slurmd), so a stale,
# reused or lost pid file neither hits another process nor loses one of ours.
daemon_pid() {
  local pid="" p want pids=""
  case "$1" in munged) want="--pid-file=$dir/munged.pid" ;; *) want=$conf ;; esac
  if [ -s "$2" ]; then
    pid=$(tr -dc '0-9' <"$2")
    [ -n "$pid" ] && _is_ours "$pid" "$1" "$want" && pids=$pid
  fi
  for p in /proc/[0-9]*; do
    p=${p#/proc/}
    [ "$p" = "$pid" ] && continue
    _is_ours "$p" "$1" "$want" && pids="$pids $p"
  done
  # shellcheck disable=SC2086
  [ -n "$pids" ] && echo $pids
}
_is_ours() {
  local comm=""
  { read -r comm <"/proc/$1/comm"; } 2>/dev/null
  [ "$comm" = "$2" ] || return 1
  grep -q '^State:.*Z' "/proc/$1/status" 2>/dev/null && return 1
  { tr '\0' '\n' <"/proc/$1/cmdline"; } 2>/dev/null | grep -qxF -- "$3"
}

# Pids of this cluster's job processes: its slurmstepd processes (started by our slurmd, so
# their environment has SLURM_CONF=$conf) and all their descendants.
job_pids() {
  local p s pp comm roots="" all
  for p in /proc/[0-9]*; do
    p=${p#/proc/}
    comm=""
    { read -r comm <"/proc/$p/comm"; } 2>/dev/null
    [ "$comm" = slurmstepd ] || continue
    { tr '\0' '\n' <"/proc/$p/environ"; } 2>/dev/null | grep -qxF "SLURM_CONF=$conf" && roots="$roots $p"
  done
  [ -z "$roots" ] && return 0
  # "pid ppid" lines; walk down from the roots.
  all=$(for p in /proc/[0-9]*/stat; do
    s=$(cat "$p" 2>/dev/null) || continue
    s=${s##*) }
    read -r _ pp _ <<<"$s"
    p=${p#/proc/}
    echo "${p%/stat} $pp"
  done)
  echo "$all" | awk -v roots="$roots" '
    { parent[$1] = $2 }
    END {
      n = split(roots, r, " "); for (i = 1; i <= n; i++) keep[r[i]] = 1
      do { changed = 0
        for (p in parent) if (!(p in keep) && (parent[p] in keep)) { keep[p] = 1; changed = 1 }
      } while (changed)
      for (p in keep) print p
    }'
}

# Sends TERM to the pids given, waits up to $STOP_WAIT (10) seconds, then KILLs what is left.
stop_pids() {
  local p n=0 alive
  [ $# -eq 0 ] && return 0
  kill -TERM "$@" 2>/dev/null
  while :; do
    alive=""
    for p in "$@"; do [ -d "/proc/$p" ] && ! grep -q '^State:.*Z' "/proc/$p/status" 2>/dev/null && alive="$alive $p"; done
    [ -z "$alive" ] && return 0
    if [ "$n" -ge "$((${STOP_WAIT:-10} * 10))" ]; then
      log "killing$alive"
      # shellcheck disable=SC2086
      kill -KILL $alive 2>/dev/null
      sleep 0.2
      return 0
    fi
    sleep 0.1
    n=$((n + 1))
  done
}

# Prints the last lines of each log of this cluster (on stderr).
log_tails() {
  local f
  for f in "$dir"/log/munged.log "$dir"/log/slurmctld.log "$dir"/log/slurmd.log; do
    [ -s "$f" ] || continue
    echo "---- tail $f" >&2
    tail -n "${1:-25}" "$f" >&2
  done
}
