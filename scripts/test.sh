#!/usr/bin/env bash
# Installs dependencies, builds, and runs the unit test suite (ctest label "unit").
# The long statistical suite runs with: ctest --test-dir build -L long
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh "$@"
ctest --test-dir "${BUILD_DIR:-build}" -L unit -j"$(nproc)" --output-on-failure
