#!/bin/sh
# Side by side with EbSynth's CPU build on EbSynth's own example command lines: emaki three
# times, EbSynth once, emaki three times more, wall seconds and peak RSS from /usr/bin/time.
# EbSynth is not part of emaki: build it yourself (jamriska/ebsynth, build-linux-cpu_only.sh)
# and pass its binary. Quality: run ../shared/tools/judge on the outputs left in OUT.
#
#   bench/compare_ebsynth.sh /path/to/ebsynth [OUT=/tmp/emaki_vs_ebsynth]
set -e
EB=${1:?usage: compare_ebsynth.sh EBSYNTH_BINARY [OUT]}
OUT=${2:-/tmp/emaki_vs_ebsynth}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
E=$ROOT/build/release/apps/emaki/emaki
S=$ROOT/examples/stylit
F=$ROOT/../shared/data/facestyle
mkdir -p "$OUT"
ST="-style $S/source_style.png -guide $S/source_fullgi.png $S/target_fullgi.png -weight 0.5
 -guide $S/source_dirdif.png $S/target_dirdif.png -weight 0.5
 -guide $S/source_dirspc.png $S/target_dirspc.png -weight 0.5
 -guide $S/source_indirb.png $S/target_indirb.png -weight 0.5"
FA="-style $F/source_painting.png -guide $F/source_Gapp.png $F/target_Gapp.png -weight 2.0
 -guide $F/source_Gseg.png $F/target_Gseg.png -weight 1.5
 -guide $F/source_Gpos.png $F/target_Gpos.png -weight 1.5"
run() {  # name args
  name=$1; shift
  for i in 1 2 3; do
    /usr/bin/time -f "emaki $name %e s wall, %M KB" "$E" synth "$@" -output "$OUT/${name}_emaki.png" --quiet
  done
  /usr/bin/time -f "ebsynth $name %e s wall, %M KB" "$EB" "$@" -output "$OUT/${name}_ebsynth.png" >/dev/null
  for i in 1 2 3; do
    /usr/bin/time -f "emaki $name %e s wall, %M KB" "$E" synth "$@" -output "$OUT/${name}_emaki.png" --quiet
  done
}
# shellcheck disable=SC2086
run stylit $ST
if [ -d "$F" ]; then
  # shellcheck disable=SC2086
  run facestyle $FA
fi
