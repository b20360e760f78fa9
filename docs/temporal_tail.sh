#!/bin/sh
# Regenerates docs/images/temporal_tail.png: the bundled shot's base layer (960x540, 48 frames,
# the shipped temporal defaults) behind the Fox's tail, frame by frame (left) against the
# temporal chain (right), at frames 10 (top) and 46 (bottom), from bench/temporal_bench --save
# (frames over white outside the layer's mask).
# Usage: docs/temporal_tail.sh [path/to/temporal_bench] [FOLDER]   (from the repository root;
# the two 48-frame runs take a few minutes). FOLDER: the --save folder of an earlier run of
# `temporal_bench --size 960x540 --frames 48 --variants frame,rest_position`, instead of running
# it again. Needs oiiotool (openimageio-tools).
set -eu
B=${1:-build/release/bench/temporal_bench}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
S=${2:-}
if [ -z "$S" ]; then
  "$B" --size 960x540 --frames 48 --variants frame,rest_position --save "$T" >/dev/null
  S=$T
fi
mkdir -p docs/images
oiiotool "$S/frame_0010.png" --cut 400x280+480+100 -o "$T/a.png"
oiiotool "$S/rest_position_0010.png" --cut 400x280+480+100 -o "$T/b.png"
oiiotool "$S/frame_0046.png" --cut 400x280+560+140 -o "$T/c.png"
oiiotool "$S/rest_position_0046.png" --cut 400x280+560+140 -o "$T/d.png"
oiiotool "$T/a.png" "$T/b.png" "$T/c.png" "$T/d.png" --mosaic:pad=2 2x2 -d uint8 \
  -o docs/images/temporal_tail.png
echo "wrote docs/images/temporal_tail.png"
