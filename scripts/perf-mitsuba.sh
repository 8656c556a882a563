#!/usr/bin/env bash
# envgi against Mitsuba 3 at equal samples and equal time on envgi's example scenes
# (docs/performance.md). Installs Mitsuba into .venv-mitsuba as crosscheck-mitsuba.sh does
# (this downloads, so it is not part of CI). Extra arguments go to scripts/perf_compare.py.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/mitsuba-venv.sh
.venv-mitsuba/bin/python scripts/perf_compare.py --renderer mitsuba --envgi build/bin/envgi --scenes scenes "$@"
