#!/usr/bin/env bash
# Registers, stack frame and spills as ptxas reports them, for sm_90, without a GPU: of the path
# kernel (regenKernel over SampleIntegrator<BvhTracer>), compiled alone (about 2 minutes) for each
# resident-threads count given (ENVGI_CUDA_THREADS_PER_SM; default 1536, the build's); then of
# each wave stage's kernel at its own launch bounds (wavefront/CudaStageLaunch.cuh), as a table
# (docs/gpu.md). The figures are bytes of spill code (static), not traffic.
#
#   bash scripts/kernel-spills.sh [SOURCE_TREE] [THREADS_PER_SM ...]
# STAGES=0 leaves the stage kernels out; STAGES=only leaves the path kernel out.
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
stages=${STAGES:-1}
[[ $stages == only ]] && counts=()
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

[[ $stages == 0 ]] && exit 0
# The stage kernels, each instantiated alone: one a stage, and a shade stage a material kind.
{
  echo '#include "accel/BvhView.h"'
  echo '#include "wavefront/CudaStageLaunch.cuh"'
  echo 'namespace envgi {'
  echo 'using I = SampleIntegrator<BvhTracer>;'
  for st in 'CameraStage<I>' 'ClosestHitStage<I>' 'EscapeStage<I>' 'ShadowStage<I>' 'DirectSampleStage<I>' 'FilmStage'; do
    echo "template __global__ void stageKernel<$st>($st, int, const int*);"
  done
  for k in 0 1 2 3 4 5 6 7 8 9; do
    echo "template __global__ void stageKernel<ShadeStage<I, $k>>(ShadeStage<I, $k>, int, const int*);"
    echo "template __global__ void wideStageKernel<ShadeStage<I, $k>>(ShadeStage<I, $k>, int, const int*);"
  done
  echo '}  // namespace envgi'
} >"$work/stages.cu"
"$nvcc" -DENVGI_HAS_CUDA=1 -I"$root/src" -O3 -DNDEBUG --generate-code=arch=compute_90,code=sm_90 \
  --expt-relaxed-constexpr -std=c++17 -Xptxas -v -x cu -c "$work/stages.cu" -o "$work/stages.o" \
  >"$work/stages.txt" 2>&1 || { cat "$work/stages.txt" >&2; exit 1; }
# A row a kernel: its own figures, then its spills with those of the functions ptxas kept out of
# it (each kernel has its own copies).
echo "stage kernels (launch bounds 128 threads x 8 blocks an SM: at most 64 registers; rows"
echo "', 4 blocks': the shade kernels of ENVGI_GPU_STAGES=wide, at most 128 registers):"
echo "| kernel | registers | stack frame (B) | spill stores / loads (B) | with out-of-line calls (B) |"
echo "| --- | --- | --- | --- | --- |"
c++filt <"$work/stages.txt" | awk '
  BEGIN { split("diffuse conductor roughconductor dielectric thindielectric roughdielectric plastic roughplastic principled blend", kind, " ") }
  /Compiling entry function/ {
    n = $0
    wide = n ~ /wideStageKernel/
    if (match(n, /ShadeStage<envgi::SampleIntegrator<envgi::BvhTracer>, [0-9]/)) n = "shade " kind[substr(n, RSTART + RLENGTH - 1, 1) + 1] (wide ? ", 4 blocks" : "")
    else { sub(/Stage.*/, "", n); sub(/.*[sS]tageKernel<envgi::/, "", n); n = tolower(n) }
    order[++m] = n; cur = n
  }
  /Function properties for/ { isKernel = $0 ~ /[sS]tageKernel/ }
  /stack frame/ {
    if (isKernel) { stack[cur] = $1; st[cur] = $5; ld[cur] = $9 }
    allSt[cur] += $5; allLd[cur] += $9
  }
  /Used [0-9]+ registers/ { regs[cur] = $5 }
  END { for (i = 1; i <= m; ++i) { n = order[i]; printf "| %s | %d | %d | %d / %d | %d / %d |\n", n, regs[n], stack[n], st[n], ld[n], allSt[n], allLd[n] } }'
