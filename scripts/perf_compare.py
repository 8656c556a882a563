#!/usr/bin/env python3
"""envgi's `path` against Mitsuba 3's or Blender Cycles' path tracer on envgi's own example
scenes: RMSE at equal samples and at equal time, each renderer against its own high-sample
reference (so a systematic difference between the two, docs/validation.md, does not count as
noise).

Mitsuba reads the same XML. Cycles reads it through scripts/cycles_render.py, with its nearest
materials; its images therefore differ a little from envgi's, and its RMSE is taken relative to
its own reference's mean (so is envgi's, in that table).

All use a box pixel filter (see mitsuba_scene). Times are render times only: envgi's "done in"
(passes, after loading and Embree), Mitsuba's mi.render after a warm-up render (its kernels
compiled), Cycles' render call less the scene's set-up (a 1-spp render's time, see Cycles).
Run through scripts/perf-mitsuba.sh or scripts/perf-cycles.sh; prints the Markdown table that
docs/performance.md holds.
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import mitsuba as mi
import numpy as np

from crosscheck_mitsuba import ENVGI_ONLY


def envgi_render(envgi, xml, out, spp, seed, res, threads, strategy='product', adaptive=()):
    cmd = [envgi, 'render', xml, '-o', out, '--spp', str(spp), '--seed', str(seed), '--no-progress',
           '--device', 'cpu', '--integrator', 'path', '--strategy', strategy, '-D', f'res={res}', '--threads', str(threads),
           '--filter', 'box'] + list(adaptive)
    log = subprocess.run(cmd, check=True, capture_output=True, text=True)
    m = re.search(r'done in ([0-9.]+) s', log.stdout + log.stderr)
    return np.array(mi.Bitmap(out))[..., :3].astype(np.float64), float(m.group(1))


def mitsuba_scene(xml, res):
    text = ENVGI_ONLY.sub('', open(xml).read())
    # envgi's scenes may name direct; the comparison is of path tracers.
    text = re.sub(r'<integrator type="[a-z]+">', '<integrator type="path">', text)
    text = re.sub(r'<integer name="(emitter_samples|bsdf_samples|shading_samples)"[^>]*/>', '', text)
    # A box filter in both: Mitsuba splats a tent or Gaussian sample over several pixels, envgi
    # importance-samples the filter (one pixel a sample), so with those the per-pixel noise
    # would differ by design, not by the estimators.
    text = re.sub(r'<rfilter type="[a-z]+"\s*/>', '<rfilter type="box"/>', text)
    resolver = mi.file_resolver()
    resolver.prepend(os.path.dirname(os.path.abspath(xml)))
    return mi.load_string(text, res=str(res))


def mitsuba_render(scene, spp, seed):
    t = time.perf_counter()
    img = np.array(mi.render(scene, spp=spp, seed=seed))[..., :3].astype(np.float64)
    return img, time.perf_counter() - t


class Mitsuba:
    name = 'Mitsuba'
    relative = False  # the same scene, the same images: plain RMSE

    def __init__(self, xml, args, out):
        self.scene = mitsuba_scene(xml, args.res)
        mitsuba_render(self.scene, 4, 0)  # compiles its kernels
        self.version = f'Mitsuba {mi.__version__} {args.variant}'

    def render(self, spp, seed):
        return mitsuba_render(self.scene, spp, seed)


class Cycles:
    """Blender's Cycles through scripts/cycles_render.py, one Blender process a render. Its render
    call includes syncing the scene and building its BVH; the median of three 1-spp renders,
    t(1), stands for that, and N samples are taken to cost (t(N) - t(1)) N / (N - 1)."""
    name = 'Cycles'
    relative = True  # nearest materials, not the same BSDFs: RMSE over the reference's mean

    def __init__(self, xml, args, out):
        self.cmd = [args.blender, '-b', '--factory-startup', '-noaudio', '--python',
                    os.path.join(os.path.dirname(os.path.abspath(__file__)), 'cycles_render.py'), '--', xml,
                    '--out', out, '--threads', str(args.threads), '-D', f'res={args.res}', '--envgi', args.envgi]
        self.adaptive = ['--noise-threshold', str(args.noise_threshold), '--min-spp', str(args.min_spp)]
        self.out = out
        # One render first, not timed: the first Blender start after an install or a boot reads
        # its files from disk, and a t(1) that includes it made a 16-spp render look free.
        self.run(1, 0)
        self.setup = statistics.median(self.run(1, 0)[1] for _ in range(3))
        v = subprocess.run([args.blender, '--version'], capture_output=True, text=True).stdout.split('\n')[0]
        self.version = f'{v.strip()} Cycles (CPU)'

    def run(self, spp, seed, adaptive=False):
        log = subprocess.run(self.cmd + ['--spp', str(spp), '--seed', str(seed)] + (self.adaptive if adaptive else []),
                             capture_output=True, text=True)
        m = re.search(r'cycles render: ([0-9.]+) s', log.stdout)
        if log.returncode != 0 or not m:
            raise SystemExit(f'Cycles failed on {" ".join(self.cmd)}:\n{log.stderr[-2000:]}')
        return np.array(mi.Bitmap(self.out))[..., :3].astype(np.float64), float(m.group(1))

    def render(self, spp, seed, adaptive=False):
        img, t = self.run(spp, seed, adaptive)
        if t - self.setup < 0.25 * self.setup:
            print(f'warning: Cycles took {t:.2f} s for {spp} spp, within a quarter of its set-up ({self.setup:.2f} s): '
                  'its time for the samples alone is not measurable at this count', file=sys.stderr)
        if adaptive:  # the samples are not spread evenly: the set-up alone comes off
            return img, max(t - self.setup, 1e-3)
        return img, max(t - self.setup, 1e-3) * spp / max(spp - 1, 1)


def over_seeds(render, ref, seeds, scale=1.0):
    """RMSE over several seeds (the root of their mean squared error), divided by scale, and the
    median time. One seed is not enough on a scene with fireflies: the teapot's glass moves one render's RMSE
    by 10-20% from seed to seed, and with it a ratio near 0.7. The median time, because one
    render's time moves by 10-30% on a shared machine."""
    runs = [render(seed) for seed in seeds]
    mse = statistics.fmean(float(np.mean((img - ref) ** 2)) for img, _ in runs)
    return float(np.sqrt(mse)) / scale, statistics.median(t for _, t in runs)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--envgi', required=True)
    ap.add_argument('--scenes', required=True)
    ap.add_argument('--renderer', choices=('mitsuba', 'cycles'), default='mitsuba')
    ap.add_argument('--blender', default='blender', help='the Blender whose Cycles --renderer cycles runs')
    ap.add_argument('--variant', default='scalar_rgb')  # llvm_ad_rgb aborts in LLVM here (Debian's libLLVM)
    ap.add_argument('--res', type=int, default=256)
    ap.add_argument('--ref-spp', type=int, default=2048)
    ap.add_argument('--spp', default='16,64')
    ap.add_argument('--threads', type=int, default=os.cpu_count())
    ap.add_argument('--strategy', default='product', help="envgi's environment strategy (its default: product)")
    ap.add_argument('--seeds', type=int, default=4,
                    help='renders per measurement, seeds 7, 8, ...: RMSE from their mean squared error, '
                         'the median time')
    ap.add_argument('--scene-names', default='buddha,cornell-box,teapot-glass,bunny-sunrise',
                    help='comma-separated scene files (without .xml) in --scenes to compare on')
    ap.add_argument('--noise-threshold', type=float, default=0.0,
                    help='Cycles only: both renderers with adaptive sampling at this noise threshold, --spp the '
                         'budget; the table then compares at equal budgets (no equal-time search: time is not '
                         'proportional to the budget)')
    ap.add_argument('--min-spp', type=int, default=16, help="adaptive sampling's minimum samples, both renderers")
    args = ap.parse_args()
    if args.noise_threshold > 0 and args.renderer != 'cycles':
        ap.error('--noise-threshold compares with Cycles (Mitsuba has no adaptive sampling)')
    if args.seeds < 1:
        ap.error('--seeds must be at least 1')
    seeds = range(7, 7 + args.seeds)
    mi.set_variant(args.variant)  # also reads the EXR images, for either renderer
    tmp = tempfile.mkdtemp(prefix='envgi_perf_')
    out = os.path.join(tmp, 'e.exr')
    rows = []
    names = [n for n in args.scene_names.split(',') if n]
    for name in names:
        if not os.path.isfile(os.path.join(args.scenes, name + '.xml')):
            ap.error(f'no scene {name}.xml in {args.scenes}')
    other = Mitsuba if args.renderer == 'mitsuba' else Cycles
    for name in names:
        xml = os.path.join(args.scenes, name + '.xml')
        eref, _ = envgi_render(args.envgi, xml, out, args.ref_spp, 1, args.res, args.threads, args.strategy)
        o = other(xml, args, os.path.join(tmp, 'o.exr'))
        oref, _ = o.render(args.ref_spp, 1)
        escale, oscale = (float(np.mean(eref)), float(np.mean(oref))) if other.relative else (1.0, 1.0)
        adaptive = args.noise_threshold > 0
        eadaptive = ['--noise-threshold', str(args.noise_threshold), '--min-spp', str(args.min_spp)] if adaptive else []
        for spp in (int(s) for s in args.spp.split(',')):
            rm, mt = over_seeds(lambda seed: o.render(spp, seed, adaptive) if adaptive else o.render(spp, seed), oref,
                                seeds, oscale)
            erender = lambda n: lambda seed: envgi_render(args.envgi, xml, out, n, seed, args.res, args.threads,
                                                          args.strategy, eadaptive)
            re_, et = over_seeds(erender(spp), eref, seeds, escale)
            if adaptive:
                espp, re2, et2 = spp, re_, et
            else:
                espp = max(1, int(round(spp * mt / max(et, 1e-3))))  # envgi logs 0.00 s for a tiny render
                re2, et2 = over_seeds(erender(espp), eref, seeds, escale)
            rows.append((name, spp, mt, rm, et, re_, espp, et2, re2, (re2 * re2 * et2) / (rm * rm * mt),
                         (re_ * re_ * et) / (rm * rm * mt)))
            print(rows[-1], flush=True)
    n, err = other.name, 'rel. RMSE' if other.relative else 'RMSE'
    owner = n + ("'" if n.endswith('s') else "'s")
    if args.noise_threshold > 0:
        print(f'\nBoth with adaptive sampling: noise threshold {args.noise_threshold}, at least {args.min_spp} spp, '
              'spp the budget; the "same time" columns repeat the budget\'s')
    print(f'\n{o.version} vs envgi path (strategy {args.strategy}), {args.res}^2, {args.threads} threads; '
          f'{err} against each renderer\'s own {args.ref_spp}-spp reference, over {args.seeds} seeds; times are '
          f'the medians of those renders\n')
    print(f'| scene | spp | {n} s | {n} {err} | envgi s | envgi {err} | envgi spp, same time | s | {err} | '
          f'envgi {err}² t / {owner}, same time | same spp |')
    print('|---|---|---|---|---|---|---|---|---|---|---|')
    for r in rows:
        print(f'| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]:.4f} | {r[4]:.2f} | {r[5]:.4f} | {r[6]} | {r[7]:.2f} | {r[8]:.4f} '
              f'| {r[9]:.2f} | {r[10]:.2f} |')


if __name__ == '__main__':
    main()
