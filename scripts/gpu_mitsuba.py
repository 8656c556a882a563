#!/usr/bin/env python3
"""Mitsuba 3 on envgi_bench_gpu's scene, for a same-machine comparison of the GPU renderers.

The bundled Happy Buddha in Grace Cathedral at 512^2 with every surface a GGX conductor
(alpha 0.15, perfect reflector) and `path` to depth 8, as bench/bench_gpu.cpp renders it.
Prints Mitsuba's milliseconds per 1-spp frame (median of --frames, after warm-up renders that
compile its kernels) and its M samples/s over a --spp render, like the benchmark's table.
    python3 scripts/gpu_mitsuba.py [--variant cuda_ad_rgb] [--frames 21] [--spp 64]
"""
import argparse
import os
import re
import statistics
import time

import drjit as dr
import mitsuba as mi

HERE = os.path.dirname(os.path.abspath(__file__))


def bench_scene(res):
    xml = os.path.join(HERE, '..', 'scenes', 'buddha.xml')
    text = open(xml).read()
    text = re.sub(r'<integrator type="direct">.*?</integrator>',
                  '<integrator type="path"><integer name="max_depth" value="8"/></integrator>', text, flags=re.S)
    text = re.sub(r'<bsdf type="twosided">.*</bsdf>\s*</bsdf>',
                  '<bsdf type="twosided"><bsdf type="roughconductor"><string name="material" value="none"/>'
                  '<float name="alpha" value="0.15"/><string name="distribution" value="ggx"/></bsdf></bsdf>',
                  text, flags=re.S)
    mi.file_resolver().prepend(os.path.dirname(os.path.abspath(xml)))
    return mi.load_string(text, res=str(res), spp='1')


def timed_render(scene, spp):
    t = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=0)
    dr.eval(img)
    dr.sync_thread()
    return time.perf_counter() - t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument('--variant', default='cuda_ad_rgb')
    ap.add_argument('--res', type=int, default=512)
    ap.add_argument('--frames', type=int, default=21)
    ap.add_argument('--spp', type=int, default=64)
    a = ap.parse_args()
    mi.set_variant(a.variant)
    scene = bench_scene(a.res)
    t0 = time.perf_counter()
    for _ in range(3):
        timed_render(scene, 1)
    print(f'mitsuba {mi.__version__} {a.variant}: warm-up (kernel compilation) {time.perf_counter() - t0:.2f} s')
    frames = sorted(timed_render(scene, 1) for _ in range(a.frames))
    timed_render(scene, a.spp)  # its own kernel for this sample count
    run = statistics.median(timed_render(scene, a.spp) for _ in range(3))
    print(f'| buddha-100k | mitsuba {a.variant} | {1e3 * frames[len(frames) // 2]:.2f} | {a.spp} | '
          f'{a.res * a.res * a.spp / run / 1e6:.2f} | - |')


if __name__ == '__main__':
    main()
