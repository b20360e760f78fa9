#!/bin/sh
# Regenerates docs/images/temporal_tail.png: the bundled shot's base layer (960x540, 48 frames,
# the shipped temporal defaults) behind the Fox's tail, frame by frame (left), the temporal chain
# without the base kind's coherent warm start (`cr=0`, middle) and the temporal chain (right), at
# frames 10 (top) and 46 (bottom), from bench/temporal_bench --save (frames over white outside
# the layer's mask).
# Usage: docs/temporal_tail.sh [path/to/temporal_bench] [FOLDER]   (from the repository root;
# the three 48-frame runs take a few minutes). FOLDER: the --save folder of an earlier run of
# `temporal_bench --size 960x540 --frames 48 --variants frame,rest_position:cr=0,rest_position`,
# instead of running it again. Needs oiiotool (openimageio-tools).
set -eu
B=${1:-build/release/bench/temporal_bench}
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
S=${2:-}
if [ -z "$S" ]; then
  "$B" --size 960x540 --frames 48 --variants frame,rest_position:cr=0,rest_position \
    --save "$T" >/dev/null
  S=$T
fi
mkdir -p docs/images
set --
for f in 0010 0046; do
  for v in frame rest_position:cr=0 rest_position; do
    if [ $f = 0010 ]; then cut=400x280+480+100; else cut=400x280+560+140; fi
    oiiotool "$S/${v}_$f.png" --cut $cut -o "$T/$f-$#.png"
    set -- "$@" "$T/$f-$#.png"
  done
done
oiiotool "$@" --mosaic:pad=2 3x2 -d uint8 -o docs/images/temporal_tail.png
echo "wrote docs/images/temporal_tail.png"
