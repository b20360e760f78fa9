#!/bin/sh
# One command: install the Debian packages, build, and run the bundled example: the StyLit
# painting (a pastel sphere) carried onto a target figure through four light-path guides,
# EbSynth's own example command line, run by `emaki synth`. Output: out/stylit.png
set -e
cd "$(dirname "$0")"
./scripts/setup.sh
./scripts/build.sh
mkdir -p out
E=examples/stylit
./build/release/apps/emaki/emaki synth -style $E/source_style.png \
  -guide $E/source_fullgi.png $E/target_fullgi.png -weight 0.5 \
  -guide $E/source_dirdif.png $E/target_dirdif.png -weight 0.5 \
  -guide $E/source_dirspc.png $E/target_dirspc.png -weight 0.5 \
  -guide $E/source_indirb.png $E/target_indirb.png -weight 0.5 \
  -output out/stylit.png
echo "wrote out/stylit.png"
