#!/bin/bash
# Slurm's per-task overhead on the private test cluster (scripts/slurm/start.sh): submits N
# trivial `true` tasks (default 20) as one job array, then as N single jobs, then a chain of N/4
# afterok-dependent jobs, then N/2 `sleep 1` tasks as an array, and prints the seconds from
# submit to all done, per task (polling squeue every 0.1 s). Starts its own cluster in a temp
# dir and stops it at exit. Usage: bench/slurm_overhead.sh [N]
set -u
n=${1:-20}
root=$(cd "$(dirname "$0")/.." && pwd)
state=$(mktemp -d /tmp/emaki-slurm-bench.XXXXXX)
trap '"$root/scripts/slurm/stop.sh" "$state"; rm -rf "$state"' EXIT
env_line=$("$root/scripts/slurm/start.sh" "$state") || exit 1
eval "$env_line"
cd "$state" || exit 1

now() { date +%s.%N; }
# Waits until none of the given job ids is pending or running (0.1 s polls).
wait_jobs() {
  local ids
  ids=$(echo "$*" | tr ' ' ',')
  while [ -n "$(squeue -h -j "$ids" -t PD,R,CG,CF -o %i 2>/dev/null)" ]; do sleep 0.1; done
}
report() { awk -v what="$1" -v n="$2" -v t0="$3" -v t1="$4" \
  'BEGIN { printf "%-28s %3d tasks %7.2f s  %5.2f s/task\n", what, n, t1 - t0, (t1 - t0) / n }'; }
check_ok() {
  local bad
  bad=$(scontrol show job "$@" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | grep -vc COMPLETED)
  [ "$bad" -eq 0 ] || echo "  ($bad tasks not COMPLETED)"
}

t0=$(now)
a=$(sbatch --parsable -o /dev/null -a "0-$((n - 1))" --wrap true)
wait_jobs "$a"
report "array ($a)" "$n" "$t0" "$(now)"
check_ok "$a"

t0=$(now)
ids=""
for _ in $(seq "$n"); do ids="$ids $(sbatch --parsable -o /dev/null --wrap true)"; done
# shellcheck disable=SC2086
wait_jobs $ids
report "single jobs" "$n" "$t0" "$(now)"

k=$(((n + 3) / 4))
t0=$(now)
prev=$(sbatch --parsable -o /dev/null --wrap true)
ids=$prev
for _ in $(seq $((k - 1))); do
  prev=$(sbatch --parsable -o /dev/null -d "afterok:$prev" --wrap true)
  ids="$ids $prev"
done
# shellcheck disable=SC2086
wait_jobs $ids
report "afterok chain" "$k" "$t0" "$(now)"
# Tasks that work: N/2 one-second tasks on all CPUs; the time past the ideal is Slurm's.
m=$(((n + 1) / 2))
cpus=$(sinfo -h -o %c | head -n 1)
t0=$(now)
a=$(sbatch --parsable -o /dev/null -a "0-$((m - 1))" --wrap 'sleep 1')
wait_jobs "$a"
t1=$(now)
report "array of sleep 1 ($a)" "$m" "$t0" "$t1"
awk -v m="$m" -v c="$cpus" -v t0="$t0" -v t1="$t1" 'BEGIN {
  ideal = int((m + c - 1) / c); printf "  ideal %d s on %d CPUs: %.2f s over, %.2f s/task\n", ideal, c, t1 - t0 - ideal, (t1 - t0 - ideal) / m }'
echo "SchedulerParameters: $(scontrol show config | sed -n 's/^SchedulerParameters *= *//p')"
