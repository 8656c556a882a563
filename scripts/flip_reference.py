"""Reference values for envgi's FLIP (tests/study/test_FlipError.cpp), from NVIDIA's own
implementation on PyPI (flip-evaluator): python3 scripts/flip_reference.py, in a venv with
`pip install flip-evaluator`. The two test images are formulas, written the same way there."""

import math

import flip_evaluator as flip
import numpy as np

W, H = 40, 32


def pair(hdr):
    ref = np.zeros((H, W, 3), np.float32)
    test = np.zeros((H, W, 3), np.float32)
    for y in range(H):
        for x in range(W):
            for c in range(3):
                r = 0.5 + 0.4 * math.sin(0.31 * x + 0.17 * y + 1.3 * c)
                t = r + 0.15 * math.sin(1.7 * x * y + 0.9 * c) * (x > W // 2)
                if hdr:
                    bright = 40.0 if (x - 10) ** 2 + (y - 12) ** 2 < 9 else 1.0
                    r, t = 4.0 * r * bright, 4.0 * t * bright * (1.3 if y > 24 else 1.0)
                ref[y, x, c], test[y, x, c] = r, max(0.0, min(t, 1.0)) if not hdr else max(0.0, t)
    return ref, test


for name, hdr in (("LDR", False), ("HDR", True)):
    ref, test = pair(hdr)
    err, mean, params = flip.evaluate(ref, test, name, inputsRGB=False, applyMagma=False)
    err = np.asarray(err).reshape(H, W)
    print(f"{name}: mean {mean:.7f} params {params}")
    for (x, y) in ((21, 5), (25, 3), (30, 20), (5, 28), (20, 10), (39, 31)):
        print(f"  ({x}, {y}) {err[y, x]:.7f}")
