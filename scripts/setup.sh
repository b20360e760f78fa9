#!/bin/sh
# Installs the Debian 12 packages emaki builds and tests with (skips those already installed);
# libgmock-dev because GTest's CMake config checks that the gmock files exist; slurm-wlm and
# munge run the private test cluster of scripts/slurm/start.sh (daemons not started);
# libcpp-httplib-dev serves emaki view's page, chromium (headless) drives it in the browser tests.
set -e
PKGS="build-essential cmake pkg-config libopenimageio-dev openimageio-tools libopencv-core-dev
libopenexr-dev libtinygltf-dev libtbb-dev libcli11-dev libtomlplusplus-dev libfmt-dev
libglm-dev libopencolorio-dev opencolorio-tools python3-pyopencolorio libgtest-dev libgmock-dev libpng-dev zlib1g-dev libdeflate-dev ffmpeg blender python3-numpy
pybind11-dev python3-dev python3-pytest
clang-14 libclang-rt-14-dev clang-format slurm-wlm slurm-client munge
libcpp-httplib-dev chromium"
missing=""
for p in $PKGS; do dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"; done
if [ -n "$missing" ]; then
  echo "setup: installing$missing"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq $missing >/dev/null
fi
