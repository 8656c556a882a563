#!/usr/bin/env bash
# Checks a relocatable package (scripts/package.sh, or cpack in a build folder): under 48 MB
# (the device tool carries 64 MB: the rest is room for A/B benchmark builds beside it),
# needing nothing from the system but the C library, and rendering from where it was unpacked.
# Usage: scripts/check-package.sh PATH/envgi-*.tar.xz
set -euo pipefail
pkg=$(realpath "$1")
size=$(stat -c %s "$pkg")
echo "check-package: $(basename "$pkg"): $((size / 1024 / 1024)) MB"
((size < 48 * 1024 * 1024)) || { echo "check-package: larger than 48 MB"; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
tar xf "$pkg" -C "$dir"
root=$(echo "$dir"/envgi-*)
for b in "$root"/bin/*; do
  outside=$(ldd "$b" | grep '=>' | grep -v "$root/bin/../lib/" | grep -Ev '/(libc|libm|libdl|libpthread|librt)\.so' || true)
  if [[ -n "$outside" ]]; then
    echo "check-package: $(basename "$b") loads libraries from outside the package:"
    echo "$outside"
    exit 1
  fi
done
(cd "$dir" && env -i PATH=/usr/bin:/bin "$root/bin/envgi" render "$root/share/envgi/scenes/buddha.xml" \
  -o "$dir/b.png" -D res=32 --spp 2 --no-progress --device auto)
test -s "$dir/b.png"
rc=0
env -i PATH=/usr/bin:/bin "$root/bin/envgi_gpu_tests" >"$dir/gpu.log" 2>&1 || rc=$?
if [[ $rc -ne 0 && $rc -ne 77 ]]; then cat "$dir/gpu.log"; exit 1; fi
echo "check-package: ok (GPU test: $([[ $rc -eq 77 ]] && echo 'skipped, no device' || echo passed))"
