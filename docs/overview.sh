#!/bin/sh
# Regenerates docs/images/overview.png, the README's picture, from a finished run of the bundled
# shot (./run_example.sh, or `emaki run examples/fox/shot.toml`): the StyLit painting (A'), the
# reference sphere's normals fitted to it (A), the normal, diffuse and shadow passes of one frame
# (B, from its layered EXR) and the composited frame (B'), labelled and side by side.
# Usage: docs/overview.sh [FRAME=24] [path/to/emaki]   (from the repository root; needs oiiotool)
set -eu
N=${1:-24}
F=$(printf %04d "$N")
EMAKI=${2:-build/release/apps/emaki/emaki}
OUT=examples/fox/out
FONT=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
H=180
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
[ -f "$OUT/layered/frame_$F.exr" ] || { echo "overview.sh: no $OUT/layered/frame_$F.exr: run the shot first" >&2; exit 1; }

# A' and A: the painting, and the reference passes the shot fits to it (its exemplar's keys).
"$EMAKI" template --fit examples/stylit/source_style.png --sphere 608.2,494.2,242.5 \
  --elevation 20 --fov 30 --light 0.3,0.9,-0.3 --softness 8 --out "$T/ref" --previews >/dev/null
WA=$(( H * 1200 / 912 ))  # the painting's aspect
oiiotool examples/stylit/source_style.png --resize ${WA}x$H -o "$T/a1.png"
oiiotool "$T/ref/preview/reference_normal.png" --resize ${WA}x$H -o "$T/a0.png"

# B: three passes of the frame, stacked into one panel of the frame's aspect.
E=$OUT/layered/frame_$F.exr
W=$(( H * 16 / 9 ))
oiiotool "$E" --ch normal.X,normal.Y,normal.Z --mulc 0.5 --addc 0.5 --resize ${W}x$H -o "$T/n.png"
oiiotool "$E" --ch diffuse.Y,diffuse.Y,diffuse.Y --resize ${W}x$H -o "$T/d.png"
oiiotool "$E" --ch shadow.Y,shadow.Y,shadow.Y --resize ${W}x$H -o "$T/s.png"
# The normal pass on the left half, diffuse over the right top, shadow over the right bottom.
oiiotool "$T/n.png" --cut $(( W / 2 ))x$H+0+0 -o "$T/nl.png"
oiiotool "$T/d.png" --cut $(( W / 2 ))x$(( H / 2 ))+$(( W / 2 ))+0 -o "$T/dr.png"
oiiotool "$T/s.png" --cut $(( W / 2 ))x$(( H - H / 2 ))+$(( W / 2 ))+$(( H / 2 )) -o "$T/sr.png"
oiiotool "$T/dr.png" "$T/sr.png" --mosaic 1x2 -o "$T/right.png"
oiiotool "$T/nl.png" "$T/right.png" --mosaic 2x1 --resize ${W}x$H -o "$T/b0.png"

# B': the composited frame.
oiiotool "$OUT/composite/frame_$F.png" --resize ${W}x$H -o "$T/b1.png"

mkdir -p docs/images
P=6
L=24  # a white strip under the panels for the labels
WT=$(( 2 * WA + 2 * W + 3 * P ))
X2=$(( WA + P )); X3=$(( 2 * WA + 2 * P )); X4=$(( 2 * WA + W + 3 * P ))
TXT="size=15:color=0.1,0.1,0.1:font=$FONT:y=$(( H + 17 ))"
# Each panel pasted over a white canvas (--paste takes the foreground first, hence --swap).
oiiotool --create ${WT}x$(( H + L )) 3 --fill:color=1,1,1 ${WT}x$(( H + L ))+0+0 \
  "$T/a1.png" --swap --paste +0+0 "$T/a0.png" --swap --paste +$X2+0 \
  "$T/b0.png" --swap --paste +$X3+0 "$T/b1.png" --swap --paste +$X4+0 \
  --text:x=4:$TXT "the painting (A')" --text:x=$(( X2 + 4 )):$TXT "its guides (A)" \
  --text:x=$(( X3 + 4 )):$TXT "guides of frame $N (B)" \
  --text:x=$(( X4 + 4 )):$TXT "frame $N stylized (B')" -d uint8 -o docs/images/overview.png
echo "wrote docs/images/overview.png"
