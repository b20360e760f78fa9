#!/bin/sh
# CTest's fuzz smoke test: FUZZER RUNS DICT SCRATCH CORPUS [REPRODUCERS]. Every file of the
# corpus and of the reproducer folder runs once, then RUNS mutations; any crash, leak, timeout
# (30 s an input) or RSS over 2 GiB fails. New inputs go to SCRATCH, never into the source tree.
# The seed is fixed so that a CI run is repeatable: the same commit passes or fails the same way.
# Exploring with other seeds is fuzz/run.sh's job (a random seed per run); what it finds goes to
# tests/data/hostile/<target>/ and is replayed here.
set -e
fuzzer=$1 runs=$2 dict=$3 scratch=$4 corpus=$5 hostile=$6
rm -rf "$scratch" && mkdir -p "$scratch"
set -- "$scratch" "$corpus"
[ -n "$hostile" ] && [ -d "$hostile" ] && set -- "$@" "$hostile"
exec "$fuzzer" -seed=1 -runs="$runs" -rss_limit_mb=2048 -malloc_limit_mb=2048 -timeout=30 \
  -max_total_time=120 -dict="$dict" -artifact_prefix="$scratch/" "$@"
