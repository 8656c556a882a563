#!/usr/bin/env bash
# Installs the Debian 12 packages envgi builds and tests with. Idempotent: packages already
# installed are skipped, and apt is not touched when nothing is missing.
set -euo pipefail

PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libembree-dev libtbb-dev libopenexr-dev libstb-dev libjpeg62-turbo-dev zlib1g-dev
  libtinyobjloader-dev libpugixml-dev libcli11-dev nlohmann-json3-dev
  libfmt-dev libspdlog-dev libnanoflann-dev
  libgtest-dev libbenchmark-dev
  libboost-dev
  # The relocatable package is a .tar.xz (scripts/package.sh).
  xz-utils
  # The viewer's browser test drives a real headless Chromium.
  chromium
  # import envgi: the module (pybind11) for Debian's Python, and what its tests use.
  python3-dev pybind11-dev python3-numpy python3-pytest
  # The example notebook (examples/strategies.ipynb) plots with matplotlib.
  python3-matplotlib
)

missing=()
for p in "${PKGS[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#PKGS[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done"
