#!/usr/bin/env python3
"""Compares two `envgi study` results.csv files run with the same arguments on two devices.

For each strategy and sample count (the equal-samples runs), the median RMSE over seeds on
each device and their ratio; exits 1 if any ratio is outside [1/TOL, TOL] (default 1.25).
Same seeds give nearly the same samples on both devices, so the errors should agree closely;
each study's own reference adds its noise.
    python3 scripts/compare_study.py GPU/results.csv CPU/results.csv [TOL]
"""
import csv
import statistics
import sys


def medians(path):
    runs = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if float(row["time_budget"]) > 0:
                continue
            runs.setdefault((row["strategy"], int(row["spp"])), []).append(float(row["rmse"]))
    return {k: statistics.median(v) for k, v in runs.items()}


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    a, b = medians(sys.argv[1]), medians(sys.argv[2])
    tol = float(sys.argv[3]) if len(sys.argv) == 4 else 1.25
    if set(a) != set(b) or not a:
        sys.exit("compare_study: the two studies have different runs")
    worst = 1.0
    print("| strategy | spp | RMSE (first) | RMSE (second) | ratio |\n|---|---|---|---|---|")
    for k in sorted(a):
        r = a[k] / b[k] if b[k] > 0 else float("inf")
        worst = max(worst, r, 1 / r if r > 0 else float("inf"))
        print(f"| {k[0]} | {k[1]} | {a[k]:.4f} | {b[k]:.4f} | {r:.3f} |")
    print(f"largest ratio either way: {worst:.3f} (limit {tol})")
    sys.exit(0 if worst <= tol else 1)


if __name__ == "__main__":
    main()
