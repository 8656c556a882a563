#!/usr/bin/env bash
# The Cycles harness (scripts/cycles_render.py) checked against envgi on the example scenes:
# needs Blender (apt-get install blender) and .venv-mitsuba (for EXR reading; a download, so
# neither is part of CI). Exits 77, which ctest reports as skipped, without Blender.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v blender >/dev/null; then
  echo "crosscheck-cycles.sh: skipped: no blender on PATH (apt-get install blender)"
  exit 77
fi
source scripts/mitsuba-venv.sh
.venv-mitsuba/bin/python scripts/crosscheck_cycles.py --envgi build/bin/envgi --scenes scenes "$@"
