#!/usr/bin/env bash
# Fuzzes envgi's file readers, map sampling and viewer messages with libFuzzer (clang,
# AddressSanitizer, UBSan):
#   bash scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]   targets: image mesh scene envmap view
#                                                           (all of tests/fuzz/fuzz_*.cpp by default)
# Builds in build-fuzz, starts each target from its checked-in corpus (tests/fuzz/corpus) and
# keeps what it finds in build-fuzz/findings/TARGET: crash-*, timeout-*, oom-* inputs to add to
# the corpus once fixed (the unit suite replays that corpus in every build).
set -euo pipefail
cd "$(dirname "$0")/.."
secs=${1:-120}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for f in tests/fuzz/fuzz_*.cpp; do targets+=("$(basename "$f" .cpp | sed 's/^fuzz_//')"); done
fi
command -v clang++ >/dev/null || { echo "fuzz.sh: needs clang (apt-get install clang)" >&2; exit 2; }
CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DENVGI_CUDA=OFF \
  -DENVGI_BENCH=OFF -DENVGI_GPU_TOOLS=OFF -DENVGI_SANITIZE=ON -DENVGI_FUZZ=ON > build-fuzz.cmake.log
ninja -C build-fuzz $(printf 'envgi_fuzz_%s ' "${targets[@]}") > /dev/null
status=0
for t in "${targets[@]}"; do
  work=build-fuzz/corpus/$t findings=build-fuzz/findings/$t
  mkdir -p "$work" "$findings"
  cp -n tests/fuzz/corpus/$t/* "$work"/
  echo "fuzz.sh: $t for ${secs} s"
  # RSS grows slowly across millions of runs (allocator caches), so the limit that matters is
  # the one on a single allocation.
  dict=()
  [ -f tests/fuzz/$t.dict ] && dict=(-dict="$PWD/tests/fuzz/$t.dict")
  if ! (cd "$findings" && "$OLDPWD/build-fuzz/tests/fuzz/envgi_fuzz_$t" "$OLDPWD/$work" "${dict[@]}" -max_len=4096 \
        -timeout=10 -rss_limit_mb=6000 -malloc_limit_mb=2048 -max_total_time="$secs" \
        -print_final_stats=1 > ../$t.log 2>&1); then
    echo "fuzz.sh: $t found a defect: $(grep -m1 -E 'SUMMARY|ERROR' build-fuzz/findings/$t.log)"
    ls "$findings"
    status=1
  else
    grep -E 'stat::number_of_executed_units' build-fuzz/findings/$t.log | sed "s/^/fuzz.sh: $t: /"
  fi
done
exit $status
