#!/usr/bin/env bash
# Makes .venv-mitsuba (Mitsuba 3 and numpy from PyPI; this downloads) unless it exists.
# Sourced by crosscheck-mitsuba.sh and perf-mitsuba.sh from the repository root.
if [[ ! -x .venv-mitsuba/bin/python ]]; then
  if ! python3 -m venv .venv-mitsuba 2>/dev/null; then
    SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
    $SUDO apt-get install -y -qq python3-venv >/dev/null
    python3 -m venv .venv-mitsuba
  fi
  .venv-mitsuba/bin/pip install -q mitsuba numpy
fi
[[ -x build/bin/envgi ]] || bash scripts/build.sh
