#!/usr/bin/env bash
# Installs dependencies, builds, and renders the default example; prints the image's path.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mkdir -p out
./build/bin/envgi envmap plot scenes/envmaps/studio.hdr --count 2000 -o out/default.png
echo "image: $(pwd)/out/default.png"
