#!/bin/sh
# A small animated scene made by a script (tests/blender/make_scene.py: four objects, a moving
# camera, frames 1-4 at 160x90) and the reference sphere, both rendered by Blender through
# tools/blender/emaki_passes.py; `emaki run` stylizes the shot with the StyLit painting over
# Blender's reference sphere; the outputs are checked (layers and composite exist, values in
# range, the base layer's alpha matches the coverage).
set -e
. "$(dirname "$0")/common.sh"

blender_run -P "$HERE/make_scene.py" -- "$WORK/scene.blend"
blender_run "$WORK/scene.blend" -P "$EXPORTER" -- --out "$WORK/renders" --frames 1-4 \
  --samples 8
# The StyLit painting at a quarter of its size, and Blender's reference sphere fitted to it
# (examples/stylit_fit.txt at 1/4 scale).
run oiiotool "$ROOT/examples/stylit/source_style.png" --resize 300x228 -o "$WORK/painting.png"
blender_run -P "$EXPORTER" -- --reference --out "$WORK/reference" --size 300x228 \
  --sphere 152.05,123.55,60.6 --elevation 20 --fov 30 --light=0.3,0.9,-0.3 --softness 8 \
  --samples 8
for f in renders/frame_0001.exr renders/frame_0004.exr reference/reference.exr \
  reference/template.png; do
  [ -f "$WORK/$f" ] || { echo "FAIL: the exporter did not write $f"; exit 1; }
done
"$CHECK" passes "$WORK"/renders/frame_000[1-4].exr "$WORK/reference/reference.exr"
# The add-on: registered, its operator renders the scene's (here: first) frame.
blender_run "$WORK/scene.blend" --python-expr "import sys, bpy
sys.dont_write_bytecode = True
sys.path.insert(0, '$ROOT/tools/blender')
import emaki_passes
emaki_passes.register()
bpy.context.scene.frame_end = 1
bpy.context.scene.emaki_out = '$WORK/addon'
assert bpy.ops.emaki.render_passes() == {'FINISHED'}"
"$CHECK" passes "$WORK/addon/frame_0001.exr"
# Bad input: one line naming the option, a non-zero exit, nothing written.
if blender -b --factory-startup -P "$EXPORTER" -- --out "$WORK/bad" --frames 4-1 \
  >"$WORK/err" 2>&1; then
  echo "FAIL: the exporter accepted --frames 4-1"; exit 1
fi
grep "emaki_passes: error: --frames" "$WORK/err" || { cat "$WORK/err"; exit 1; }
[ ! -e "$WORK/bad" ] || { echo "FAIL: the refused export created its folder"; exit 1; }
# Blender's reference against emaki's own reference scene with the same settings.
run "$EMAKI" template --size 300x228 --sphere 152.05,123.55,60.6 --elevation 20 --fov 30 \
  --light 0.3,0.9,-0.3 --softness 8 --out "$WORK/emaki_reference"
echo "reference sphere, emaki vs Blender:"
"$CHECK" compare "$WORK/emaki_reference/reference.exr" "$WORK/reference/reference.exr" \
  --max-normal-deg 1 --max-position 0.01 --min-iou 0.99

cat >"$WORK/shot.toml" <<TOML
[source]
sequence = "renders/frame_%04d.exr"
frames = [1, 4]

[exemplars.pastel]
kind = "keyframe"
painting = "painting.png"
passes = "reference/reference.exr"

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
folder = "out"
mp4 = false
TOML
run "$EMAKI" run "$WORK/shot.toml"
"$CHECK" outputs "$WORK/out" 1 4 base shadow outline

# colour.toml: Blender's config, display and view as shot keys, which emaki accepts (Blender's
# config, its default Filmic view on the previews).
for key in config display view passes_colorspace; do
  grep -q "^$key = " "$WORK/renders/colour.toml" ||
    { cat "$WORK/renders/colour.toml"; echo "FAIL: colour.toml has no $key"; exit 1; }
done
{
  sed -n '/^\[colour\]/,/^$/p' "$WORK/renders/colour.toml"
  sed 's/^folder = "out"/folder = "out_colour"/' "$WORK/shot.toml"
  sed -n '/^\[outputs\]/,$p' "$WORK/renders/colour.toml" | grep -E '^(display|view) = '
} >"$WORK/shot_colour.toml"
run "$EMAKI" run "$WORK/shot_colour.toml" --frames 1
[ -f "$WORK/out_colour/composite/frame_0001.png" ] ||
  { echo "FAIL: the shot with Blender's colour settings wrote no composite"; exit 1; }
