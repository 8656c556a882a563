#!/usr/bin/env bash
# The grid integrator's error and cost against path on the bundled scenes (docs/grid.md):
# a 2048-spp path reference at 256^2, then grid at 4, 16 and 256 spp (photons and grid fill
# included in its time; 256 spp shows its bias floor) and path at about the same wall time.
# Prints a markdown table.
# Usage: scripts/measure-grid.sh [OUTDIR]   (build first: scripts/build.sh)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
envgi="$root/build/bin/envgi"
out="${1:-$root/build/grid-measure}"
mkdir -p "$out"
secs() { local t0 t1; t0=$(date +%s.%N); "$@" > /dev/null 2>&1; t1=$(date +%s.%N); awk -v a="$t0" -v b="$t1" 'BEGIN {print b - a}'; }
rmse() { "$envgi" compare "$1" "$2" | awk 'NR==3 {print $3}'; }
echo "| scene | method | spp | seconds | RMSE |"
echo "| --- | --- | --- | --- | --- |"
for sc in buddha cornell-box teapot-glass; do
  ref="$out/ref_$sc.pfm"
  [ -f "$ref" ] || "$envgi" render "$root/scenes/$sc.xml" -D res=256 --integrator path --strategy mis --spp 2048 \
    -o "$ref" --no-progress > /dev/null 2>&1
  # path's cost: a fixed part (loading, Embree) and a per-sample part, from two probes
  t4=$(secs "$envgi" render "$root/scenes/$sc.xml" -D res=256 --integrator path --strategy mis --spp 4 --seed 7 \
    -o "$out/probe.pfm" --no-progress)
  t20=$(secs "$envgi" render "$root/scenes/$sc.xml" -D res=256 --integrator path --strategy mis --spp 20 --seed 7 \
    -o "$out/probe.pfm" --no-progress)
  for spp in 4 16 256; do
    t=$(secs "$envgi" render "$root/scenes/$sc.xml" -D res=256 --integrator grid --strategy mis --spp $spp \
      --seed 7 -o "$out/grid_${sc}_$spp.pfm" --no-progress)
    echo "| $sc | grid | $spp | $(printf %.2f "$t") | $(rmse "$ref" "$out/grid_${sc}_$spp.pfm") |"
    pspp=$(awk -v t="$t" -v a="$t4" -v b="$t20" 'BEGIN {r = 16 / (b - a); f = a - 4 / r; n = int((t - f) * r);
      print (n < 1 ? 1 : n)}')
    t2=$(secs "$envgi" render "$root/scenes/$sc.xml" -D res=256 --integrator path --strategy mis --spp "$pspp" \
      --seed 7 -o "$out/path_${sc}_$spp.pfm" --no-progress)
    echo "| $sc | path, same time | $pspp | $(printf %.2f "$t2") | $(rmse "$ref" "$out/path_${sc}_$spp.pfm") |"
  done
done
