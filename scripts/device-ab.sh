#!/usr/bin/env bash
# A/B of GPU benchmark builds on a device machine, alternating so that drift hits all alike.
#
#   bash scripts/device-ab.sh PACKAGE.tar.xz ROUNDS NAME=BENCH[.gz|.xz] ... [-- BENCH ARGS]
#
# PACKAGE is envgi's relocatable package (cpack -G TXZ); it supplies the libraries. Each BENCH
# is an envgi_bench_gpu built here for one variant (e.g. -DCMAKE_CUDA_ARCHITECTURES=90, one
# build folder, a variant at a time), compressed to fit the carry limit. Each round runs every
# variant once and prints its buddha rows and its path kernel's registers. Arguments after --
# go to every run (default --no-cpu). ROWS (an extended regex) picks the lines printed from each
# run's output (default: the buddha rows and the path kernel's registers).
set -euo pipefail
[[ $# -ge 3 ]] || { sed -n 2,10p "$0"; exit 2; }
package=$1 rounds=$2
shift 2
names=() args=(--no-cpu)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar xf "$package" -C "$work"
root=$(echo "$work"/envgi-*)
while [[ $# -gt 0 ]]; do
  if [[ $1 == -- ]]; then shift; args=("$@"); break; fi
  name=${1%%=*} file=${1#*=}
  case $file in
    *.xz) xz -dc "$file" >"$root/bin/ab_$name" ;;
    *.gz) gunzip -c "$file" >"$root/bin/ab_$name" ;;
    *) cp "$file" "$root/bin/ab_$name" ;;
  esac
  chmod +x "$root/bin/ab_$name"
  names+=("$name")
  shift
done
export LD_LIBRARY_PATH=$root/lib
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader || true
for ((k = 1; k <= rounds; ++k)); do
  for name in "${names[@]}"; do
    out=$("$root/bin/ab_$name" "${args[@]}" 2>&1 || true)
    echo "round $k $name: $(grep -E "${ROWS:-^\| buddha|path kernel}" <<<"$out" | tr '\n' ' ')"
  done
done
