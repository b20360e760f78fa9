#!/bin/sh
# One command: install the Debian packages, build, run every test (CTest).
set -e
cd "$(dirname "$0")"
./scripts/setup.sh
./scripts/build.sh
ctest --preset release -j"$(nproc)"
