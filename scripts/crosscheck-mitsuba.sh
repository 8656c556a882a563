#!/usr/bin/env bash
# The independent cross-check: installs Mitsuba 3 from PyPI into a virtual environment
# (.venv-mitsuba; this downloads, so it is not part of CI), builds envgi, and renders a
# white-furnace matrix and the bundled scenes in both renderers from the same XML.
# Extra arguments go to scripts/crosscheck_mitsuba.py (e.g. --seeds 8 --spp 128 --only furnace).
set -euo pipefail
cd "$(dirname "$0")/.."
if [[ ! -x .venv-mitsuba/bin/python ]]; then
  if ! python3 -m venv .venv-mitsuba 2>/dev/null; then
    SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
    $SUDO apt-get install -y -qq python3-venv >/dev/null
    python3 -m venv .venv-mitsuba
  fi
  .venv-mitsuba/bin/pip install -q mitsuba numpy
fi
[[ -x build/bin/envgi ]] || bash scripts/build.sh
.venv-mitsuba/bin/python scripts/crosscheck_mitsuba.py --envgi build/bin/envgi --scenes scenes "$@"
