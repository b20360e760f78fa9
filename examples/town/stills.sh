#!/bin/sh
# The stills in docs/town/ from a finished run of examples/town/shot.toml (default frame 40):
#   composite_NNNN.png  the composited frame, 8-bit
#   layers_NNNN.png     half size, left to right and top to bottom: the base, hatching, shadow
#                       and outline layers (each layer's touch over white where it covers), the
#                       object_id pass (grey levels) and the composite
#   seams_0047.png      where the Fox walks in front of an alien (frame 47, 3x crop): composite,
#                       outline pass, object_id pass, outline layer coverage
#   shadows_NNNN.png    the right-hand house, an alien and the banner (3x crop): composite,
#                       shadow pass, object_id pass, shadow layer coverage
# Needs oiiotool (Debian package openimageio-tools).
set -e
cd "$(dirname "$0")"
F=$(printf %04d "${1:-40}")
E=out/layered/frame_$F.exr
D=../../docs/town
T=$(mktemp -d)
mkdir -p $D
oiiotool out/composite/frame_$F.png -d uint8 -o $D/composite_$F.png
for l in base hatching shadow outline; do
  # Y * A + (1 - A)
  oiiotool $E --ch layer_$l.Y,layer_$l.Y,layer_$l.Y $E --ch layer_$l.A,layer_$l.A,layer_$l.A \
    --mul $E --ch layer_$l.A,layer_$l.A,layer_$l.A --mulc -1 --addc 1 --add \
    --resize 320x180 -d uint8 -o $T/$l.png
done
oiiotool $E --ch object_id.Y,object_id.Y,object_id.Y --mulc 0.09 --resize 320x180 -d uint8 \
  -o $T/ids.png
oiiotool out/composite/frame_$F.png --resize 320x180 -d uint8 -o $T/composite.png
oiiotool $T/base.png $T/hatching.png $T/shadow.png $T/outline.png $T/ids.png $T/composite.png \
  --mosaic 3x2 -d uint8 -o $D/layers_$F.png
# Where the Fox walks in front of an alien, 3x.
E=out/layered/frame_0047.exr
C="--cut 180x130+120+120 --resize:filter=box 540x390 -d uint8"
oiiotool out/composite/frame_0047.png $C -o $T/z1.png
oiiotool $E --ch outline.Y,outline.Y,outline.Y $C -o $T/z2.png
oiiotool $E --ch object_id.Y,object_id.Y,object_id.Y --mulc 0.09 $C -o $T/z3.png
oiiotool $E --ch layer_outline.A,layer_outline.A,layer_outline.A $C -o $T/z4.png
oiiotool $T/z1.png $T/z2.png $T/z3.png $T/z4.png --mosaic 4x1 --resize 1080x195 -d uint8 \
  -o $D/seams_0047.png
# Shadows across objects, 3x.
E=out/layered/frame_$F.exr
C="--cut 200x120+420+110 --resize:filter=box 600x360 -d uint8"
oiiotool out/composite/frame_$F.png $C -o $T/y1.png
oiiotool $E --ch shadow.Y,shadow.Y,shadow.Y $C -o $T/y2.png
oiiotool $E --ch object_id.Y,object_id.Y,object_id.Y --mulc 0.09 $C -o $T/y3.png
oiiotool $E --ch layer_shadow.A,layer_shadow.A,layer_shadow.A $C -o $T/y4.png
oiiotool $T/y1.png $T/y2.png $T/y3.png $T/y4.png --mosaic 4x1 --resize 1200x180 -d uint8 \
  -o $D/shadows_$F.png
rm -r $T
echo "wrote $D/composite_$F.png $D/layers_$F.png $D/seams_0047.png $D/shadows_$F.png"
