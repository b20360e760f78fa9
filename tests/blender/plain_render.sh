#!/bin/sh
# A plain Blender render (tests/blender/plain_render.py: Blender's own pass names, no exporter)
# of the scripted scene, read by a shot file with `preset = "blender"`, stylized by `emaki run`;
# the outputs are checked. Then the errors: a missing view layer or the wrong preset stop with
# one line naming the key and the channel, listing the file's channels, and write nothing.
set -e
. "$(dirname "$0")/common.sh"

blender_run -P "$HERE/make_scene.py" -- "$WORK/scene.blend"
blender_run "$WORK/scene.blend" -P "$HERE/plain_render.py" -- --out "$WORK/renders" \
  --frames 1-4 --samples 8
run oiiotool "$ROOT/examples/stylit/source_style.png" --resize 300x228 -o "$WORK/painting.png"

"$CHECK" passes "$WORK"/renders/frame_0001.exr:blender "$WORK"/renders/frame_0004.exr:blender

shot() {  # $1: extra source keys, $2: output folder
  cat <<TOML
[source]
sequence = "renders/frame_%04d.exr"
frames = [1, 4]
$1

[exemplars.pastel]
painting = "painting.png"
sphere = [152.05, 123.55, 60.6]
elevation = 20
light = [0.3, 0.9, -0.3]

[layers.base]
kind = "base"
exemplar = "pastel"

[layers.shadow]
kind = "shadow"
exemplar = "pastel"

[layers.outline]
kind = "outline"
exemplar = "pastel"

[outputs]
folder = "$2"
mp4 = false
TOML
}
shot 'preset = "blender"' out >"$WORK/shot.toml"
run "$EMAKI" run "$WORK/shot.toml"
"$CHECK" outputs "$WORK/out" 1 4 base shadow outline

expect_error() {  # $1: shot file, $2: folder that must not appear, then strings the error has
  file=$1 folder=$2
  shift 2
  if "$EMAKI" run "$file" >"$WORK/err" 2>&1; then
    echo "FAIL: $file should have been refused"; exit 1
  fi
  cat "$WORK/err"
  [ "$(wc -l <"$WORK/err")" -eq 1 ] || { echo "FAIL: the error is not one line"; exit 1; }
  for s in "$@"; do
    grep -qF -- "$s" "$WORK/err" || { echo "FAIL: the error does not say '$s'"; exit 1; }
  done
  [ ! -e "$WORK/$folder" ] || { echo "FAIL: $folder was written"; exit 1; }
}
shot 'preset = "blender"
view_layer = "Nope"' bad1 >"$WORK/bad1.toml"
expect_error "$WORK/bad1.toml" bad1 "source.preset" "'Nope.Normal.X'" "frame_0001.exr" \
  "which has: " "ViewLayer.Normal.X"
shot '' bad2 >"$WORK/bad2.toml"
expect_error "$WORK/bad2.toml" bad2 "source.sequence" "'normal.X'" "ViewLayer.Vector.W"
shot 'preset = "blender"
channels.shadow = ["ViewLayer.Shadow.X"]' bad3 >"$WORK/bad3.toml"
expect_error "$WORK/bad3.toml" bad3 "source.channels.shadow" "'ViewLayer.Shadow.X'"
echo "all checks passed"
