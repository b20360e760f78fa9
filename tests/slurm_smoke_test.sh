#!/bin/bash
# Slurm smoke test on a private one-node cluster (scripts/slurm/start.sh): a 2-task job array
# whose tasks write files and run side by side, an afterok job on that array, a job that fails
# (exit 3) whose afterok dependent must never run, and a long job cancelled with scancel. Waits
# with bounded timeouts (squeue polled every 0.2 s), checks every job's end state and output,
# and stops the cluster however it ends. Exits 77 (CTest skip) when Slurm is not installed or
# when not root.
# Usage: slurm_smoke_test.sh REPO_ROOT WORK_DIR
set -u
root=$1
work=$2
for b in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
  if ! command -v "$b" >/dev/null; then
    echo "SKIP: '$b' not installed (scripts/setup.sh installs slurm-wlm and munge)"
    exit 77
  fi
done

if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: the test cluster's slurmd needs root (CI runs as root)"
  exit 77
fi

state=$work/cluster
out=$work/out
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
finish() {
  local rc=$?
  [ "$failures" -gt 0 ] && rc=1
  if [ "$rc" -ne 0 ] && [ -d "$state/log" ]; then
    for f in "$state"/log/slurmctld.log "$state"/log/slurmd.log; do
      echo "---- tail $f"
      grep -vE 'pmix|MPI' "$f" | tail -n 30
    done
  fi
  "$root/scripts/slurm/stop.sh" "$state"
  exit "$rc"
}
trap finish EXIT
trap 'echo "interrupted"; exit 1' INT TERM

"$root/scripts/slurm/stop.sh" "$state" 2>/dev/null # a previous run killed mid-way
rm -rf "$work"
mkdir -p "$out" || exit 1
env_line=$("$root/scripts/slurm/start.sh" "$state") || exit 1
eval "$env_line"
echo "cluster: $env_line"
[ "$(scontrol show config | sed -n 's/^SLURM_CONF *= *//p')" = "$state/slurm.conf" ] ||
  fail "scontrol does not read $state/slurm.conf"

# Waits (bounded by $1 s) until none of the jobs $2... is pending, running or completing.
wait_done() {
  local limit=$1 ids
  shift
  ids=$(echo "$*" | tr ' ' ',')
  for _ in $(seq $((limit * 5))); do
    [ -z "$(squeue -h -j "$ids" -t PD,R,CG,CF,S -o %i 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  fail "jobs $ids not done after ${limit}s:"
  squeue -j "$ids" -o '%i %T %r'
  return 1
}
# The states of job $1 (one line per array task), sorted: e.g. "COMPLETED COMPLETED".
states() { squeue -h -t all -j "$1" -o %T 2>/dev/null | sort | tr '\n' ' ' | sed 's/ $//'; }
expect_state() {
  local got
  got=$(states "$1")
  [ "$got" = "$2" ] || fail "$3: job $1 is '$got', expected '$2'"
}
submit() {
  local id
  id=$(sbatch --parsable "$@") || { fail "sbatch $*"; echo 0; return; }
  echo "${id%%;*}"
}

# 1. A 2-task array; each task records its start and end, so they must overlap (2 CPUs, one each).
arr=$(submit -J smoke-array -a 0-1 -o "$out/array_%a.log" --wrap \
  "date +%s.%N > $out/start_\$SLURM_ARRAY_TASK_ID; echo task \$SLURM_ARRAY_TASK_ID > $out/task_\$SLURM_ARRAY_TASK_ID.txt; sleep 2; date +%s.%N > $out/end_\$SLURM_ARRAY_TASK_ID")
after=$(submit -J smoke-after -d "afterok:$arr" -o "$out/after.log" --wrap \
  "cat $out/task_0.txt $out/task_1.txt > $out/joined.txt")
# 2. A failing job; its afterok dependent must be cancelled, never run.
bad=$(submit -J smoke-fail -o "$out/fail.log" --wrap 'echo failing; exit 3')
never=$(submit -J smoke-never -d "afterok:$bad" -o "$out/never.log" --wrap "touch $out/never.txt")
# 3. A long job, cancelled once it runs.
long=$(submit -J smoke-long -o "$out/long.log" --wrap "touch $out/long_started; sleep 300; touch $out/long_finished")
echo "jobs: array $arr, afterok $after, failing $bad, never $never, long $long"

running=""
for _ in $(seq 150); do
  [ "$(states "$long")" = RUNNING ] && [ -e "$out/long_started" ] && { running=1; break; }
  sleep 0.2
done
[ -n "$running" ] || fail "long job $long not running after 30s (state '$(states "$long")')"
scancel "$long" || fail "scancel $long"

wait_done 60 "$arr" "$after" "$bad" "$never" "$long"

expect_state "$arr" "COMPLETED COMPLETED" "array"
expect_state "$after" COMPLETED "afterok job"
expect_state "$bad" FAILED "failing job"
expect_state "$never" CANCELLED "dependent of the failing job"
expect_state "$long" CANCELLED "cancelled long job"
exit_code=$(scontrol show job "$bad" | grep -o ' ExitCode=[0-9:]*' | cut -d= -f2)
[ "$exit_code" = "3:0" ] || fail "failing job's ExitCode is '$exit_code', expected 3:0"
reason=$(squeue -h -t all -j "$never" -o %r)
[ "$reason" = DependencyNeverSatisfied ] || fail "dependent's reason is '$reason', expected DependencyNeverSatisfied"

for i in 0 1; do
  [ "$(cat "$out/task_$i.txt" 2>/dev/null)" = "task $i" ] || fail "array task $i wrote no task_$i.txt"
done
[ "$(cat "$out/joined.txt" 2>/dev/null)" = "$(printf 'task 0\ntask 1')" ] ||
  fail "afterok job did not see both array outputs (joined.txt: '$(cat "$out/joined.txt" 2>/dev/null)')"
if [ -s "$out/start_0" ] && [ -s "$out/start_1" ] && [ -s "$out/end_0" ] && [ -s "$out/end_1" ]; then
  awk -v s0="$(cat "$out/start_0")" -v s1="$(cat "$out/start_1")" -v e0="$(cat "$out/end_0")" \
    -v e1="$(cat "$out/end_1")" 'BEGIN { exit !((s0 > s1 ? s0 : s1) < (e0 < e1 ? e0 : e1)) }' ||
    fail "the two array tasks did not run at the same time"
else
  fail "array tasks left no start/end times"
fi
[ ! -e "$out/never.txt" ] || fail "the dependent of the failing job ran"
[ ! -e "$out/long_finished" ] || fail "the cancelled job ran to its end"
[ "$(cat "$out/fail.log" 2>/dev/null)" = failing ] || fail "failing job's output missing"

if [ "$failures" -eq 0 ]; then
  echo "PASS: array, afterok, failed dependency cancelled, scancel"
fi
