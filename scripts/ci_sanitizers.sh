#!/bin/sh
# CI's second half, after ./run_tests.sh: the whole suite under ASan+UBSan and under TSan
# (halt_on_error: any report fails), and every libFuzzer target for a fixed number of runs over
# its corpus and the reproducers in tests/data/hostile/ (clang-14, ASan+UBSan+libFuzzer).
# Each stage prints its wall time.
set -e
cd "$(dirname "$0")/.."
stage() {
  name=$1; shift
  t0=$(date +%s)
  echo "== $name"
  "$@"
  echo "== $name: $(( $(date +%s) - t0 )) s"
}
j=$(nproc)
stage "asan build" sh -c "cmake --preset asan >/dev/null && cmake --build --preset asan -j$j >/dev/null"
# The Slurm tests: farm_slurm runs under ASan (the farm code and every task it starts);
# slurm_smoke exercises only the cluster scripts, and TSan adds nothing to either but minutes.
stage "asan tests" ctest --preset asan -j"$j" -E '^slurm_smoke$'
stage "tsan build" sh -c "cmake --preset tsan >/dev/null && cmake --build --preset tsan -j$j >/dev/null"
stage "tsan tests" ctest --preset tsan -j"$j" -LE slurm
stage "fuzz build" sh -c "cmake --preset fuzz >/dev/null && cmake --build --preset fuzz -j$j >/dev/null"
stage "fuzz smoke" ctest --preset fuzz -j"$j"
