#!/bin/sh
# Fails when a tracked C++ file is not clang-formatted (.clang-format); lists the files.
cd "$(dirname "$0")/.."
bad=""
for f in $(git ls-files '*.cpp' '*.h'); do
  clang-format --dry-run --Werror "$f" >/dev/null 2>&1 || bad="$bad $f"
done
if [ -n "$bad" ]; then
  echo "check_format: not clang-formatted (run clang-format -i):$bad"
  exit 1
fi
echo "check_format: $(git ls-files '*.cpp' '*.h' | wc -l) files formatted"
