"""The Cycles harness checked: envgi's example scenes rendered by envgi and by Blender Cycles
(scripts/cycles_render.py) at 48², 64 spp, one thread, must agree in the image mean within 5%
and in 8x8-pixel block means within 15% (relative RMSE). The BSDFs are Cycles' nearest nodes, not
envgi's, so the bounds are loose; a map turned the wrong way or a light on the wrong face is far
outside them (the buddha with the map a quarter turn off: block RMSE 2.2).
Run by scripts/crosscheck-cycles.sh (ctest -L crosscheck)."""
import argparse
import os
import subprocess
import sys
import tempfile

import mitsuba as mi
import numpy as np

mi.set_variant('scalar_rgb')


def read(path):
    return np.array(mi.Bitmap(path))[..., :3].astype(np.float64)


def blocks(x, n=8):
    h, w, _ = x.shape
    return x[:h // n * n, :w // n * n].reshape(h // n, n, w // n, n, 3).mean((1, 3))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--envgi', required=True)
    ap.add_argument('--scenes', required=True)
    ap.add_argument('--names', default='buddha,teapot-glass,bunny-sunrise,cornell-box,textured,microfacets,mask,instances,'
                    'uffizi-probe,orthographic,sun-and-sky,textured-light')
    a = ap.parse_args()
    here = os.path.dirname(os.path.abspath(__file__))
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.names.split(','):
            xml = os.path.join(a.scenes, name + '.xml')
            e, c = os.path.join(tmp, name + '_envgi.exr'), os.path.join(tmp, name + '_cycles.exr')
            subprocess.run([a.envgi, '-q', 'render', xml, '-D', 'res=48', '--spp', '64', '--integrator', 'path',
                            '--threads', '1', '--no-progress', '-o', e], check=True)
            subprocess.run(['blender', '-b', '--factory-startup', '-noaudio', '--python',
                            os.path.join(here, 'cycles_render.py'), '--', xml, '--out', c, '--spp', '64',
                            '--threads', '1', '-D', 'res=48', '--envgi', a.envgi], check=True,
                           stdout=subprocess.DEVNULL)
            x, y = read(e), read(c)
            ratio = x.mean() / y.mean()
            block = np.sqrt(((blocks(x) - blocks(y)) ** 2).mean()) / y.mean()
            ok = abs(ratio - 1) < 0.05 and block < 0.15
            failed += not ok
            print(f'{name:14s} mean envgi/cycles {ratio:.4f}  block rel. RMSE {block:.4f}  {"ok" if ok else "FAIL"}')
    print(f'crosscheck_cycles: {failed} of {len(a.names.split(","))} scenes outside the bounds')
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
