#!/usr/bin/env bash
# Builds the relocatable package: build-package/envgi-VERSION-linux-x86_64[-cuda].tar.xz, which
# runs on a Linux x86-64 machine with only a C library (and, for the GPU, the NVIDIA driver):
#   tar xf envgi-*.tar.xz && envgi-*/bin/envgi render envgi-*/share/envgi/scenes/buddha.xml -o b.exr
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR=${BUILD_DIR:-build-package} bash scripts/build.sh -DENVGI_BENCH=OFF -DENVGI_TESTS=OFF -DENVGI_GPU_TOOLS=ON "$@"
cd "${BUILD_DIR:-build-package}"
cpack -G TXZ >cpack.log 2>&1 || { cat cpack.log; exit 1; }
ls -l envgi-*.tar.xz
