#!/usr/bin/env bash
# envgi against Blender Cycles at equal samples and equal time on envgi's example scenes: the
# three map-lit ones and the Cornell box with its area light (docs/performance.md). Needs Blender
# (Debian 12: `apt-get install blender`, Cycles 3.4.1, the version the goal was set against) and
# the Python of .venv-mitsuba for numpy and EXR reading, set up as perf-mitsuba.sh does (a
# download, so neither is part of CI). Extra arguments go to scripts/perf_compare.py.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v blender >/dev/null; then
  echo "perf-cycles.sh: error: no blender on PATH (apt-get install blender)" >&2
  exit 2
fi
source scripts/mitsuba-venv.sh
.venv-mitsuba/bin/python scripts/perf_compare.py --renderer cycles --envgi build/bin/envgi --scenes scenes \
  --scene-names buddha,teapot-glass,bunny-sunrise,cornell-box,textured "$@"
