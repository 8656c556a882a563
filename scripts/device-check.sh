#!/usr/bin/env bash
# The GPU checks, run from the relocatable package on a machine with an NVIDIA GPU (and nothing
# else installed): the kernel check, a CLI render per integrator on the device, the viewer's
# server, the GPU test suite, the GPU benchmark, and the study on the GPU against the CPU. Each step has its own time limit, so one hang cannot eat the
# machine's time. A summary line per step goes to stdout; into LOGDIR go device-check.log (every
# step's whole log) and device-check-images.tar (the renders).
#   bash scripts/device-check.sh build-package/envgi-*-cuda.tar.xz [DRAGON.ply]
# LOGDIR defaults to $OUT (the device tool's folder) or out/device-check. STEPS picks steps by
# name (default: "check render view interrupt tests bench bench_stages bench_stages_wide study";
# also bench_perpixel, the path kernel without path regeneration); a failed step is followed by a compute-sanitizer
# run of a tiny render when `compute-sanitizer` is on the PATH.
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
pkg=${1:?usage: device-check.sh PACKAGE.tar.xz [DRAGON.ply]}
dragon=${2:-}
logdir=${LOGDIR:-${OUT:-out/device-check}}
steps=${STEPS:-check render view interrupt tests bench bench_stages bench_stages_wide study}
mkdir -p "$logdir"
rm -f "$logdir/device-check.log"
work=$(mktemp -d)
logs=$work/logs
mkdir -p "$logs"
tar xf "$pkg" -C "$work" || { echo "device-check: cannot unpack $pkg"; exit 1; }
root=$(echo "$work"/envgi-*)
bin=$root/bin
scenes=$root/share/envgi/scenes
failed=0

# step NAME LIMIT_S COMMAND...: runs COMMAND with a time limit, its output to logs/NAME.log.
step() {
  local name=$1 limit=$2
  shift 2
  local t0=$SECONDS
  timeout --kill-after=5 "$limit" "$@" >"$logs/$name.log" 2>&1
  local rc=$?
  local verdict=ok
  if [ $rc -eq 124 ] || [ $rc -eq 137 ]; then verdict="TIMED OUT after ${limit}s"; failed=1
  elif [ $rc -eq 77 ]; then verdict="skipped (no device)"
  elif [ $rc -ne 0 ]; then verdict="FAILED (exit $rc)"; failed=1; fi
  printf '%-24s %-22s %4ds\n' "$name" "$verdict" $((SECONDS - t0))
  # Appended as each step ends, so that what finished survives a caller's own time limit.
  { echo "=== $name: $verdict"; cat "$logs/$name.log"; } >>"$logdir/device-check.log"
}

# `envgi view --device cuda` from the command line: the server starts on the GPU, serves the
# page, and Ctrl-C (SIGINT) stops it with exit code 0.
view_smoke() {
  "$1/envgi" view "$2/buddha.xml" --device cuda --port 18734 &
  local pid=$! ok=1
  for _ in $(seq 50); do
    if python3 -c "import urllib.request as u; assert u.urlopen('http://127.0.0.1:18734/', timeout=1).status == 200" \
      2>/dev/null; then ok=0; break; fi
    sleep 0.2
  done
  kill -INT $pid
  wait $pid || return 1
  [ $ok -eq 0 ] || { echo "view_smoke: the page was not served"; return 1; }
  echo "view_smoke: page served, server stopped cleanly"
}

# The paper's study (docs/study.md's command) on the GPU and on the CPU: the wall time of each,
# and their RMSE tables compared (scripts/compare_study.py).
study_both() {
  local args=(study "$2/buddha.xml" -D res=128 --reference-spp 2048 --seeds 2 --time 0.5,2)
  local t0=$SECONDS
  "$1/envgi" -q "${args[@]}" -o "$3/study-cuda" --device cuda || return 1
  echo "study on the GPU: $((SECONDS - t0)) s"
  t0=$SECONDS
  "$1/envgi" -q "${args[@]}" -o "$3/study-cpu" --device cpu || return 1
  echo "study on the CPU ($(nproc) cores): $((SECONDS - t0)) s"
  cat "$3/study-cuda/results.csv"
  python3 "$4" "$3/study-cuda/results.csv" "$3/study-cpu/results.csv"
}

# Ctrl-C during a long GPU render: the finished passes are written, the exit is clean, and how
# long after the signal it came (a pass runs to its end first).
interrupt_check() {
  "$1/envgi" render "$2/buddha.xml" --device cuda -D res=1024 --spp 1000000 -o "$3/long.exr" --no-progress &
  local pid=$!
  sleep 5
  local t0
  t0=$(date +%s.%N)
  kill -INT $pid
  wait $pid
  local rc=$?
  echo "exit $rc, $(python3 -c "print(f'{$(date +%s.%N) - $t0:.2f}')") s after SIGINT"
  [ $rc -eq 0 ] && [ -s "$3/long.exr" ]
}

command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
for s in $steps; do
  case $s in
    check) step cuda_check 60 "$bin/envgi_cuda_check" ;;
    render)
      for integ in path direct sppm grid photon; do
        step "render_$integ" 60 "$bin/envgi" render "$scenes/buddha.xml" --device cuda --integrator "$integ" \
          -D res=256 --spp 64 -o "$logs/buddha_$integ.png"
      done ;;
    tests) step gpu_tests 240 "$bin/envgi_gpu_tests" ;;
    interrupt) step interrupt 60 bash -c "$(declare -f interrupt_check); interrupt_check '$bin' '$scenes' '$work'" ;;
    study) step study 240 bash -c "$(declare -f study_both); study_both '$bin' '$scenes' '$work' '$here/compare_study.py'" ;;
    view) step view_server 60 bash -c "$(declare -f view_smoke); view_smoke '$bin' '$scenes'" ;;
    bench)
      if [ -n "$dragon" ]; then step bench_gpu 180 "$bin/envgi_bench_gpu" --dragon "$dragon"
      else step bench_gpu 180 "$bin/envgi_bench_gpu"; fi ;;
    bench_perpixel)  # the path kernel without path regeneration, for an A/B with "bench"
      ENVGI_GPU_REGEN=0 step bench_perpixel 120 "$bin/envgi_bench_gpu" --no-cpu ${dragon:+--dragon "$dragon"} ;;
    bench_stages)  # the path and direct kernels as wave stages (a kernel a stage and material kind)
      ENVGI_GPU_STAGES=1 step bench_stages 120 "$bin/envgi_bench_gpu" --no-cpu ${dragon:+--dragon "$dragon"} ;;
    bench_stages_wide)  # the same with the shade kernels at up to 128 registers (4 blocks an SM)
      ENVGI_GPU_STAGES=wide step bench_stages_wide 120 "$bin/envgi_bench_gpu" --no-cpu ${dragon:+--dragon "$dragon"} ;;
    *) echo "device-check: unknown step $s"; exit 2 ;;
  esac
done
if [ $failed -ne 0 ] && command -v compute-sanitizer >/dev/null; then
  step sanitizer_path 120 compute-sanitizer --tool memcheck --print-limit 20 "$bin/envgi" render "$scenes/buddha.xml" \
    --device cuda --integrator path -D res=32 --spp 2 -o "$logs/sanitizer.png"
fi
(cd "$logs" && tar cf "$logdir/device-check-images.tar" --ignore-failed-read ./*.png 2>/dev/null)
# The end of each log, so that a caller who sees only stdout still sees the figures.
for f in "$logs"/*.log; do echo "=== $(basename "$f")"; tail -n 25 "$f"; done
rm -rf "$work"
exit $failed
