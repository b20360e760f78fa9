#!/bin/bash
# The bundled production (examples/production: 3 shots at 480x270, 60 frames, 3 layers each), or
# the shots FARM_BENCH_SHOTS names: what the farm's tasks cost against `emaki run` of the same
# shots, in CPU-seconds and wall time per stage, and through Slurm on this machine. Prints
# figures; asserts nothing.
#   bench/farm_bench.sh [EMAKI] [WORK_DIR]      (FARM_BENCH_SLURM=0: leave Slurm out)
#   FARM_BENCH_SHOTS="examples/fox/shot.toml examples/town/shot.toml" bench/farm_bench.sh
#     (other shots than the production's, paths from the repository's root)
#   FARM_BENCH_REPEAT=3 bench/farm_bench.sh  (run and tasks measured 3 times, alternated)
#   FARM_BENCH_CALLGRIND=1 FARM_BENCH_SLURM=0 bench/farm_bench.sh
#     (every command under valgrind's callgrind: user-space instructions, in billions, instead
#     of CPU seconds; the same figure under any load and on any machine of the architecture,
#     about 50 times slower. Kernel work, the page faults and the pass cache's writes, is not
#     counted, nor the run's split by stage, which comes from its clock; ffmpeg's, a child, in
#     neither.)
# Each run writes its own output folders (N: the repetition):
#   runN    `emaki run SHOT --threads 1` for each shot in turn
#   tasksN  the plan's tasks (`--threads 1`) run here one by one, stage by stage, without a
#           scheduler: the work a farm's nodes do, each task's CPU time (user + system) summed
#           per stage. Its outputs must be byte-identical to `run`'s.
#   slurm   `emaki farm submit` on the private cluster (scripts/slurm/start.sh), waited for
# The scheduler's per-task overhead: from the tasks' own start/end stamps, the mean time from
# the end of the stage a task waits for to its start, when a CPU was free.
set -u
root=$(cd "$(dirname "$0")/.." && pwd)
emaki=${1:-$root/build/release/apps/emaki/emaki}
work=${2:-/tmp/emaki_farm_bench}
use_slurm=${FARM_BENCH_SLURM:-1}
callgrind=${FARM_BENCH_CALLGRIND:-0}
cost=CPU
[ "$callgrind" = 1 ] && cost=Ginstr
chunk=8
cores=$(nproc)
rm -rf "$work"
mkdir -p "$work"
state=$work/cluster
trap '[ "$use_slurm" = 1 ] && "$root/scripts/slurm/stop.sh" "$state" >/dev/null 2>&1' EXIT

