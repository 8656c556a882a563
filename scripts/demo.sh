#!/usr/bin/env bash
# Installs dependencies, builds, and renders the default example (the paper's Figure 5: a
# teapot and two glass spheres in Grace Cathedral); prints the image's path.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mkdir -p out
./build/bin/envgi render scenes/teapot-glass.xml -o out/default.exr --png --spp 64
echo "image: $(pwd)/out/default.png (linear HDR: $(pwd)/out/default.exr)"
