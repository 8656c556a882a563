"""Ray's overhead on one machine: the same render (samples and image) in one process and as
Ray tasks over sample ranges, each a task of one CPU, on a local Ray that this script starts.

    PYTHONPATH=build/python .venv/bin/python bench/ray_overhead.py [--res 256] [--spp 256]

Prints each side's median of --repeats timed renders (after one untimed render each, which
loads the scene and builds its BVH in every worker), their ratio and the images' largest
relative difference."""

import argparse
import os
import statistics
import time
from pathlib import Path

import numpy as np

import envgi
import envgi.distributed as ed

SOURCE = Path(__file__).resolve().parents[1]


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(SOURCE / "scenes" / "buddha.xml"))
    p.add_argument("--res", type=int, default=256)
    p.add_argument("--spp", type=int, default=256)
    p.add_argument("--repeats", type=int, default=5)
    a = p.parse_args()
    cpus = os.cpu_count()
    os.environ.setdefault("RAY_AUTH_MODE", "disabled")
    import ray

    ray.init(num_cpus=cpus, include_dashboard=False, log_to_driver=False)
    scene = envgi.load_file(a.scene, res=a.res)

    def local():
        return envgi.render(scene, spp=a.spp, device="cpu", threads=cpus, progress=False)

    def on_ray():
        return ed.render(a.scene, spp=a.spp, parts=cpus, device="cpu", threads=1, progress=False, res=a.res)

    times = {}
    images = {}
    for name, run in (("one process", local), ("Ray", on_ray)):
        images[name] = run()
        spans = []
        for _ in range(a.repeats):
            t0 = time.perf_counter()
            run()
            spans.append(time.perf_counter() - t0)
        times[name] = statistics.median(spans)
    one, split = images["one process"], images["Ray"]
    diff = float(np.max(np.abs(split - one) / np.maximum(np.abs(one), 1e-3)))
    print(f"{Path(a.scene).name} {a.res}x{a.res}, {a.spp} spp, {cpus} CPUs, Ray {ray.__version__}, "
          f"median of {a.repeats}")
    print(f"  one process ({cpus} threads): {times['one process']:.3f} s")
    print(f"  Ray, {cpus} tasks of one CPU: {times['Ray']:.3f} s")
    print(f"  Ray / one process: {times['Ray'] / times['one process']:.3f}; largest relative difference {diff:.2e}")
    ray.shutdown()


if __name__ == "__main__":
    main()
