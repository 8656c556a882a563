#!/usr/bin/env python3
"""envgi's AOVs against Mitsuba 3's `aov` integrator on the same scenes: each bundled scene is
wrapped in an aov integrator asking for depth, position, (u, v) and both normals; both renderers
write their EXRs and the channels are compared pixel by pixel where both see one triangle
(or sphere) through the whole pixel (edges, where a pixel averages two surfaces, would compare the sample
positions instead). Prints a Markdown table of the median and 99th-percentile absolute
differences and the share of pixels compared; exits 1 if a median exceeds 1e-3 of the scene's
size. Run: .venv-mitsuba/bin/python scripts/crosscheck_aovs.py --envgi build/bin/envgi
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

import mitsuba as mi
import numpy as np

mi.set_variant('scalar_rgb')

AOVS = 'dd:depth,p:position,t:uv,ng:geo_normal,nn:sh_normal,s:shape_index,i:prim_index'
CHANNELS = {'depth': ['dd.T'], 'position': ['p.X', 'p.Y', 'p.Z'], 'uv': ['t.U', 't.V'],
            'geo_normal': ['ng.X', 'ng.Y', 'ng.Z'], 'sh_normal': ['nn.X', 'nn.Y', 'nn.Z']}


# envgi's own properties, which Mitsuba would refuse (as crosscheck_mitsuba.py strips them).
ENVGI_ONLY = re.compile(r'\s*<(string|boolean|integer|float) name="(strategy|mis_compensation|gather_samples)"[^>]*/>')


def wrap(text, scenes_dir):
    """The scene with its integrator inside an aov integrator, data paths made absolute."""
    m = re.search(r'<integrator\b[^>]*/>', text)
    full = re.search(r'<integrator\b[^>]*[^/]>.*?</integrator>', text, flags=re.S)
    if not m or (full and full.start() < m.start()):
        m = full
    text = text[:m.start()] + f'<integrator type="aov"><string name="aovs" value="{AOVS}"/>' + m.group(0) + \
        '</integrator>' + text[m.end():]
    for d in ('envmaps', 'textures', 'meshes'):
        text = text.replace(f'value="{d}/', f'value="{os.path.abspath(os.path.join(scenes_dir, d))}/')
    return text


def channels(path):
    b = mi.Bitmap(path)
    arr = np.array(b, copy=False)
    fields = [f.name for f in b.struct_()]
    return {n: arr[..., i] for i, n in enumerate(fields)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--envgi', required=True)
    ap.add_argument('--scenes', default=os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'scenes'))
    ap.add_argument('--scene-names', default='orthographic,instances,textured')
    # Not the instances scene: Mitsuba 3.9.1 (scalar_rgb) crashes on it with hide_emitters on.
    ap.add_argument('--alpha-scene-names', default='orthographic,textured,buddha')
    ap.add_argument('--res', type=int, default=64)
    ap.add_argument('--spp', type=int, default=16)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix='envgi_aov_')
    print(f'Mitsuba {mi.__version__} aov integrator vs envgi --aov, {args.res}^2, {args.spp} spp; pixels that see one shape whole\n')
    print('| scene | AOV | median abs diff | 99th percentile | pixels compared |')
    print('|---|---|---|---|---|')
    bad = 0
    for name in args.scene_names.split(','):
        xml = os.path.join(tmp, name + '.xml')
        open(xml, 'w').write(wrap(open(os.path.join(args.scenes, name + '.xml')).read(), args.scenes))
        ours = os.path.join(tmp, name + '_envgi.exr')
        subprocess.run([args.envgi, '-q', 'render', xml, '-o', ours, '-D', f'res={args.res}', '-D', f'spp={args.spp}',
                        '--no-progress'], check=True)
        mxml = os.path.join(tmp, name + '_mitsuba.xml')
        open(mxml, 'w').write(ENVGI_ONLY.sub('', open(xml).read()))
        scene = mi.load_file(mxml, res=str(args.res), spp=str(args.spp))
        theirs = os.path.join(tmp, name + '_mitsuba.exr')
        mi.render(scene, spp=args.spp)
        scene.sensors()[0].film().write(theirs)
        a, b = channels(ours), channels(theirs)
        # One triangle (or sphere) through the whole pixel: the shape and primitive indices are
        # integers there, and depth's 3x3 neighbourhood is smooth (no silhouette inside).
        sa, pa = a['s.I'], a['i.I']
        whole = (np.abs(sa - np.round(sa)) < 1e-6) & (sa >= 0) & (np.abs(pa - np.round(pa)) < 1e-6)
        d = a['dd.T']
        pad = np.pad(d, 1, mode='edge')
        rough = np.zeros_like(d, dtype=bool)
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                rough |= np.abs(pad[1 + dy:1 + dy + d.shape[0], 1 + dx:1 + dx + d.shape[1]] - d) > 0.05 * np.maximum(d, 1e-3)
        mask = whole & ~rough & (b['dd.T'] > 0)
        size = float(np.percentile(d[mask], 99)) if mask.any() else 1.0
        for aov, chans in CHANNELS.items():
            diff = np.max([np.abs(a[c] - b[c]) for c in chans], axis=0)[mask]
            if not diff.size:
                continue
            med, p99 = float(np.median(diff)), float(np.percentile(diff, 99))
            scale = size if aov in ('depth', 'position') else 1.0
            ok = med <= 1e-3 * scale
            bad += not ok
            print(f'| {name} | {aov} | {med:.2e} | {p99:.2e} | {mask.mean() * 100:.0f}% |' + ('' if ok else ' **over**'))
    # The film's alpha: each scene with hide_emitters and pixel_format rgba, plain (no AOVs);
    # over all pixels, edges included, where the two sets of sample positions differ most.
    print('\n| scene | alpha: mean abs diff | share of pixels off by > 0.25 | coverage envgi / Mitsuba |')
    print('|---|---|---|---|')
    for name in args.alpha_scene_names.split(','):
        text = open(os.path.join(args.scenes, name + '.xml')).read()
        for d in ('envmaps', 'textures', 'meshes'):
            text = text.replace(f'value="{d}/', f'value="{os.path.abspath(os.path.join(args.scenes, d))}/')
        text = re.sub(r'(<film type="hdrfilm">)', r'\1<string name="pixel_format" value="rgba"/>', text, count=1)
        text = re.sub(r'(<integrator type="[a-z]+"[^/>]*>)', r'\1<boolean name="hide_emitters" value="true"/>', text, count=1)
        xml = os.path.join(tmp, name + '_rgba.xml')
        open(xml, 'w').write(text)
        ours = os.path.join(tmp, name + '_rgba_envgi.exr')
        subprocess.run([args.envgi, '-q', 'render', xml, '-o', ours, '-D', f'res={args.res}', '-D', f'spp={args.spp}',
                        '--no-progress'], check=True)
        mxml = os.path.join(tmp, name + '_rgba_mitsuba.xml')
        open(mxml, 'w').write(ENVGI_ONLY.sub('', text))
        scene = mi.load_file(mxml, res=str(args.res), spp=str(args.spp))
        theirs = os.path.join(tmp, name + '_rgba_mitsuba.exr')
        mi.render(scene, spp=args.spp)
        scene.sensors()[0].film().write(theirs)
        a, b = channels(ours)['A'], channels(theirs)['A']
        diff = np.abs(a - b)
        ok = diff.mean() < 0.01
        bad += not ok
        print(f'| {name} | {diff.mean():.4f} | {(diff > 0.25).mean() * 100:.2f}% | {a.mean():.4f} / {b.mean():.4f} |' +
              ('' if ok else ' **over**'))
    sys.exit(1 if bad else 0)


if __name__ == '__main__':
    main()
