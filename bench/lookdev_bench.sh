#!/bin/sh
# emaki lookdev's figure: the seconds from saving the painting to the new preview frame written
# (GET /api/status's generation moves on; the page asks for it every 0.1 s, then loads the
# frame), for the Fox example at --scale 0.5 (480x270), frame 0, after a first run that made the
# reference passes. Prints the first run, then SAVES saves (default 3), one line each, with the
# CPU seconds lookdev used from the save to the frame. The status is asked for every 20 ms here,
# by curl: on 2 cores that takes a little from lookdev itself.
#   sh bench/lookdev_bench.sh [EMAKI] [SAVES]
set -e
root=$(cd "$(dirname "$0")/.." && pwd)
emaki=${1:-$root/build/release/apps/emaki/emaki}
saves=${2:-3}
work=$(mktemp -d /tmp/emaki_lookdev_bench.XXXXXX)
port=$((20000 + $$ % 20000))
cp "$root/examples/stylit/source_style.png" "$work/painting.png"
sed -e "s#\"../data/#\"$root/examples/data/#; s#\"../stylit/source_style.png\"#\"painting.png\"#" \
  "$root/examples/fox/shot.toml" > "$work/shot.toml"
"$emaki" lookdev "$work/shot.toml" --frames 0 --scale 0.5 --port "$port" \
  > "$work/url" 2> "$work/log" &
pid=$!
trap 'kill $pid 2>/dev/null; wait $pid 2>/dev/null; rm -rf "$work"' EXIT
status() { curl -s "http://127.0.0.1:$port/api/status" || true; }
# The CPU seconds lookdev has used (user + system, /proc/PID/stat fields 14 and 15): on a shared
# machine they say more than the wall seconds.
cpu() { awk -v hz="$(getconf CLK_TCK)" '{ printf "%.2f", ($14 + $15) / hz }' "/proc/$pid/stat"; }
wait_generation() {
  while ! status | grep -q "\"generation\":$1,"; do
    kill -0 $pid 2>/dev/null || { cat "$work/log"; exit 1; }
    sleep 0.02
  done
}
wait_generation 1
echo "first run (reference passes included): $(status | sed 's/.*"seconds":\([0-9.]*\).*/\1/') s"
g=1
while [ $g -le "$saves" ]; do
  cp "$work/painting.png" "$work/painting.tmp.png"
  c0=$(cpu)
  t0=$(date +%s.%N)
  mv "$work/painting.tmp.png" "$work/painting.png"
  g=$((g + 1))
  wait_generation $g
  t1=$(date +%s.%N)
  run=$(status | sed 's/.*"seconds":\([0-9.]*\).*/\1/')
  echo "save $((g - 1)): save to frame written $(echo "$t1 - $t0" | bc) s (run $run s," \
    "CPU $(echo "$(cpu) - $c0" | bc) s)"
done
