#!/bin/bash
# A production through a real Slurm (scripts/slurm/start.sh: a private one-node cluster with its
# own munged, slurmctld and slurmd): `emaki farm submit` of two small shots (160x90, 6 frames,
# three layers: two temporal, one chunked), waited for with a bounded timeout, and
#   1. every output file is byte-identical to `emaki run` of the same shot on one machine;
#   2. a temporal layer task cancelled mid-run (scancel) leaves its dependants unrun, and
#      submitting again completes the shot to identical outputs;
#   3. a shot with a bad input (a truncated glTF) fails its task, its compositing never runs,
#      `emaki farm status` names the failing task and its error line, and the other shot of the
#      same submission completes.
# Along the way: `submit` prints its job ids, `status` plans with the recorded chunk, its --json
# and its exit code (0 all done, 4 after the cancelled task).
# The cluster stops however the test ends. Exits 77 (CTest skip) without Slurm.
# Usage: farm_slurm_test.sh REPO_ROOT EMAKI_BINARY WORK_DIR
set -u
root=$1
emaki=$2
work=$3
for b in munged slurmctld slurmd sbatch squeue scontrol scancel sinfo; do
  if ! command -v "$b" >/dev/null; then
    echo "SKIP: '$b' not installed (scripts/setup.sh installs slurm-wlm and munge)"
    exit 77
  fi
done

