#!/bin/sh
# Configures and builds the release preset into build/release.
set -e
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release -j"$(nproc)"