# The shots (the production's unless FARM_BENCH_SHOTS names others), each copied to
# $work/$1/NAME/ beside links to its folder's other files, its "../" paths made absolute and its
# output folder under $work/$1/NAME/.
shots=${FARM_BENCH_SHOTS:-$(cd "$root" && echo examples/production/*.toml)}
shot_name() { local d; d=$(basename "$(dirname "$1")"); echo "$d-$(basename "$1" .toml)"; }
copy_shots() {
  local s src dest f
  for s in $shots; do
    src=$root/$s dest=$work/$1/$(shot_name "$s")
    mkdir -p "$dest"
    for f in "$(dirname "$src")"/*; do
      case $f in *.toml | */out) ;; *) ln -s "$f" "$dest/" ;; esac
    done
    sed -e "s|\"\.\./|\"$(dirname "$(dirname "$src")")/|" \
      -e "s|^folder = \"out[^\"]*\"|folder = \"$dest/out\"|" "$src" >"$dest/shot.toml"
  done
}
shot_files() { echo "$work/$1"/*/shot.toml; }
now() { date +%s.%N; }
secs() { awk -v a="$1" -v b="$2" 'BEGIN { print b - a }'; }
calc() { awk "BEGIN { printf \"%.2f\", $1 }"; }
# timed CMD...: runs it, prints "WALL CPU SYSTEM" (CPU = user + system, seconds; with
# FARM_BENCH_CALLGRIND=1 the instructions callgrind counted, in billions, instead, and 0).
timed() {
  if [ "$callgrind" = 1 ]; then
    rm -f "$work"/callgrind.*
    /usr/bin/time -f "%e" -o "$work/time" valgrind -q --tool=callgrind \
      --callgrind-out-file="$work/callgrind.%p" "$@" >/dev/null 2>"$work/stderr" ||
      echo "failed: $* ($(tail -n 1 "$work/stderr"))" >&2
    awk -v w="$(tail -n 1 "$work/time")" '$1 == "summary:" { n += $2 }
      END { printf "%.2f %.3f 0\n", w, n / 1e9 }' "$work"/callgrind.*
    return
  fi
  /usr/bin/time -f "%e %U %S" -o "$work/time" "$@" >/dev/null 2>"$work/stderr" ||
    echo "failed: $* ($(tail -n 1 "$work/stderr"))" >&2
  tail -n 1 "$work/time" | awk '{ printf "%.2f %.2f %.2f\n", $1, $2 + $3, $3 }'
}
# The MP4 is left out: libx264 here encodes the same PNGs to different bytes from one run to the
# next (two `emaki task previews` of one folder differed).
outputs_md5() {
  (cd "$1" && find . -type f ! -name '.emaki*' ! -path './farm/*' ! -path './passes/*' \
    ! -path './references/*' ! -name preview.mp4 -exec md5sum {} + | sort -k 2)
}
# same DIR_A DIR_B: "identical" when every shot's outputs match byte for byte.
same() {
  local r=identical s
  for s in $shots; do
    s=$(shot_name "$s")
    [ "$(outputs_md5 "$1/$s/out")" = "$(outputs_md5 "$2/$s/out")" ] || r="DIFFERENT ($s)"
  done
  echo "$r"
}

# measure_run DIR: `emaki run` of each shot into DIR; adds to run_wall, run_cpu, and per stage
# (its --timings, named as the tasks' kinds) to run_stage_wall, run_stage_cpu.
declare -A stage_wall stage_cpu stage_n run_stage_wall run_stage_cpu
for kind in prepare passes layer composite previews; do
  stage_wall[$kind]=0 stage_cpu[$kind]=0 stage_n[$kind]=0
  run_stage_wall[$kind]=0 run_stage_cpu[$kind]=0
done
measure_run() {
  local s w c k kind
  copy_shots "$1"
  for s in $(shot_files "$1"); do
    read -r w c k < <(timed "$emaki" run "$s" --threads 1 --timings)
    run_wall=$(calc "$run_wall + $w") run_cpu=$(calc "$run_cpu + $c") run_sys=$(calc "$run_sys + $k")
    [ "$callgrind" = 1 ] && continue  # the stage clock's CPU seconds are not instructions
    while read -r kind w c; do
      run_stage_wall[$kind]=$(calc "${run_stage_wall[$kind]} + $w")
      run_stage_cpu[$kind]=$(calc "${run_stage_cpu[$kind]} + $c")
    done < <(awk '$1 == "emaki" && $2 == "run:" && $3 ~ /^(prepare|passes|layers|composite|previews)$/ {
      sub(/^layers$/, "layer", $3); print $3, $4, $5 }' "$work/stderr")
  done
}
# The tasks run as the farm's batch scripts run them (src/farm/slurm.cpp): glibc's huge-page
# tunable named, so that no task starts itself again to add it.
case ":${GLIBC_TUNABLES-}:" in
  *:glibc.malloc.hugetlb=*) task_tunables=$GLIBC_TUNABLES ;;
  *) task_tunables=${GLIBC_TUNABLES:+$GLIBC_TUNABLES:}glibc.malloc.hugetlb=1 ;;
esac
# measure_tasks DIR: the plan's tasks into DIR, stage by stage; adds to stage_wall, stage_cpu.
measure_tasks() {
  local dir=$1 kind line w c k  # `set --` below takes the positional parameters
  copy_shots "$dir"
  "$emaki" plan $(shot_files "$dir") --chunk $chunk --threads 1 --json >"$work/$dir/plan.json"
  tasks=$(grep -c '"id":' "$work/$dir/plan.json")
  for kind in prepare passes layer composite previews; do
    stage_n[$kind]=0
    while IFS= read -r -d '' line; do
      eval "set -- $line"
      read -r w c k < <(GLIBC_TUNABLES=$task_tunables timed "$@")
      tasks_sys=$(calc "$tasks_sys + $k")
      stage_wall[$kind]=$(calc "${stage_wall[$kind]} + $w")
      stage_cpu[$kind]=$(calc "${stage_cpu[$kind]} + $c")
      stage_n[$kind]=$((stage_n[$kind] + 1))
    done < <(/usr/bin/python3 -c '
import json, shlex, sys
for t in json.load(open(sys.argv[1]))["tasks"]:
    if t["kind"] == sys.argv[2]: sys.stdout.write(" ".join(shlex.quote(a) for a in t["argv"]) + "\0")
' "$work/$dir/plan.json" "$kind")
  done
}
# stage_total stage_wall|stage_cpu: the sum over the stages.
stage_total() {
  local -n per=$1
  local kind sum=0
  for kind in prepare passes layer composite previews; do
    sum=$(calc "$sum + ${per[$kind]}")
  done
  echo "$sum"
}

# FARM_BENCH_REPEAT=N measures both N times, alternating which goes first, each into fresh
# folders: one machine's CPU time moves by more than the ratio's margin from one run to the next.
reps=${FARM_BENCH_REPEAT:-1}
run_wall=0 run_cpu=0 run_sys=0 tasks_sys=0 ratios="" run_each="" tasks_each=""
same_all=identical
for ((i = 1; i <= reps; i++)); do
  r0=$run_cpu t0=$(stage_total stage_cpu)
  if ((i % 2)); then
    measure_run run$i
    measure_tasks tasks$i
  else
    measure_tasks tasks$i
    measure_run run$i
  fi
  ratios="$ratios $(calc "($(stage_total stage_cpu) - $t0) / ($run_cpu - $r0)")"
  run_each="$run_each $(calc "$run_cpu - $r0")" tasks_each="$tasks_each $(calc "$(stage_total stage_cpu) - $t0")"
  r=$(same "$work/run$i" "$work/tasks$i")
  [ "$r" = identical ] || same_all=$r
done
mean() { calc "$1 / $reps"; }
tasks_wall=$(stage_total stage_wall) tasks_cpu=$(stage_total stage_cpu)

echo "shots: $shots; $tasks tasks (chunk $chunk, 1 thread each)"
[ "$reps" = 1 ] || echo "mean of $reps repetitions"
# Per stage: `emaki run`'s own split (--timings; the process's start and exit fall outside it)
# against the tasks of that kind, each a whole process.
printf '%-22s %9s %9s %13s %13s %9s\n' "stage" "run wall" "run $cost" "tasks wall" \
  "tasks $cost" "$cost ratio"
for kind in prepare passes layer composite previews; do
  ratio=$(awk -v t="${stage_cpu[$kind]}" -v r="${run_stage_cpu[$kind]}" \
    'BEGIN { if (r > 0) printf "%.2fx", t / r; else print "n/a" }')
  printf '%-22s %9.1f %9.1f %13.1f %13.1f %9s\n' "$kind (${stage_n[$kind]} tasks)" \
    "$(mean "${run_stage_wall[$kind]}")" "$(mean "${run_stage_cpu[$kind]}")" \
    "$(mean "${stage_wall[$kind]}")" "$(mean "${stage_cpu[$kind]}")" "$ratio"
done
printf '%-22s %9.1f %9.1f %13.1f %13.1f %9s\n' "all (whole processes)" "$(mean "$run_wall")" \
  "$(mean "$run_cpu")" "$(mean "$tasks_wall")" "$(mean "$tasks_cpu")" \
  "$(calc "$tasks_cpu / $run_cpu")x"
if [ "$callgrind" = 1 ]; then
  echo "tasks vs emaki run: $(calc "$tasks_cpu / $run_cpu")x user-space instructions (callgrind)"
else
  echo "tasks vs emaki run: $(calc "$tasks_cpu / $run_cpu")x CPU time"
  # The kernel's part (page faults, the pass cache's writes): callgrind does not count it.
  echo "of which system time: run $(mean "$run_sys") s, tasks $(mean "$tasks_sys") s;" \
    "user time alone $(calc "($tasks_cpu - $tasks_sys) / ($run_cpu - $run_sys)")x"
fi
if [ "$reps" != 1 ]; then
  echo "per repetition:$ratios; median $(printf '%s\n' $ratios | sort -n |
    awk '{ v[NR] = $1 } END { printf "%.2f", NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }')"
  # Another process on the machine only ever adds to a measured CPU time: each side's least
  # over the repetitions is the figure the machine's load moves least.
  least() { printf '%s\n' $1 | sort -n | head -n 1; }
  echo "least of $reps repetitions: run $(least "$run_each") $cost, tasks $(least "$tasks_each")" \
    "$cost: $(calc "$(least "$tasks_each") / $(least "$run_each")")x"
fi
echo "outputs (but the MP4), tasks vs emaki run: $same_all"
[ "$use_slurm" = 1 ] || exit 0

copy_shots slurm
eval "$("$root/scripts/slurm/start.sh" "$state")"
t=$(now)
"$emaki" farm submit $(shot_files slurm) --chunk $chunk 2>/dev/null
while [ -n "$(squeue -h -o %i)" ]; do sleep 0.2; done
slurm_s=$(secs "$t" "$(now)")
"$emaki" farm status $(shot_files slurm) --chunk $chunk | tail -n 1

# Dispatch latency: per task, its start minus the end of the last task of the stage before it
# (its dependency), for tasks that started within 5 s of it (a CPU was free).
latency=$(/usr/bin/python3 - "$work/slurm" <<'PY'
import glob, os, sys
order = ["prepare", "passes", "layer", "composite", "previews"]
lat = []
for farm in glob.glob(os.path.join(sys.argv[1], "*", "out", "farm", "status")):
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
for farm in glob.glob(os.path.join(sys.argv[1], "*", "out", "farm", "status")):
    for f in glob.glob(os.path.join(farm, "*.start")):
        end = f[:-6] + ".end"
        k = os.path.basename(f).split(".")[1]
        if os.path.exists(end):
            n, s = cpu.get(k, (0, 0.0))
            cpu[k] = (n + 1, s + float(open(end).read()) - float(open(f).read()))
print("task seconds: " + ", ".join(f"{k} {n} x {s / n:.1f} s" for k, (n, s) in sorted(cpu.items())))
PY
)
printf '%-44s %8.1f s\n' "emaki farm submit on Slurm ($cores cores), to all done" "$slurm_s"
echo "slurm vs emaki run (1 thread, one shot after another): $(calc "$slurm_s * $reps / $run_wall")x wall time"
echo "Slurm's per-task overhead (dispatch after the stage waited for ends): $latency"
echo "outputs (but the MP4), slurm vs emaki run: $(same "$work/run1" "$work/slurm")"
