#!/bin/sh
# The add-on's "Stylize current frame" action, headless: Blender renders the reference sphere
# (the StyLit painting's passes) and a frame of the scripted test scene through the exporter,
# then stylizes that frame in its own process through emaki's Python module and keeps the
# result as an image; tests/blender/python_stylize.py checks it against emaki.synthesize run
# on the same files.
# Usage: python_stylize.sh EMAKI CHECK WORK PYTHON_MODULE_DIR
set -e
. "$(dirname "$0")/common.sh"
MODULE_DIR=$4

blender_run -P "$HERE/make_scene.py" -- "$WORK/scene.blend"
run oiiotool "$ROOT/examples/stylit/source_style.png" --resize 300x228 -o "$WORK/painting.png"
blender_run -P "$EXPORTER" -- --reference --out "$WORK/reference" --size 300x228 \
  --sphere 152.05,123.55,60.6 --elevation 20 --fov 30 --light=0.3,0.9,-0.3 --softness 8 \
  --samples 8
blender_run "$WORK/scene.blend" -P "$HERE/python_stylize.py" -- "$ROOT/tools/blender" \
  "$MODULE_DIR" "$WORK"
cat "$WORK/log" | grep "python_stylize:"
