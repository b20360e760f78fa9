#!/bin/sh
# Fuzz one or every target for a chosen time: fuzz/run.sh SECONDS [TARGET...]
# Builds the `fuzz` preset (clang, ASan+UBSan+libFuzzer), runs each target for SECONDS over its
# corpus and reproducers (new inputs under build/fuzz/work/<target>/), and prints executions
# and coverage from libFuzzer's final lines.
set -e
cd "$(dirname "$0")/.."
secs=${1:-60}; shift || true
targets=${*:-"gltf png exr shot synth_args field kept_fields script_text farm_state confine exemplar_index"}
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"$(nproc)" >/dev/null
for t in $targets; do
  bin=build/fuzz/fuzz/${t}_fuzz
  [ -x "$bin" ] || { echo "fuzz/run.sh: no target $t"; exit 1; }
  work=build/fuzz/work/$t; mkdir -p "$work"
  log=build/fuzz/work/$t.log
  extra=""; [ -d tests/data/hostile/$t ] && extra=tests/data/hostile/$t
  "$bin" -max_total_time="$secs" -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=30 \
    -dict=fuzz/$t.dict -artifact_prefix="$work/" -print_final_stats=1 \
    "$work" fuzz/corpus/$t $extra >"$log" 2>&1 && status=ok || status=FAILED
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1)
  ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1)
  echo "$t: $status, ${secs} s, $execs executions, $cov, $ft (log $log)"
done
