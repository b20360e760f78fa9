#!/bin/sh
# Regenerates docs/images/hatching_chain.png: the town's hatching layer (640x360, 48 frames, the
# shipped temporal defaults) on the house at the left, frame by frame (left) against the
# temporal chain (right), at frames 8 (top) and 40 (bottom), from bench/temporal_bench --save
# (frames over white outside the layer's mask).
# Usage: docs/hatching_chain.sh [path/to/temporal_bench]   (from the repository root; the two
# 48-frame runs take about a minute). Needs oiiotool (openimageio-tools).
set -eu
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"${1:-build/release/bench/temporal_bench}" --shot examples/town/shot.toml --size 640x360 \
  --frames 48 --layer hatching --variants frame,rest_position --save "$T/run" >/dev/null
mkdir -p docs/images
for v in frame rest_position; do
  for f in 0008 0040; do oiiotool "$T/run/${v}_$f.png" --cut 320x240+0+10 -o "$T/${v}_$f.png"; done
done
oiiotool "$T/frame_0008.png" "$T/rest_position_0008.png" "$T/frame_0040.png" \
  "$T/rest_position_0040.png" --mosaic:pad=2 2x2 -d uint8 -o docs/images/hatching_chain.png
echo "wrote docs/images/hatching_chain.png"
