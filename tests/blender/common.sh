# Shared by the Blender tests: arguments, the skip when Blender is missing, logged commands.
# Usage from a test: . "$(dirname "$0")/common.sh" "$@"
EMAKI=$1
CHECK=$2
WORK=$3
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../.." && pwd)
EXPORTER=$ROOT/tools/blender/emaki_passes.py
if ! command -v blender >/dev/null 2>&1; then
  echo "SKIP: blender is not installed (scripts/setup.sh installs Debian's blender)"
  exit 77
fi
rm -rf "$WORK"
mkdir -p "$WORK"
# Runs a command with its output in $WORK/log; shows the log and fails when it fails.
run() {
  echo "+ $*"
  if ! "$@" >"$WORK/log" 2>&1; then
    tail -n 30 "$WORK/log"
    echo "FAIL: $1 exited non-zero"
    exit 1
  fi
}
# Blender on at most 2 threads, without the user's startup file or add-ons.
blender_run() {
  run blender -b --factory-startup -t 2 --python-exit-code 1 "$@"
}
