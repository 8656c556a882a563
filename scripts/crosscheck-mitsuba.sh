#!/usr/bin/env bash
# The independent cross-check: installs Mitsuba 3 from PyPI into a virtual environment
# (.venv-mitsuba; this downloads, so it is not part of CI), builds envgi, and renders a
# white-furnace matrix and the bundled scenes in both renderers from the same XML.
# Extra arguments go to scripts/crosscheck_mitsuba.py (e.g. --seeds 8 --spp 128 --only furnace).
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mitsuba-venv.sh
.venv-mitsuba/bin/python scripts/crosscheck_mitsuba.py --envgi build/bin/envgi --scenes scenes "$@"
