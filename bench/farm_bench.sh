#!/bin/bash
# The bundled production (examples/production: 3 shots at 480x270, 60 frames, 3 layers each)
# through Slurm on this machine, against `emaki run` of each shot in turn, and the scheduler's
# per-task overhead. Prints figures; asserts nothing.
#   bench/farm_bench.sh [EMAKI] [WORK_DIR]
# Three runs over the same shots, each into its own output folders:
#   run     `emaki run SHOT` for each shot in turn (all cores)
#   local   the plan's tasks run here without a scheduler, stage by stage, as many at once as
#           there are cores (xargs -P): the same work and the same parallelism, no Slurm
#   slurm   `emaki farm submit` on the private cluster (scripts/slurm/start.sh), waited for
# The scheduler's per-task overhead: from the tasks' own start/end stamps, the mean time from
# the end of the stage a task waits for to its start, when a CPU was free. (`local` has a
# barrier between stages across all shots where Slurm has one per shot, so slurm - local is
# not an overhead.) Also the CPU-seconds per task kind.
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
emaki=${1:-$root/build/release/apps/emaki/emaki}
work=${2:-/tmp/emaki_farm_bench}
chunk=8
cores=$(nproc)
rm -rf "$work"
mkdir -p "$work"
state=$work/cluster
trap '"$root/scripts/slurm/stop.sh" "$state" >/dev/null 2>&1' EXIT

# The production's shots with absolute paths and their output in $work/$1/.
copy_shots() {
  mkdir -p "$work/$1"
  for s in "$root"/examples/production/*.toml; do
    sed -e "s|\"\.\./|\"$root/examples/|" -e "s|^folder = \"out/|folder = \"$work/$1/|" "$s" \
      >"$work/$1/$(basename "$s")"
  done
}
now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { print b - a }'; }
calc() { awk "BEGIN { printf \"%.2f\", $1 }"; }

copy_shots run
t=$(now)
for s in "$work"/run/*.toml; do "$emaki" run "$s" 2>/dev/null || echo "emaki run $s failed"; done
run_s=$(secs "$t" "$(now)")

copy_shots local
"$emaki" plan "$work"/local/*.toml --chunk $chunk --json >"$work/local/plan.json"
tasks=$(grep -c '"id":' "$work/local/plan.json")
t=$(now)
for kind in prepare passes layer composite previews; do
  /usr/bin/python3 -c '
import json, shlex, sys
for t in json.load(open(sys.argv[1]))["tasks"]:
    if t["kind"] == sys.argv[2]: print(" ".join(shlex.quote(a) for a in t["argv"]))
' "$work/local/plan.json" "$kind" | xargs -P "$cores" -I{} sh -c '{} 2>/dev/null || echo "task failed: {}"'
done
local_s=$(secs "$t" "$(now)")

copy_shots slurm
eval "$("$root/scripts/slurm/start.sh" "$state")"
t=$(now)
"$emaki" farm submit "$work"/slurm/*.toml --chunk $chunk 2>/dev/null
while [ -n "$(squeue -h -o %i)" ]; do sleep 0.2; done
slurm_s=$(secs "$t" "$(now)")
"$emaki" farm status "$work"/slurm/*.toml --chunk $chunk | tail -n 1

same=identical
for s in sh010 sh020 sh030; do
  a=$(cd "$work/run/$s" && find . -type f ! -name '.emaki*' ! -path './farm/*' ! -path './passes/*' -exec md5sum {} + | sort -k 2)
  b=$(cd "$work/slurm/$s" && find . -type f ! -name '.emaki*' ! -path './farm/*' ! -path './passes/*' -exec md5sum {} + | sort -k 2)
  [ "$a" = "$b" ] || same="DIFFERENT ($s)"
done

# Dispatch latency: per task, its start minus the end of the last task of the stage before it
# (its dependency), for tasks that started within 5 s of it (a CPU was free).
latency=$(/usr/bin/python3 - "$work/slurm" <<'PY'
import glob, os, sys
order = ["prepare", "passes", "layer", "composite", "previews"]
lat = []
for farm in glob.glob(os.path.join(sys.argv[1], "*", "farm", "status")):
    stamps = {}
    for f in glob.glob(os.path.join(farm, "*.start")):
        task = os.path.basename(f)[:-6]
        end = f[:-6] + ".end"
        if os.path.exists(end):
            stamps[task] = (float(open(f).read()), float(open(end).read()))
    kind = lambda t: t.split(".")[1]
    for t, (start, _) in stamps.items():
        k = order.index(kind(t))
        if k == 0: continue
        ends = [e for u, (_, e) in stamps.items() if kind(u) == order[k - 1]]
        if not ends: continue
        d = start - max(ends)
        if 0 <= d < 5: lat.append(d)
print(f"{sum(lat) / len(lat):.2f} s mean over {len(lat)} tasks" if lat else "n/a")
cpu = {}
for farm in glob.glob(os.path.join(sys.argv[1], "*", "farm", "status")):
    for f in glob.glob(os.path.join(farm, "*.start")):
        end = f[:-6] + ".end"
        k = os.path.basename(f).split(".")[1]
        if os.path.exists(end):
            n, s = cpu.get(k, (0, 0.0))
            cpu[k] = (n + 1, s + float(open(end).read()) - float(open(f).read()))
print("task seconds: " + ", ".join(f"{k} {n} x {s / n:.1f} s" for k, (n, s) in sorted(cpu.items())))
PY
)
echo "production: 3 shots, 480x270, 60 frames, 3 layers; $tasks tasks (chunk $chunk), $cores cores"
printf '%-44s %8.1f s\n' "emaki run of each shot in turn" "$run_s"
printf '%-44s %8.1f s\n' "plan's tasks here, no scheduler (xargs -P$cores)" "$local_s"
printf '%-44s %8.1f s\n' "emaki farm submit on Slurm, to all done" "$slurm_s"
echo "slurm vs emaki run: $(calc "$slurm_s / $run_s")x wall time"
echo "Slurm's per-task overhead (dispatch after the stage waited for ends): $latency"
echo "outputs, slurm vs emaki run: $same"
