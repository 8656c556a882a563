#!/usr/bin/env python3
"""Adaptive sampling against full renders on envgi's example scenes (docs/performance.md).

For each scene: a high-sample reference, then full renders at several sample counts and
adaptive renders (--noise-threshold) at several thresholds, each over a few seeds. Each row
gives the time ("done in", so loading and the BVH are left out), the image's mean over the
reference's (adaptive sampling's bias shows there), the relative RMSE (RMSE over the reference's
mean) and relMSE from `envgi compare`, and the efficiency RMSE^2 x seconds
divided by the median of the full renders' (below 1: adaptive reaches an error sooner).
Standard library only: `envgi compare` computes the errors.

  python3 scripts/perf_adaptive.py [--envgi build/bin/envgi] [--res 256] [--ref-spp 1024]
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile


def render(envgi, scene, out, res, spp, seed, threads, extra):
    cmd = [envgi, "render", scene, "--integrator", "path", "-D", f"res={res}", "--spp", str(spp), "--seed",
           str(seed), "--threads", str(threads), "--no-progress", "--checkpoint", "0", "-o", out] + extra
    log = subprocess.run(cmd, capture_output=True, text=True)
    if log.returncode != 0:
        sys.exit(f"perf_adaptive.py: {' '.join(cmd)} failed:\n{log.stdout}{log.stderr}")
    text = log.stdout + log.stderr
    seconds = float(re.search(r"done in ([0-9.]+) s", text).group(1))
    share = re.search(r"adaptive sampling: \S+ samples, ([0-9.]+)%", text)
    return seconds, float(share.group(1)) / 100 if share else 1.0


def errors(envgi, ref, images):
    out = subprocess.run([envgi, "compare", ref] + images, capture_output=True, text=True, check=True).stdout
    rows = {}
    for line in out.splitlines()[2:]:
        f = line.split()
        rows[os.path.basename(f[0])] = (float(f[2]), float(f[3]), float(f[1]))  # RMSE, relMSE, mean
    mean = float(out.splitlines()[1].split()[-5])  # the reference row
    return rows, mean


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--envgi", default="build/bin/envgi")
    ap.add_argument("--scenes", default="scenes")
    ap.add_argument("--scene-names", default="buddha,teapot-glass,bunny-sunrise,textured")
    ap.add_argument("--res", type=int, default=256)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--full-spp", default="16,64,256")
    ap.add_argument("--thresholds", default="0.1,0.05,0.02")
    ap.add_argument("--max-spp", type=int, default=256, help="adaptive renders' sample budget")
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    print("| scene | render | samples taken | s | mean / ref. | rel. RMSE | relMSE | RMSE² s / full's | relMSE s / full's |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.scene_names.split(","):
            scene = os.path.join(a.scenes, name + ".xml")
            ref = os.path.join(tmp, name + "-ref.exr")
            render(a.envgi, scene, ref, a.res, a.ref_spp, 1000, a.threads, [])
            configs = [(f"full {s} spp", s, []) for s in map(int, a.full_spp.split(","))]
            configs += [(f"threshold {t}", a.max_spp, ["--noise-threshold", t]) for t in a.thresholds.split(",")]
            results = []
            for label, spp, extra in configs:
                times, shares, imgs = [], [], []
                for seed in range(a.seeds):
                    img = os.path.join(tmp, f"{name}-{len(results)}-{seed}.exr")
                    t, share = render(a.envgi, scene, img, a.res, spp, seed, a.threads, extra)
                    times.append(t), shares.append(share), imgs.append(img)
                rows, mean = errors(a.envgi, ref, imgs)
                rmse = statistics.mean(rows[os.path.basename(i)][0] for i in imgs) / mean
                relmse = statistics.mean(rows[os.path.basename(i)][1] for i in imgs)
                ratio = statistics.mean(rows[os.path.basename(i)][2] for i in imgs) / mean
                results.append((label, spp * statistics.mean(shares), statistics.median(times), rmse, relmse, ratio))
            full = [r for r in results if r[0].startswith("full")]
            eff = statistics.median(r[3] ** 2 * r[2] for r in full)
            effRel = statistics.median(r[4] * r[2] for r in full)
            for label, taken, t, rmse, relmse, ratio in results:
                print(f"| {name} | {label} | {taken:.0f} spp | {t:.2f} | {ratio:.4f} | {rmse:.4f} | {relmse:.5f} | "
                      f"{rmse ** 2 * t / eff:.2f} | {relmse * t / effRel:.2f} |", flush=True)


if __name__ == "__main__":
    main()
