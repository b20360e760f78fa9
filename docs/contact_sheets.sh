#!/bin/sh
# Regenerates docs/passes_fox.png and docs/passes_sphere.png: the guide passes of one frame of the
# walking Fox and of the reference sphere, as PNG previews labelled and tiled with oiiotool.
# Usage: docs/contact_sheets.sh [path/to/emaki]   (run from the repository root)
set -eu
EMAKI=${1:-build/release/apps/emaki/emaki}
FONT=/usr/share/fonts/truetype/dejavu/DejaVuSansMono.ttf
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

label() {  # label IN OUT TEXT
  oiiotool "$1" --text:x=6:y=18:size=15:color=1,0.75,0:font="$FONT" "$3" -o "$2"
}

"$EMAKI" render examples/data/Fox.glb --clip Walk --frames 8 --size 300x169 --azimuth=-50 \
  --elevation 12 --out "$TMP/fox" --previews --quiet
tiles=""
for p in normal position_norm rest_position depth diffuse shadow albedo object_id material_id \
         outline motion alpha; do
  label "$TMP/fox/preview/frame_0008_$p.png" "$TMP/fox_$p.png" "$p"
  tiles="$tiles $TMP/fox_$p.png"
done
oiiotool $tiles --mosaic:pad=2 4x3 -o docs/passes_fox.png

"$EMAKI" template --size 300x225 --out "$TMP/sphere" --previews > /dev/null 2>&1
label "$TMP/sphere/template.png" "$TMP/sphere_template.png" "template.png"
tiles="$TMP/sphere_template.png"
for p in normal position_norm rest_position depth diffuse shadow albedo object_id outline alpha \
         material_id; do
  label "$TMP/sphere/preview/reference_$p.png" "$TMP/sphere_$p.png" "$p"
  tiles="$tiles $TMP/sphere_$p.png"
done
oiiotool $tiles --mosaic:pad=2 4x3 -o docs/passes_sphere.png
