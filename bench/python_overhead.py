"""What `import envgi` adds to a render, on the machine it runs on.

    PYTHONPATH=build/python .venv/bin/python bench/python_overhead.py

1. A sweep step: envgi.render of a loaded scene at 64x64 and 1 spp, its wall time less the
   render's own seconds (stats=True), median over --repeats calls.
2. The same work from Python and from the CLI: the render's seconds as each reports them (the
   passes, as `envgi render` prints "done in"), and Python's whole call, each the median of
   --repeats, alternating.
"""

import argparse
import os
import re
import statistics
import subprocess
import time
from pathlib import Path

import envgi

SOURCE = Path(__file__).resolve().parents[1]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(SOURCE / "scenes" / "buddha.xml"))
    p.add_argument("--repeats", type=int, default=7)
    p.add_argument("--res", type=int, default=256)
    p.add_argument("--spp", type=int, default=64)
    a = p.parse_args()
    cli = os.environ.get("ENVGI_CLI", str(SOURCE / "build" / "bin" / "envgi"))

    small = envgi.load_file(a.scene, res=64)
    envgi.render(small, spp=1, progress=False)  # the BVH, built once
    overheads, renders = [], []
    for _ in range(max(a.repeats, 20)):
        t0 = time.perf_counter()
        _, st = envgi.render(small, spp=1, progress=False, stats=True)
        overheads.append(time.perf_counter() - t0 - st["seconds"])
        renders.append(st["seconds"])
    print(f"sweep step, 64x64 at 1 spp: render {1e3 * statistics.median(renders):.2f} ms, "
          f"overhead {1e3 * statistics.median(overheads):.2f} ms (median of {len(overheads)})")

    scene = envgi.load_file(a.scene, res=a.res)
    envgi.render(scene, spp=1, progress=False)
    py, wall, cl = [], [], []
    for _ in range(a.repeats):
        t0 = time.perf_counter()
        _, st = envgi.render(scene, spp=a.spp, progress=False, stats=True)
        wall.append(time.perf_counter() - t0)
        py.append(st["seconds"])
        out = subprocess.run([cli, "render", a.scene, "-o", "/tmp/envgi-bench.exr",
                              "--spp", str(a.spp), "-D", f"res={a.res}", "--no-progress"],
                             capture_output=True, text=True, check=True)
        cl.append(float(re.search(r"done in ([0-9.]+) s", out.stdout + out.stderr).group(1)))
    mp, mc, mw = statistics.median(py), statistics.median(cl), statistics.median(wall)
    print(f"{Path(a.scene).name} {a.res}x{a.res}, {a.spp} spp, the render's seconds: Python {mp:.3f} s, CLI {mc:.3f} s, "
          f"Python / CLI {mp / mc:.3f}; Python's whole call {mw:.3f} s (medians of {a.repeats}, alternating)")


if __name__ == "__main__":
    main()
