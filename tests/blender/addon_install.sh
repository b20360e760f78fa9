#!/bin/sh
# The Blender add-on (build/release/blender/emaki_blender.zip) installs with Blender's own add-on
# installer, headless (addon_install.py), into Blender user folders inside WORK: one package,
# emaki_blender/, with one bl_info (no "missing 'bl_info'" warning), and it finds emaki on PATH.
# Usage: addon_install.sh ZIP VERSION EMAKI WORK
set -e
ZIP=$1
VERSION=$2
EMAKI=$3
WORK=$4
HERE=$(cd "$(dirname "$0")" && pwd)
if ! command -v blender >/dev/null 2>&1; then
  echo "SKIP: blender is not installed (scripts/setup.sh installs Debian's blender)"
  exit 77
fi
rm -rf "$WORK"
mkdir -p "$WORK/prefix/bin"
# An install's layout: PREFIX/bin/emaki.
ln -s "$EMAKI" "$WORK/prefix/bin/emaki"
export BLENDER_USER_CONFIG="$WORK/config" BLENDER_USER_SCRIPTS="$WORK/scripts"
if ! PATH="$WORK/prefix/bin:$PATH" blender -b --factory-startup -t 1 --python-exit-code 1 \
    -P "$HERE/addon_install.py" -- "$ZIP" "$VERSION" "$WORK/prefix/bin/emaki" \
    >"$WORK/log" 2>&1; then
  tail -n 30 "$WORK/log"
  echo "FAIL: the add-on did not install and enable"
  exit 1
fi
if grep -i "bl_info" "$WORK/log"; then
  echo "FAIL: Blender warned about bl_info"
  exit 1
fi
installed=$(ls "$WORK/scripts/addons")
if [ "$installed" != "emaki_blender" ]; then
  echo "FAIL: the zip installed '$installed', not the one package emaki_blender"
  exit 1
fi
grep "emaki add-on: installed, enabled, disabled" "$WORK/log"
