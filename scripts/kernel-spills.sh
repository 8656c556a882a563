#!/usr/bin/env bash
# Registers, stack frame and spills of the path kernel (regenKernel over SampleIntegrator<BvhTracer>)
# as ptxas reports them, for sm_90, without a GPU: the kernel alone is compiled (about 2 minutes)
# for each resident-threads count given (ENVGI_CUDA_THREADS_PER_SM; default 1536, the build's;
# docs/gpu.md). The figures are bytes of spill code (static), not traffic.
#
#   bash scripts/kernel-spills.sh [SOURCE_TREE] [THREADS_PER_SM ...]
set -euo pipefail
root=$(cd "${1:-$(dirname "$0")/..}" && pwd)
shift || true
counts=("$@")
[[ ${#counts[@]} -gt 0 ]] || counts=(1536)
# Every count checked before the first 2-minute compile (CMakeLists.txt's rule for the setting).
for n in "${counts[@]}"; do
  if ! [[ $n =~ ^[0-9]+$ ]] || ((n < 128 || n > 2048 || n % 128 != 0)); then
    echo "error: threads per SM must be 128 to 2048, a multiple of 128, not '$n'" >&2
    exit 2
  fi
done
nvcc=${CUDACXX:-/usr/local/cuda/bin/nvcc}
[[ -x $nvcc ]] || { echo "error: nvcc not found (set CUDACXX)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The kernel itself, instantiated alone; its launch bounds follow ENVGI_CUDA_THREADS_PER_SM
# (a tree older than that setting keeps its own 1536).
cat >"$work/probe.cu" <<'CU'
#include "gpu/CudaPassExecutor.cuh"
namespace envgi::gpu {
template __global__ void regenKernel<SampleIntegrator<BvhTracer>>(SampleIntegrator<BvhTracer>, Camera, SampleSequence,
                                                                  int, int, FilmView, unsigned long long*);
}  // namespace envgi::gpu
CU
for n in "${counts[@]}"; do
  "$nvcc" -DENVGI_HAS_CUDA=1 -I"$root/src" -O3 -DNDEBUG --generate-code=arch=compute_90,code=sm_90 \
    --expt-relaxed-constexpr -std=c++17 -DENVGI_CUDA_THREADS_PER_SM=$n -Xptxas -v -x cu -c "$work/probe.cu" \
    -o "$work/probe.o" >"$work/ptxas.txt" 2>&1 || { cat "$work/ptxas.txt" >&2; exit 1; }
  echo "threads per SM $n:"
  # One line a function: the kernel, then each function ptxas kept out of it (name without its
  # namespaces, template arguments and parameters).
  c++filt <"$work/ptxas.txt" | awk '
    /Function properties for/ {
      n = $0; sub(/.*Function properties for /, "", n)
      if (n ~ /regenKernel/) n = "kernel"
      else { sub(/\(.*/, "", n); while (n ~ /<[^<>]*>/) gsub(/<[^<>]*>/, "", n); sub(/.* /, "", n); sub(/.*::/, "", n) }
    }
    /stack frame/ { printf "  %-26s stack frame %5d B, spill stores %5d B, spill loads %5d B\n", n, $1, $5, $9 }
    /Used [0-9]+ registers/ && n == "kernel" { printf "  %-26s %d registers\n", "kernel", $5 }'
done