state=$work/cluster
failures=0
fail() {
  echo "FAIL: $*"
  failures=$((failures + 1))
}
finish() {
  local rc=$?
  [ "$failures" -gt 0 ] && rc=1
  if [ "$rc" -ne 0 ]; then
    for f in "$work"/*/farm/logs/*.log; do
      [ -f "$f" ] && { echo "---- $f"; tail -n 5 "$f"; }
    done
    [ -f "$state/log/slurmctld.log" ] && { echo "---- slurmctld"; tail -n 20 "$state/log/slurmctld.log"; }
  fi
  "$root/scripts/slurm/stop.sh" "$state"
  exit "$rc"
}
trap finish EXIT
trap 'echo "interrupted"; exit 1' INT TERM

"$root/scripts/slurm/stop.sh" "$state" 2>/dev/null
rm -rf "$work"
mkdir -p "$work" || exit 1
env_line=$("$root/scripts/slurm/start.sh" "$state") || exit 1
eval "$env_line"

# shot NAME FRAMES SIZE [SCENE]: examples/production/sh010.toml made small, output in $work/NAME.
shot() {
  local scene=${4:-$root/examples/data/Fox.glb}
  sed -e "s|\"../data/Fox.glb\"|\"$scene\"|" -e "s|\"../data/|\"$root/examples/data/|" \
    -e "s|\"../stylit/|\"$root/examples/stylit/|" -e "s|^frames = .*|frames = [0, $2]|" \
    -e "s|^size = .*|size = [$3]|" -e "s|^folder = .*|folder = \"$work/$1\"|" \
    "$root/examples/production/sh010.toml" >"$work/$1.toml"
}

# Waits (at most $1 s) until the queue is empty.
wait_queue() {
  local end=$((SECONDS + $1))
  while [ -n "$(squeue -h -o %i)" ]; do
    [ $SECONDS -ge $end ] && { fail "queue not empty after $1 s: $(squeue -h -o '%i %j %T %r' | head)"; return 1; }
    sleep 0.2
  done
}

# The files two output folders must share byte for byte (the farm's own files aside).
outputs_md5() {
  (cd "$1" && find . -type f ! -name '.emaki*' ! -path './farm/*' ! -path './passes/*' \
    -exec md5sum {} + | sort -k 2)
}
same_outputs() {
  local a b
  a=$(outputs_md5 "$1")
  b=$(outputs_md5 "$2")
  [ -n "$a" ] || { fail "$1 holds no outputs"; return; }
  if [ "$a" = "$b" ]; then
    echo "identical: $2 = $1 ($(echo "$a" | wc -l) files)"
  else
    fail "$2 differs from $1:"
    diff <(echo "$a") <(echo "$b") | head
  fi
}

# --- 1. two shots through Slurm equal `emaki run`
for s in a b; do
  shot "$s" 5 "160, 90"
  sed "s|folder = \"$work/$s\"|folder = \"$work/ref_$s\"|" "$work/$s.toml" >"$work/ref_$s.toml"
  "$emaki" run "$work/ref_$s.toml" --threads 1 2>/dev/null || fail "emaki run ref_$s"
done
# b's output folder holds a space, a Slurm pattern (%j) and shell syntax: it stays out of the
# #SBATCH lines and is one quoted word in the script, so none of it is expanded or run.
b_out="$work/b 50%j \$(touch $work/pwned)"
sed -i "s|folder = \"$work/b\"|folder = \"$b_out\"|" "$work/b.toml"
t0=$SECONDS
"$emaki" farm submit "$work/a.toml" "$work/b.toml" --chunk 3 || fail "submit a b"
wait_queue 300
echo "two shots through Slurm: $((SECONDS - t0)) s"
status=$("$emaki" farm status "$work/a.toml" "$work/b.toml" --chunk 3)
echo "$status" | tail -n 1
echo "$status" | grep -vE ' done |^[0-9]+ done$' && fail "a task of a or b is not done"
# The same as JSON, and an exit code saying all is done (no --chunk: submit recorded it).
"$emaki" farm status "$work/a.toml" "$work/b.toml" --json >"$work/status.json"
rc=$?
[ "$rc" -eq 0 ] || fail "status --json of finished shots exits $rc"
/usr/bin/python3 -c 'import json, sys; t = json.load(open(sys.argv[1])); assert t and all(x["state"] == "done" and x["job"] for x in t)' \
  "$work/status.json" || fail "status --json: $(head -c 300 "$work/status.json")"
same_outputs "$work/ref_a" "$work/a"
same_outputs "$work/ref_b" "$b_out"
[ -e "$work/pwned" ] && fail "a command in b's folder name ran"
ls "$b_out/farm/logs/"slurm-*_*.log >/dev/null 2>&1 || fail "no Slurm log in b's farm/logs"
# Submitting a finished shot again submits nothing.
again=$("$emaki" farm submit "$work/a.toml" --chunk 3 2>&1)
echo "$again" | grep -q "0 tasks in 0 job arrays submitted" || fail "resubmitting a finished shot: $again"

# --- 2. a temporal layer task cancelled mid-run, then submitted again
shot c 11 "320, 180"
sed "s|folder = \"$work/c\"|folder = \"$work/ref_c\"|" "$work/c.toml" >"$work/ref_c.toml"
"$emaki" run "$work/ref_c.toml" --threads 1 2>/dev/null || fail "emaki run ref_c"
ids=$("$emaki" farm submit "$work/c.toml" --chunk 4) || fail "submit c"
# One line per job array queued: JOBID, job name, tasks.
echo "$ids" | awk -F'\t' 'NF != 3 || $1 !~ /^[0-9]+$/ || $2 !~ /^emaki:c-/ { bad = 1 } END { exit bad }' ||
  fail "submit's job ids: $ids"
running=""
end=$((SECONDS + 120))
while [ -z "$running" ] && [ $SECONDS -lt $end ]; do
  running=$("$emaki" farm status "$work/c.toml" --chunk 4 | awk '$1 ~ /^c-[0-9a-f]+\.layer\.base\.0-11$/ && $2 == "running" { print $3 }')
  [ -z "$running" ] && sleep 0.1
done
[ -n "$running" ] || fail "c.layer.base.0-11 never ran"
sleep 1 # a frame or two into its chain
scancel "$running"
echo "cancelled c.layer.base.0-11 (job $running) while it ran"
wait_queue 120
status=$("$emaki" farm status "$work/c.toml" --chunk 4)
echo "$status" | grep -qE "^c-[0-9a-f]+\.layer\.base\.0-11 +failed +.*stopped while running" || fail "the cancelled task is not reported stopped while running"
echo "$status" | grep -E '^c-[0-9a-f]+\.composite' | grep -q 'done' && fail "compositing ran after a cancelled layer"
"$emaki" farm status "$work/c.toml" >/dev/null
rc=$?
[ "$rc" -eq 4 ] || fail "status after a cancelled task exits $rc, not 4"
echo "$status" | tail -n 1
leftovers=$(find "$work/c" -name '.*.emaki-tmp-*' | wc -l)
echo "temporaries the cancelled task left: $leftovers"
# One for certain, as a task killed while writing frame 5 leaves it.
echo partial >"$work/c/layers/base/.base_0005.emaki-tmp-0123456789abcdef.exr"
"$emaki" farm submit "$work/c.toml" --chunk 4 || fail "submit c again"
left=$(find "$work/c" -name '.*.emaki-tmp-*')
[ -z "$left" ] || fail "resubmitting left the cancelled task's temporaries: $left"
wait_queue 300
# status plans with the chunk the shot was submitted with (farm/chunk), or refuses another one.
"$emaki" farm status "$work/c.toml" | grep -vE ' done |^[0-9]+ done$' && fail "c not done after resubmitting"
other=$("$emaki" farm status "$work/c.toml" --chunk 3 2>&1) && fail "status with another chunk: $other"
echo "$other" | grep -q -- "--chunk.*submitted with chunk 4, not 3" || fail "status with another chunk: $other"
same_outputs "$work/ref_c" "$work/c"

# --- 3. a shot with a bad input beside a good one
head -c 2000 "$root/examples/data/Fox.glb" >"$work/broken.glb"
shot bad 5 "160, 90" "$work/broken.glb"
shot d 5 "160, 90"
sed "s|folder = \"$work/d\"|folder = \"$work/ref_d\"|" "$work/d.toml" >"$work/ref_d.toml"
sed -i 's|^start = .*|start = 0.5|' "$work/d.toml" "$work/ref_d.toml"
"$emaki" run "$work/ref_d.toml" --threads 1 2>/dev/null || fail "emaki run ref_d"
"$emaki" farm submit "$work/bad.toml" "$work/d.toml" --chunk 3 || fail "submit bad d"
wait_queue 300
status=$("$emaki" farm status "$work/bad.toml" "$work/d.toml" --chunk 3)
echo "$status" | grep -E '^bad-[0-9a-f]+\.'
echo "$status" | grep -E '^bad-[0-9a-f]+\.prepare +failed .*bad-[0-9a-f]+\.prepare\.log: .*error' >/dev/null ||
  fail "status does not name bad.prepare as failed with its error line"
echo "$status" | grep -E '^bad-[0-9a-f]+\.composite' | grep -vq 'not run' && fail "bad's compositing ran"
echo "$status" | grep -E '^d-[0-9a-f]+\.' | grep -v ' done ' && fail "shot d did not complete beside bad"
same_outputs "$work/ref_d" "$work/d"
[ "$failures" -eq 0 ] && echo "PASS"
