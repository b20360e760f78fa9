#!/bin/sh
# Consistency: Fox.glb at frame 10 of its Survey clip, 320x180, the same camera, rendered by
# emaki's renderer and by Blender (its glTF importer) through the exporter, and as a plain
# Blender render read with the `blender` preset. Limits: normals' mean angle < 3 degrees,
# positions' mean error < 1 % of the box, coverage IoU > 0.98, motion within 0.1 px.
set -e
. "$(dirname "$0")/common.sh"
FOX=$ROOT/tests/data/scenes/Fox.glb
CAM="150,60,120"
TARGET="-5,37,-11"

run "$EMAKI" render "$FOX" --clip Survey --frames 10 --size 320x180 --camera "$CAM" \
  --target="$TARGET" --fov 40 --no-ground --out "$WORK/emaki"
blender_run -P "$EXPORTER" -- --gltf "$FOX" --out "$WORK/exporter" --frames 10-10 \
  --size 320x180 --samples 16 --look-from="$CAM" --look-at="$TARGET" --fov 40
blender_run -P "$HERE/plain_render.py" -- --gltf "$FOX" --out "$WORK/plain" --frames 10-10 \
  --size 320x180 --samples 16 --look-from="$CAM" --look-at="$TARGET" --fov 40
"$CHECK" passes "$WORK/exporter/frame_0010.exr" "$WORK/plain/frame_0010.exr:blender"
echo "Fox frame 10, emaki vs Blender through the exporter:"
"$CHECK" compare "$WORK/emaki/frame_0010.exr" "$WORK/exporter/frame_0010.exr" \
  --max-normal-deg 3 --max-position 0.01 --min-iou 0.98 --max-motion 0.1
echo "Fox frame 10, emaki vs a plain Blender render (preset blender):"
"$CHECK" compare "$WORK/emaki/frame_0010.exr" "$WORK/plain/frame_0010.exr:blender" \
  --max-normal-deg 3 --max-position 0.01 --min-iou 0.98 --max-motion 0.1
