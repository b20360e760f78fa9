#!/bin/sh
# emaki lookdev end to end: a small Fox shot (96x54, --scale 1), a first run, then a burst of
# ten saves of the painting 50 ms apart. The frame on the page must change (the status's
# generation moves on, the composite file is rewritten) and the burst must start at most two
# runs (finished ones, plus any stopped by a newer save); the frame made then from the inputs
# kept in memory is byte for byte a fresh lookdev's. Exit 77 (skip) without curl.
#   sh lookdev_test.sh SOURCE_DIR EMAKI WORK
set -e
src=$1 emaki=$2 work=$3
command -v curl >/dev/null || { echo "skip: curl is not installed"; exit 77; }
rm -rf "$work" && mkdir -p "$work"
cp "$src/examples/stylit/source_style.png" "$work/painting.png"
sed -e "s#\"../data/#\"$src/examples/data/#; s#\"../stylit/source_style.png\"#\"painting.png\"#" \
    -e "s#size = \[960, 540\]#size = [96, 54]#" "$src/examples/fox/shot.toml" > "$work/shot.toml"
trap 'kill $pid 2>/dev/null || true' EXIT
# Runs CHECK... every 0.1 s until it succeeds; fails after 300 s, or once lookdev has stopped.
poll() {  # WHAT CHECK...
  what=$1; shift
  i=0
  until "$@"; do
    i=$((i + 1))
    [ $i -lt 3000 ] || { echo "FAIL: no $what within 300 s"; cat "$work/log"; exit 1; }
    kill -0 $pid 2>/dev/null || { echo "FAIL: lookdev stopped"; cat "$work/log"; exit 1; }
    sleep 0.1
  done
}
# lookdev picks a free port itself (no --port): the test reads it from the URL printed, so that
# tests running beside it cannot take it first.
printed_port() {
  port=$(sed -n 's#^http://127\.0\.0\.1:\([0-9][0-9]*\)/.*#\1#p' "$work/url")
  [ -n "$port" ]
}
start() {  # lookdev's arguments
  : > "$work/url"  # now, not in the child: the last run's URL must not be read
  "$emaki" lookdev "$@" > "$work/url" 2> "$work/log" &
  pid=$!
  poll "URL printed" printed_port
}
start "$work/shot.toml" --frames 0 --scale 1
status() { curl -s "http://127.0.0.1:$port/api/status" || true; }
# The status shows TEXT; a status with an error message fails the test.
shows() {
  now=$(status)
  case $now in *"$1"*) return 0 ;; esac
  case $now in *'"message":"error: '*) echo "FAIL: $now"; exit 1 ;; esac
  return 1
}
wait_for() { poll "'$1'" shows "$1"; }
wait_for '"generation":1,'
grep -q '^http://127.0.0.1:' "$work/url" || { echo "FAIL: no URL printed"; exit 1; }
frame="$work/out.lookdev/composite/frame_0000.png"
[ -f "$frame" ] || { echo "FAIL: no preview frame"; exit 1; }
before=$(stat -c %Y.%y "$frame")
runs_before=$(grep -c -e ': run [0-9]*:' -e 'starting over' "$work/log" || true)
# Each save a rename of a copy made beforehand, so that on a loaded machine the saves still
# come 50 ms apart and not a copy's time more (a gap over the 150 ms settle splits the burst).
i=0
while [ $i -lt 10 ]; do cp "$work/painting.png" "$work/painting.$i.png"; i=$((i + 1)); done
i=0
while [ $i -lt 10 ]; do
  mv "$work/painting.$i.png" "$work/painting.png"
  sleep 0.05
  i=$((i + 1))
done
wait_for '"generation":2,'
sleep 3  # anything the burst would still start shows within this time
runs=$(( $(grep -c -e ': run [0-9]*:' -e 'starting over' "$work/log") - runs_before ))
after=$(stat -c %Y.%y "$frame")
echo "burst of 10 saves: $runs runs; generation $(status)"
[ "$before" != "$after" ] || { echo "FAIL: the preview frame was not made again"; exit 1; }
[ $runs -ge 1 ] && [ $runs -le 2 ] || { echo "FAIL: $runs runs for one burst"; cat "$work/log"; exit 1; }
kill $pid && wait $pid || { echo "FAIL: lookdev did not stop cleanly on SIGTERM"; exit 1; }
one_run() {  # SHOT, OUT_DIR, then lookdev's own options
  shot=$1 out=$2; shift 2
  start "$shot" --out "$out" "$@"
  wait_for '"generation":1,'
  kill $pid && wait $pid || { echo "FAIL: lookdev $* did not stop cleanly"; exit 1; }
}
# The frame made after the saves, from what the runs kept in memory, is the frame a fresh
# lookdev of the saved painting makes.
one_run "$work/shot.toml" "$work/fresh" --frames 0 --scale 1
for f in composite/frame_0000.png layers/base/base_0000.exr layers/outline/outline_0000.exr; do
  cmp -s "$work/out.lookdev/$f" "$work/fresh/$f" || { echo "FAIL: $f differs from a fresh run"; exit 1; }
done
# --temporal: frame 3 from frame 2 made as a chain's first frame, nothing before it; frame 2
# is frame by frame's, frame 3 is not.
one_run "$work/shot.toml" "$work/temporal" --frames 3 --temporal --scale 1
one_run "$work/shot.toml" "$work/by_frame" --frames 2,3 --scale 1
[ ! -e "$work/temporal/layers/base/base_0001.exr" ] || { echo "FAIL: --temporal made frame 1"; exit 1; }
for l in base shadow outline; do
  cmp -s "$work/temporal/layers/$l/${l}_0002.exr" "$work/by_frame/layers/$l/${l}_0002.exr" ||
    { echo "FAIL: --temporal's frame 2 ($l) is not frame by frame's"; exit 1; }
done
! cmp -s "$work/temporal/layers/base/base_0003.exr" "$work/by_frame/layers/base/base_0003.exr" ||
  { echo "FAIL: --temporal's frame 3 did not use the chain"; exit 1; }
# --scale 0.5 with a painted weight map of the shot's size: the map is resampled to the preview.
cp "$work/fresh/composite/frame_0000.png" "$work/map.png"
sed -e 's#^guides = { normal = 1.0, diffuse = 1.5 }#guides = { normal = 1.0, diffuse = { weight = 1.5, map = "map.png" } }#' \
  "$work/shot.toml" > "$work/mapped.toml"
grep -q 'map = "map.png"' "$work/mapped.toml" || { echo "FAIL: the base layer's guides line moved"; exit 1; }
one_run "$work/mapped.toml" "$work/half" --frames 0 --scale 0.5
[ -f "$work/half/layers/base/base_0000.exr" ] ||
  { echo "FAIL: --scale 0.5 with a weight map made no base frame"; cat "$work/log"; exit 1; }
trap - EXIT
echo "ok"
