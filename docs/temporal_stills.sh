#!/bin/sh
# Regenerates docs/images/temporal_uniformity_frame40.png and
# docs/images/temporal_uniformity_tail.png: the bundled shot's base layer (960x540) with
# temporal_uniformity 0, 1000 and 3500 at temporal frames, and frame by frame, from
# bench/temporal_bench --save (frames over white outside the layer's mask).
#   frame40: frame 40; top 0 and 1000, bottom 3500 and frame by frame
#   tail:    frames 20 (top) and 28, right of the Fox's tail (400x220+560+150): 0, 1000, 3500
# Usage: docs/temporal_stills.sh [path/to/temporal_bench]   (from the repository root; the four
# 41-frame runs take a few minutes). Needs oiiotool (openimageio-tools).
set -eu
B=${1:-build/release/bench/temporal_bench}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$B" --frames 41 --variants frame --save "$T" >/dev/null
for u in 0 1000 3500; do
  "$B" --frames 41 --variants rest_position_uniform --temporal-uniformity $u --save "$T" >/dev/null
  for f in 0020 0028 0040; do mv "$T/rest_position_uniform_$f.png" "$T/u${u}_$f.png"; done
done
mkdir -p docs/images
oiiotool "$T/u0_0040.png" "$T/u1000_0040.png" "$T/u3500_0040.png" "$T/frame_0040.png" \
  --mosaic:pad=2 2x2 --resize 800x0 -d uint8 -o docs/images/temporal_uniformity_frame40.png
C="--cut 400x220+560+150"
tiles=""
for f in 0020 0028; do
  for u in 0 1000 3500; do
    oiiotool "$T/u${u}_$f.png" $C -o "$T/cut_${f}_$u.png"
    tiles="$tiles $T/cut_${f}_$u.png"
  done
done
# shellcheck disable=SC2086
oiiotool $tiles --mosaic:pad=2 3x2 --resize 900x0 -d uint8 \
  -o docs/images/temporal_uniformity_tail.png
echo "wrote docs/images/temporal_uniformity_frame40.png docs/images/temporal_uniformity_tail.png"
