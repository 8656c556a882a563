#!/usr/bin/env bash
# ENVGI_CUDA_THREADS_PER_SM (CMakeLists.txt) and scripts/kernel-spills.sh refuse a count that is
# not 128 to 2048 and a multiple of 128, each with one error line and a non-zero exit, before any
# compile. CMake wraps its message, so it is compared with the lines joined.
# Usage: test_ThreadsPerSmSetting.sh CMAKE SOURCE_DIR
set -uo pipefail
cmake=$1 src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
for bad in 1000 abc 0 64 4096 -128; do
  rm -rf "$work/b"
  if "$cmake" -S "$src" -B "$work/b" -DENVGI_CUDA=OFF -DENVGI_CUDA_THREADS_PER_SM="$bad" >"$work/out" 2>&1; then
    echo "FAIL: configure accepted ENVGI_CUDA_THREADS_PER_SM=$bad"; fail=1
  elif ! tr -s ' \n' ' ' <"$work/out" | grep -q "ENVGI_CUDA_THREADS_PER_SM must be [^.]*$bad"; then
    echo "FAIL: configure with $bad failed without the setting's message:"; cat "$work/out"; fail=1
  fi
  # The script checks every count before its first compile: a good one ahead of the bad one
  # does not start nvcc.
  bash "$src/scripts/kernel-spills.sh" "$src" 1536 "$bad" >"$work/out" 2>"$work/err"
  rc=$?
  if [[ $rc -ne 2 || $(wc -l <"$work/err") -ne 1 || -s $work/out ]] || ! grep -q "not '$bad'" "$work/err"; then
    echo "FAIL: kernel-spills.sh with $bad: exit $rc, stdout $(wc -c <"$work/out") bytes, stderr:"; cat "$work/err"; fail=1
  fi
done
[[ $fail -eq 0 ]] && echo "ok: 6 bad counts refused by the CMake setting and by kernel-spills.sh"
exit $fail
