#!/usr/bin/env bash
# Installs the Debian 12 packages envgi builds and tests with, and Ray from PyPI into .venv.
# Idempotent: packages already installed are skipped, and neither apt nor pip is touched when
# nothing is missing.
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
  python3-dev python3-venv pybind11-dev python3-numpy python3-pytest
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
else
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
  echo "install-deps: done"
fi

# What Debian does not package, from PyPI into .venv beside the checkout: Ray, for renders past
# one machine (envgi.distributed). The venv sees Debian's Python packages (numpy, pytest), and
# CMake builds the module for its interpreter, which is Debian's python3.
RAY_VERSION=2.60.0
VENV="$(cd "$(dirname "$0")/.." && pwd)/.venv"
if [[ ! -x "$VENV/bin/python" ]]; then
  /usr/bin/python3 -m venv --system-site-packages "$VENV"
fi
if ! "$VENV/bin/python" -c "import ray, sys; sys.exit(ray.__version__ != '$RAY_VERSION')" 2>/dev/null; then
  echo "install-deps: installing ray $RAY_VERSION from PyPI into .venv"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check "ray==$RAY_VERSION"
fi
