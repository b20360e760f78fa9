#!/bin/sh
# One command: install the Debian packages, build, and run the bundled examples:
#  1. the shot examples/fox/shot.toml (Fox walking, three stylized layers, temporal advection,
#     composited over paper) -> examples/fox/out/ (frames, layered EXRs, preview.mp4)
#  2. EbSynth's StyLit example command line through `emaki synth` -> out/stylit.png
set -e
cd "$(dirname "$0")"
./scripts/setup.sh
./scripts/build.sh
./build/release/apps/emaki/emaki run examples/fox/shot.toml
echo "wrote examples/fox/out/ (preview.mp4, contact_sheet.png, layers/, composite/, layered/)"
mkdir -p out
E=examples/stylit
./build/release/apps/emaki/emaki synth -style $E/source_style.png \
  -guide $E/source_fullgi.png $E/target_fullgi.png -weight 0.5 \
  -guide $E/source_dirdif.png $E/target_dirdif.png -weight 0.5 \
  -guide $E/source_dirspc.png $E/target_dirspc.png -weight 0.5 \
  -guide $E/source_indirb.png $E/target_indirb.png -weight 0.5 \
  -output out/stylit.png
echo "wrote out/stylit.png"
