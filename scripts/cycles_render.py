"""One of envgi's scene files rendered by Blender Cycles, for scripts/perf_compare.py
(through scripts/perf-cycles.sh).

Runs inside Blender (Debian 12's blender 3.4.1, the Cycles the issue was measured against):
  blender -b --factory-startup -noaudio --python scripts/cycles_render.py -- SCENE.xml
      --out X.exr --spp N --seed S --threads T [-D name=value ...]
It reads the part of Mitsuba's format that envgi's map-lit example scenes use (perspective
or orthographic sensor, envmap (a light probe through --envgi), directional and point
emitters, ply/obj/sphere/rectangle/cube/cylinder shapes, shapegroups and their instances, area
lights on shapes, diffuse, roughplastic (Beckmann drawn as GGX), dielectric, (rough)conductor,
principled, mask and blendbsdf BSDFs, bitmap and checkerboard textures on their colours) and stops with an error on anything else. The materials are Cycles'
nearest nodes, not the same BSDFs, so each renderer is measured against its own reference.
Prints 'cycles render: T s' (the render call: scene sync, BVH and samples).
"""
import argparse
import atexit
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET

import bpy
from mathutils import Matrix, Vector

# Mitsuba's scenes are y-up, Blender's z-up: a quarter turn about x takes (x, y, z) to (x, -z, y).
Y_UP_TO_Z_UP = Matrix.Rotation(math.radians(90.0), 4, 'X')
# The quarter turn about z that lines Cycles' lat-long lookup up with Mitsuba's (and envgi's)
# after the turn above: of the four, the only one whose buddha render matches envgi's (relative
# RMSE 0.24 at 64 spp against 3.8-15 for the others; the windows of Grace line up by eye).
ENV_TURN_DEG = 90.0
# Mitsuba principled parameters whose Cycles Principled inputs take them as they are, with
# Mitsuba's defaults (base_color, eta and clearcoat_gloss are mapped apart).
PRINCIPLED_INPUTS = {'metallic': ('Metallic', 0.0), 'roughness': ('Roughness', 0.5),
                     'anisotropic': ('Anisotropic', 0.0), 'spec_trans': ('Transmission', 0.0),
                     'specular': ('Specular', 0.5), 'spec_tint': ('Specular Tint', 0.0),
                     'sheen': ('Sheen', 0.0), 'sheen_tint': ('Sheen Tint', 0.0),
                     'clearcoat': ('Clearcoat', 0.0)}
# Typical linear-RGB normal-incidence reflectances of the metals a scene may name: Cycles 3.4 has
# no conductor with a complex index of refraction, its glossy BSDF takes a colour.
CONDUCTOR_F0 = {'Cu': (0.955, 0.638, 0.538), 'Cr': (0.549, 0.556, 0.554), 'Al': (0.913, 0.922, 0.924),
                'Au': (1.000, 0.766, 0.336), 'Ag': (0.972, 0.960, 0.915), 'none': (1.0, 1.0, 1.0)}


def gauss_legendre(n):
    """Gauss-Legendre nodes and weights on (0, 1), by Newton's method (Blender's Python has no numpy)."""
    nodes = []
    for k in range(n):
        t = math.cos(math.pi * (k + 0.75) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, t
            for j in range(2, n + 1):
                p0, p1 = p1, ((2 * j - 1) * t * p1 - (j - 1) * p0) / j
            dp = n * (t * p1 - p0) / (t * t - 1)
            step = p1 / dp
            t -= step
            if abs(step) < 1e-15:
                break
        nodes.append((0.5 * (1 - t), 1 / ((1 - t * t) * dp * dp)))
    return nodes


def rough_coat_factor(alpha, eta, n_mu=64):
    """What Mitsuba's (and envgi's) rough plastic keeps of its base's albedo under the rough GGX
    coat, at normal view: t(1) t_hemi / ((1 - Fdr_int) eta^2), with t(mu) the coat's transmittance
    and Fdr_int its hemispherical reflectance from inside: the integrals of envgi's tables
    (src/materials/RoughCoatTable.cpp) over GGX's visible normals, with fewer nodes (within 0.3%).
    Cycles' Principled BSDF keeps all of it, so its base colour is scaled by this."""
    def integral(mu, eta_rel, transmitted, quad):
        wi = (math.sqrt(max(0.0, 1 - mu * mu)), 0.0, mu)
        wh = (alpha * wi[0], 0.0, wi[2])
        ln = math.hypot(wh[0], wh[2])
        wh = (wh[0] / ln, 0.0, wh[2] / ln)
        t1 = (0.0, 1.0, 0.0) if wh[2] < 0.99999 else (1.0, 0.0, 0.0)  # z x wh, normalised (wh in xz)
        t2 = (wh[1] * t1[2] - wh[2] * t1[1], wh[2] * t1[0] - wh[0] * t1[2], wh[0] * t1[1] - wh[1] * t1[0])
        total = 0.0
        for u1, w1 in quad:
            for u2, w2 in quad:
                r, phi = math.sqrt(u1), 2 * math.pi * u2
                px, py = r * math.cos(phi), r * math.sin(phi)
                s = 0.5 * (1 + wh[2])
                py = (1 - s) * math.sqrt(max(0.0, 1 - px * px)) + s * py
                pz = math.sqrt(max(0.0, 1 - px * px - py * py))
                nh = [px * t1[i] + py * t2[i] + pz * wh[i] for i in range(3)]
                m = (alpha * nh[0], alpha * nh[1], max(1e-6, nh[2]))
                lm = math.sqrt(m[0] ** 2 + m[1] ** 2 + m[2] ** 2)
                m = (m[0] / lm, m[1] / lm, m[2] / lm)
                c = m[0] * wi[0] + m[1] * wi[1] + m[2] * wi[2]
                if c <= 0:
                    continue
                sin2t = max(0.0, 1 - c * c) / eta_rel ** 2
                if sin2t >= 1:
                    F, ct = 1.0, 0.0
                else:
                    ct = math.sqrt(1 - sin2t)
                    rs = (c - eta_rel * ct) / (c + eta_rel * ct)
                    rp = (eta_rel * c - ct) / (eta_rel * c + ct)
                    F = 0.5 * (rs * rs + rp * rp)
                if transmitted:
                    if sin2t >= 1:
                        continue
                    wo = [-wi[i] / eta_rel + (c / eta_rel - ct) * m[i] for i in range(3)]
                    if wo[2] >= 0:
                        continue
                    share = 1 - F
                else:
                    wo = [2 * c * m[i] - wi[i] for i in range(3)]
                    if wo[2] <= 0:
                        continue
                    share = F
                tan2 = (wo[0] ** 2 + wo[1] ** 2) / (wo[2] ** 2)
                total += w1 * w2 * share * 2 / (1 + math.sqrt(1 + alpha * alpha * tan2))
        return total

    outside, inside = gauss_legendre(16), gauss_legendre(32)
    mus = [max(1e-6, i / (n_mu - 1)) for i in range(n_mu)]
    t = [integral(mu, eta, True, outside) for mu in mus]
    fdr = 2 * sum(integral(mu, 1 / eta, False, inside) * mu for mu in mus) / n_mu
    t_hemi = 2 * sum(ti * mu for ti, mu in zip(t, mus)) / n_mu
    return t[-1] * t_hemi / ((1 - fdr) * eta * eta)


def fail(msg):
    print(f'cycles_render: error: {msg}', file=sys.stderr)
    sys.exit(2)


def floats(text, n=None):
    vals = [float(v) for v in re.split(r'[,\s]+', text.strip()) if v]
    if n is not None and len(vals) != n:
        fail(f"expected {n} numbers, got '{text}'")
    return vals


class Scene:
    def __init__(self, path, defs):
        self.dir = os.path.dirname(os.path.abspath(path))
        self.root = ET.parse(path).getroot()
        self.defs = {d.get('name'): d.get('value') for d in self.root.iter('default')}
        self.defs.update(defs)
        self.ids = {e.get('id'): e for e in self.root if e.get('id')}

    def val(self, e):
        v = e.get('value')
        return re.sub(r'\$(\w+)', lambda m: self.defs[m.group(1)], v) if v is not None else None

    def prop(self, e, name, default=None):
        for c in e:
            if c.get('name') == name:
                if c.tag == 'rgb':
                    v = floats(self.val(c))
                    return tuple(v * 3 if len(v) == 1 else v)
                if c.tag in ('float', 'integer'):
                    return float(self.val(c))
                return self.val(c)
        return default

    def point(self, e, name, default):
        """A <point> or <vector> property as a Vector: value="x, y, z" or x=, y=, z= (0 where left out)."""
        c = next((c for c in e if c.get('name') == name), None)
        if c is None:
            return Vector(default)
        return Vector(floats(self.val(c), 3) if c.get('value') is not None else tuple(float(c.get(k, 0)) for k in 'xyz'))

    def transform(self, e):
        m = Matrix.Identity(4)
        t = next((c for c in e if c.tag == 'transform'), None)
        if t is None:
            return m
        for c in t:
            a = {k: self.val(c) if k == 'value' else c.get(k) for k in c.keys()}
            if c.tag == 'lookat':
                o, tg, up = (Vector(floats(a[k], 3)) for k in ('origin', 'target', 'up'))
                d = (tg - o).normalized()
                left = up.normalized().cross(d).normalized()
                nup = d.cross(left)
                step = Matrix(((left.x, nup.x, d.x, o.x), (left.y, nup.y, d.y, o.y), (left.z, nup.z, d.z, o.z), (0, 0, 0, 1)))
            elif c.tag == 'translate':
                step = Matrix.Translation(Vector(floats(a['value'], 3)) if 'value' in a else
                                          Vector(tuple(float(a.get(k, 0)) for k in 'xyz')))
            elif c.tag == 'scale':
                s = floats(a['value']) if 'value' in a else [float(a.get(k, 1)) for k in 'xyz']
                s = s * 3 if len(s) == 1 else s
                step = Matrix.Diagonal((s[0], s[1], s[2], 1.0))
            elif c.tag == 'rotate':
                axis = Vector(tuple(float(a.get(k, 0)) for k in 'xyz'))
                step = Matrix.Rotation(math.radians(float(a['angle'])), 4, axis.normalized())
            elif c.tag == 'matrix':
                v = floats(a['value'], 16)
                step = Matrix([v[0:4], v[4:8], v[8:12], v[12:16]])
            else:
                fail(f'transform <{c.tag}> is not supported')
            m = step @ m
        return m

    def path(self, p):
        return p if os.path.isabs(p) else os.path.join(self.dir, p)


def node_math(nt, op, a, b=0.0):
    """One Math node, op(a, b), whose inputs are sockets or numbers; returns its output."""
    n = nt.nodes.new('ShaderNodeMath')
    n.operation = op
    for i, x in enumerate((a, b)):
        if isinstance(x, (int, float)):
            n.inputs[i].default_value = float(x)
        else:
            nt.links.new(x, n.inputs[i])
    return n.outputs[0]


def mitsuba_uv(nt, kind):
    """Mitsuba's (u, v) on a shape as node outputs: a sphere's lat-long in its own frame, a
    rectangle's ((x + 1) / 2, (y + 1) / 2), a mesh's file uvs with v flipped (Blender's UV
    output keeps the file's v)."""
    if kind not in ('mesh', 'rectangle', 'sphere'):
        fail(f"a texture on a {kind} is not supported (its uv is Mitsuba's own)")
    coord = nt.nodes.new('ShaderNodeTexCoord')
    sep = nt.nodes.new('ShaderNodeSeparateXYZ')
    nt.links.new(coord.outputs['UV' if kind == 'mesh' else 'Object'], sep.inputs[0])
    x, y, z = sep.outputs['X'], sep.outputs['Y'], sep.outputs['Z']
    if kind == 'mesh':
        return x, node_math(nt, 'SUBTRACT', 1.0, y)
    if kind == 'rectangle':
        return (node_math(nt, 'ADD', node_math(nt, 'MULTIPLY', x, 0.5), 0.5),
                node_math(nt, 'ADD', node_math(nt, 'MULTIPLY', y, 0.5), 0.5))
    u = node_math(nt, 'FRACT', node_math(nt, 'MULTIPLY', node_math(nt, 'ARCTAN2', y, x), 0.5 / math.pi))
    return u, node_math(nt, 'DIVIDE', node_math(nt, 'ARCCOSINE', z), math.pi)


def mitsuba_tangent(nt, kind):
    """Mitsuba's dp/du in world space as a node output: a sphere's azimuth (-y, x, 0) in its own
    frame, a rectangle's +x, and on each face of a cube the axis its u follows (envgi's
    makeCube, after Mitsuba's cube mesh): +y on the x faces, +z on -y, -x on +y, -y on -z, +y on +z."""
    coord = nt.nodes.new('ShaderNodeTexCoord')
    t = nt.nodes.new('ShaderNodeCombineXYZ')
    if kind == 'sphere':
        sep = nt.nodes.new('ShaderNodeSeparateXYZ')
        nt.links.new(coord.outputs['Object'], sep.inputs[0])
        nt.links.new(node_math(nt, 'MULTIPLY', sep.outputs['Y'], -1.0), t.inputs['X'])
        nt.links.new(sep.outputs['X'], t.inputs['Y'])
    elif kind == 'rectangle':
        t.inputs['X'].default_value = 1.0
    elif kind == 'cube':
        sep = nt.nodes.new('ShaderNodeSeparateXYZ')
        nt.links.new(coord.outputs['Normal'], sep.inputs[0])  # the object-space normal: one axis, +-1
        nx, ny, nz = sep.outputs['X'], sep.outputs['Y'], sep.outputs['Z']
        nt.links.new(node_math(nt, 'MULTIPLY', node_math(nt, 'GREATER_THAN', ny, 0.5), -1.0), t.inputs['X'])
        on_x = node_math(nt, 'GREATER_THAN', node_math(nt, 'ABSOLUTE', nx), 0.5)
        z_sign = node_math(nt, 'SUBTRACT', node_math(nt, 'GREATER_THAN', nz, 0.5), node_math(nt, 'LESS_THAN', nz, -0.5))
        nt.links.new(node_math(nt, 'ADD', on_x, z_sign), t.inputs['Y'])
        nt.links.new(node_math(nt, 'LESS_THAN', ny, -0.5), t.inputs['Z'])
    else:
        fail(f"an anisotropic BSDF on a {kind} is not supported (its dp/du is Mitsuba's own)")
    world = nt.nodes.new('ShaderNodeVectorTransform')
    world.vector_type = 'VECTOR'
    world.convert_from = 'OBJECT'
    world.convert_to = 'WORLD'
    nt.links.new(t.outputs[0], world.inputs[0])
    return world.outputs[0]


def to_uv(sc, tex, nt, u, v):
    """The texture's to_uv, its 2D part: (m00 u + m01 v + m03, m10 u + m11 v + m13)."""
    m = sc.transform(tex)
    out = []
    for r in (0, 1):
        a = node_math(nt, 'MULTIPLY', u, m[r][0])
        b = node_math(nt, 'MULTIPLY', v, m[r][1])
        out.append(node_math(nt, 'ADD', node_math(nt, 'ADD', a, b), m[r][3]))
    return out


def colour(sc, nt, b, name, default, kind):
    """A BSDF colour property as a node output: a constant, or Mitsuba's bitmap or checkerboard
    texture (nested or a <ref>) looked up at Mitsuba's (u, v)."""
    tex = next((c for c in b if c.get('name') == name and c.tag in ('texture', 'ref')), None)
    if tex is None:
        rgb = nt.nodes.new('ShaderNodeRGB')
        value = sc.prop(b, name, default)
        rgb.outputs[0].default_value = (*((value,) * 3 if isinstance(value, float) else value), 1)
        return rgb.outputs[0]
    if tex.tag == 'ref':
        tex = sc.ids[tex.get('id')]
    u, v = to_uv(sc, tex, nt, *mitsuba_uv(nt, kind))
    if tex.get('type') == 'checkerboard':
        # color0 where floor(2u) + floor(2v) is even.
        s = node_math(nt, 'ADD', node_math(nt, 'FLOOR', node_math(nt, 'MULTIPLY', u, 2.0)),
                      node_math(nt, 'FLOOR', node_math(nt, 'MULTIPLY', v, 2.0)))
        odd = node_math(nt, 'MULTIPLY', node_math(nt, 'FRACT', node_math(nt, 'MULTIPLY', s, 0.5)), 2.0)
        mix = nt.nodes.new('ShaderNodeMixRGB')
        nt.links.new(odd, mix.inputs['Fac'])
        mix.inputs['Color1'].default_value = (*sc.prop(tex, 'color0', (0.4,) * 3), 1)
        mix.inputs['Color2'].default_value = (*sc.prop(tex, 'color1', (0.2,) * 3), 1)
        return mix.outputs[0]
    if tex.get('type') != 'bitmap':
        fail(f"texture '{tex.get('type')}' is not supported")
    img = nt.nodes.new('ShaderNodeTexImage')
    img.image = bpy.data.images.load(sc.path(sc.prop(tex, 'filename')))
    if sc.prop(tex, 'raw', 'false') == 'true':
        img.image.colorspace_settings.name = 'Non-Color'
    img.interpolation = 'Closest' if sc.prop(tex, 'filter_type', 'bilinear') == 'nearest' else 'Linear'
    wrap = sc.prop(tex, 'wrap_mode', 'repeat')
    if wrap == 'mirror':
        fail("bitmap wrap_mode 'mirror' is not supported")
    img.extension = 'EXTEND' if wrap == 'clamp' else 'REPEAT'
    # Mitsuba's bitmap row 0 is v = 0; Blender's image v = 0 is its bottom row.
    vec = nt.nodes.new('ShaderNodeCombineXYZ')
    nt.links.new(u, vec.inputs['X'])
    nt.links.new(node_math(nt, 'SUBTRACT', 1.0, v), vec.inputs['Y'])
    nt.links.new(vec.outputs[0], img.inputs['Vector'])
    return img.outputs['Color']


def material(sc, b, name, kind):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new('ShaderNodeOutputMaterial')
    nt.links.new(bsdf_node(sc, nt, b, kind), out.inputs['Surface'])
    return m


def bsdf_node(sc, nt, b, kind):
    """The shader output for Mitsuba's BSDF element b, built in the node tree nt."""
    if b.tag == 'ref':
        b = sc.ids[b.get('id')]
    t = b.get('type')
    # Nested BSDFs: <bsdf>s, and <ref>s without a name (a named <ref> is a texture's).
    nested = [c for c in b if c.tag == 'bsdf' or (c.tag == 'ref' and not c.get('name'))]
    inner = nested[0] if nested else None
    if t == 'twosided':  # Cycles' surfaces are two-sided already
        return bsdf_node(sc, nt, inner, kind)
    if t == 'normalmap':
        # Built (the mapped normal in world space, given to the nested BSDF's nodes), it drew the
        # normal-map scene at 0.67 of envgi's mean (block RMSE 0.46): Cycles keeps a normal that
        # faces away from the viewer valid its own way, where Mitsuba flips it and envgi adds the
        # terminator term, and the scene's floor is seen at a grazing angle.
        fail("normalmap is not supported: Cycles treats normals that face away from the viewer otherwise")
    textured = {c.get('name') for c in b if c.tag in ('texture', 'ref') and c.get('name')}
    allowed = {'diffuse': {'reflectance'}, 'plastic': {'diffuse_reflectance'}, 'roughplastic': {'diffuse_reflectance'},
               'conductor': {'specular_reflectance'}, 'roughconductor': {'specular_reflectance'},
               'mask': {'opacity'}, 'blendbsdf': {'weight'}, 'principled': set(PRINCIPLED_INPUTS) | {'base_color'}}.get(t, set())
    if textured - allowed:
        fail(f"bsdf '{t}' with a texture for {sorted(textured - allowed)} is not supported")
    # Mitsuba's rough BSDFs default to Beckmann; Cycles' Principled BSDF (rough plastic here) has GGX only.
    dist = sc.prop(b, 'distribution', 'beckmann')
    anisotropic = any(c.get('name') in ('alpha_u', 'alpha_v') for c in b)
    if anisotropic and t != 'roughconductor':
        fail(f"bsdf '{t}' with alpha_u / alpha_v (anisotropic) is not supported here")
    if t == 'roughplastic' and dist != 'ggx':
        # Cycles' Principled BSDF has no Beckmann: the coat is drawn as GGX of the same alpha,
        # said on stderr. Each renderer is measured against its own reference, and
        # scripts/crosscheck_cycles.py bounds how far the two images are apart.
        print(f"cycles_render: note: roughplastic '{b.get('id') or ''}' with Beckmann's distribution is drawn "
              "with GGX (Cycles' Principled BSDF has no Beckmann)", file=sys.stderr)
    if t == 'blendbsdf':
        # Mitsuba's blendbsdf: (1 - w) f0 + w f1, Cycles' mix shader with w as its factor (a
        # colour texture as its luminance, as Mitsuba reads a float texture from RGB).
        pair = nested
        if len(pair) != 2:
            fail('blendbsdf needs two nested BSDFs')
        mix = nt.nodes.new('ShaderNodeMixShader')
        if any(c.get('name') == 'weight' and c.tag in ('texture', 'ref') for c in b):
            nt.links.new(colour(sc, nt, b, 'weight', 0.5, kind), mix.inputs['Fac'])
        else:
            mix.inputs['Fac'].default_value = sc.prop(b, 'weight', 0.5)
        nt.links.new(bsdf_node(sc, nt, pair[0], kind), mix.inputs[1])
        nt.links.new(bsdf_node(sc, nt, pair[1], kind), mix.inputs[2])
        return mix.outputs[0]
    if t == 'mask':
        # Mitsuba's mask: the inner BSDF with probability `opacity`, else the ray passes on.
        mix = nt.nodes.new('ShaderNodeMixShader')
        nt.links.new(colour(sc, nt, b, 'opacity', 0.5, kind), mix.inputs['Fac'])
        nt.links.new(nt.nodes.new('ShaderNodeBsdfTransparent').outputs[0], mix.inputs[1])
        nt.links.new(bsdf_node(sc, nt, inner, kind), mix.inputs[2])
        return mix.outputs[0]
    if t == 'diffuse':
        n = nt.nodes.new('ShaderNodeBsdfDiffuse')
        nt.links.new(colour(sc, nt, b, 'reflectance', (0.5,) * 3, kind), n.inputs['Color'])
    elif t in ('roughplastic', 'plastic'):
        n = nt.nodes.new('ShaderNodeBsdfPrincipled')
        base = colour(sc, nt, b, 'diffuse_reflectance', (0.5,) * 3, kind)
        if t == 'roughplastic':
            # The rough coat's losses, which Principled does not have (0.86 at alpha 0.12).
            k = rough_coat_factor(sc.prop(b, 'alpha', 0.1), sc.prop(b, 'int_ior', 1.49) / sc.prop(b, 'ext_ior', 1.000277))
            scale = nt.nodes.new('ShaderNodeMixRGB')
            scale.blend_type = 'MULTIPLY'
            scale.inputs['Fac'].default_value = 1.0
            scale.inputs['Color1'].default_value = (k, k, k, 1)
            nt.links.new(base, scale.inputs['Color2'])
            base = scale.outputs[0]
        nt.links.new(base, n.inputs['Base Color'])
        n.inputs['Roughness'].default_value = math.sqrt(sc.prop(b, 'alpha', 0.1)) if t == 'roughplastic' else 0.0
        n.inputs['Specular'].default_value = 0.5  # F0 = 0.04, Mitsuba's default ior 1.49
    elif t == 'dielectric':
        n = nt.nodes.new('ShaderNodeBsdfGlass')
        n.distribution = 'SHARP'
        n.inputs['IOR'].default_value = sc.prop(b, 'int_ior', 1.5046) / sc.prop(b, 'ext_ior', 1.000277)
    elif t == 'principled':
        # Both are Burley's Disney BSDF, single-scattering GGX (Cycles' Principled v1).
        n = nt.nodes.new('ShaderNodeBsdfPrincipled')
        n.distribution = 'GGX'
        nt.links.new(colour(sc, nt, b, 'base_color', (0.5,) * 3, kind), n.inputs['Base Color'])
        for name, (socket, default) in PRINCIPLED_INPUTS.items():
            nt.links.new(colour(sc, nt, b, name, default, kind), n.inputs[socket])
        eta = sc.prop(b, 'eta', None)
        if eta is not None:  # Mitsuba's specular follows eta when eta is given; Cycles' F0 is 0.08 x Specular
            n.inputs['IOR'].default_value = eta
            n.inputs['Specular'].default_value = ((eta - 1) / (eta + 1)) ** 2 / 0.08
        # Disney's clearcoat roughness (an alpha) from its gloss.
        gloss = sc.prop(b, 'clearcoat_gloss', 0.0)
        if isinstance(gloss, str):
            fail("principled: a textured clearcoat_gloss is not supported")
        n.inputs['Clearcoat Roughness'].default_value = math.sqrt(0.1 * (1 - gloss) + 0.001 * gloss)
    elif t in ('conductor', 'roughconductor') and anisotropic:
        # Cycles' anisotropic glossy: alpha_x = r^2 (1 - a), alpha_y = r^2 / (1 - a) for a >= 0 (and
        # the mirror of it for a < 0), x along its tangent: Mitsuba's alpha_u along dp/du.
        au, av = sc.prop(b, 'alpha_u', 0.1), sc.prop(b, 'alpha_v', 0.1)
        if isinstance(au, str) or isinstance(av, str):
            fail("roughconductor: textured alpha_u / alpha_v are not supported")
        n = nt.nodes.new('ShaderNodeBsdfAnisotropic')
        n.distribution = {'ggx': 'GGX', 'beckmann': 'BECKMANN'}[dist]
        n.inputs['Roughness'].default_value = (au * av) ** 0.25
        ratio = math.sqrt(min(au, av) / max(au, av))
        n.inputs['Anisotropy'].default_value = 1 - ratio if av >= au else ratio - 1
        nt.links.new(mitsuba_tangent(nt, kind), n.inputs['Tangent'])
        conductor_tint(sc, nt, b, kind, n)
    elif t in ('conductor', 'roughconductor'):
        n = nt.nodes.new('ShaderNodeBsdfGlossy')
        n.distribution = {'ggx': 'GGX', 'beckmann': 'BECKMANN'}[dist] if t == 'roughconductor' else 'SHARP'
        n.inputs['Roughness'].default_value = math.sqrt(sc.prop(b, 'alpha', 0.1)) if t == 'roughconductor' else 0.0
        conductor_tint(sc, nt, b, kind, n)
    else:
        fail(f"bsdf '{t}' is not supported")
    return n.outputs[0]


def conductor_tint(sc, nt, b, kind, n):
    """A conductor's colour into glossy node n: the metal's normal-incidence colour times
    specular_reflectance."""
    mat = sc.prop(b, 'material', 'none')
    if mat not in CONDUCTOR_F0:
        fail(f"conductor material '{mat}' has no colour here")
    tint = nt.nodes.new('ShaderNodeMixRGB')
    tint.blend_type = 'MULTIPLY'
    tint.inputs['Fac'].default_value = 1.0
    tint.inputs['Color1'].default_value = (*CONDUCTOR_F0[mat], 1)
    nt.links.new(colour(sc, nt, b, 'specular_reflectance', (1.0,) * 3, kind), tint.inputs['Color2'])
    nt.links.new(tint.outputs[0], n.inputs['Color'])


def add_shape(sc, e, i, outer=Matrix.Identity(4)):
    """Shape e, under an instance's to_world `outer` when it is a shapegroup's."""
    t = e.get('type')
    to_world = outer @ sc.transform(e)
    if t in ('ply', 'obj'):
        f = sc.path(sc.prop(e, 'filename'))
        if t == 'ply':
            bpy.ops.import_mesh.ply(filepath=f)
        else:
            bpy.ops.wm.obj_import(filepath=f, forward_axis='Y', up_axis='Z')  # no axis change
        obj = bpy.context.selected_objects[0]
    elif t == 'sphere':
        bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=64, radius=1.0)
        obj = bpy.context.active_object
        bpy.ops.object.shade_smooth()
        c = sc.point(e, 'center', (0.0, 0.0, 0.0))
        r = sc.prop(e, 'radius', 1.0)
        to_world = to_world @ Matrix.Translation(c) @ Matrix.Diagonal((r, r, r, 1.0))
    elif t == 'rectangle':
        bpy.ops.mesh.primitive_plane_add(size=2.0)
        obj = bpy.context.active_object
    elif t == 'cube':  # Mitsuba's cube spans [-1, 1]^3, flat faces
        bpy.ops.mesh.primitive_cube_add(size=2.0)
        obj = bpy.context.active_object
    elif t == 'cylinder':
        obj = open_cylinder(sc, e, i)
    else:
        fail(f"shape '{t}' is not supported")
    obj.matrix_world = Y_UP_TO_Z_UP @ to_world
    b = next((c for c in e if c.tag in ('bsdf', 'ref')), None)
    emitter = next((c for c in e if c.tag == 'emitter'), None)
    if b is None:
        # Mitsuba's default for a shape without one: diffuse, black on an emitter.
        b = ET.fromstring('<bsdf type="diffuse"><rgb name="reflectance" value="0"/></bsdf>' if emitter is not None
                          else '<bsdf type="diffuse"/>')
    kind = t if t in ('sphere', 'rectangle', 'cube') else 'mesh'
    m = material(sc, b, f'm{i}', kind)
    if emitter is not None:
        if emitter.get('type') != 'area':
            fail(f"a shape's emitter must be 'area', not '{emitter.get('type')}'")
        add_area_emission(m, colour(sc, m.node_tree, emitter, 'radiance', (1.0,) * 3, kind))
    obj.data.materials.clear()
    obj.data.materials.append(m)


def open_cylinder(sc, e, i, segments=128):
    """Mitsuba's open cylinder from p0 to p1 as a smooth mesh in world space (the shape's
    to_world comes on top), its (u, v) Mitsuba's: u the azimuth / 2 pi about the axis from
    Mitsuba's frame of it (Duff et al.'s, as envgi's makeCylinder), v the height / length."""
    p0, p1, r = sc.point(e, 'p0', (0, 0, 0)), sc.point(e, 'p1', (0, 0, 1)), sc.prop(e, 'radius', 1.0)
    d = p1 - p0
    n = d.normalized()
    sign = math.copysign(1.0, n.z)
    a = -1.0 / (sign + n.z)
    b = n.x * n.y * a
    fs, ft = Vector((1 + sign * n.x * n.x * a, sign * b, -sign * n.x)), Vector((b, sign + n.y * n.y * a, -n.y))
    verts, faces, uvs = [], [], []
    for k in range(segments + 1):
        phi = 2 * math.pi * k / segments
        radial = fs * math.cos(phi) + ft * math.sin(phi)
        verts += [p0 + radial * r, p0 + radial * r + d]
    for k in range(segments):
        b0, t0, b1, t1 = 2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3
        faces.append((b0, b1, t1, t0))  # counter-clockwise from outside
        u0, u1 = k / segments, (k + 1) / segments
        uvs += [(u0, 0.0), (u1, 0.0), (u1, 1.0), (u0, 1.0)]
    mesh = bpy.data.meshes.new(f'cylinder{i}')
    mesh.from_pydata([tuple(v) for v in verts], [], faces)
    layer = mesh.uv_layers.new()
    for loop, (u, v) in zip(layer.data, uvs):
        loop.uv = (u, 1.0 - v)  # mitsuba_uv reads a mesh's v flipped, as a PLY file's
    mesh.polygons.foreach_set('use_smooth', [True] * len(faces))
    mesh.update()
    obj = bpy.data.objects.new(f'cylinder{i}', mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def add_area_emission(m, radiance):
    """Mitsuba's area light: radiance L (a colour socket: a constant or a texture) from the front
    face only, added to the shape's BSDF. Cycles' emission shader (strength 1) has radiance equal
    to its colour, from both faces, so the back face is masked to black through the geometry's
    Backfacing output."""
    nt = m.node_tree
    out = next(n for n in nt.nodes if n.type == 'OUTPUT_MATERIAL')
    bsdf_socket = out.inputs['Surface'].links[0].from_socket
    emit = nt.nodes.new('ShaderNodeEmission')
    nt.links.new(radiance, emit.inputs['Color'])
    emit.inputs['Strength'].default_value = 1.0
    black = nt.nodes.new('ShaderNodeEmission')
    black.inputs['Strength'].default_value = 0.0
    geo = nt.nodes.new('ShaderNodeNewGeometry')
    mix = nt.nodes.new('ShaderNodeMixShader')
    nt.links.new(geo.outputs['Backfacing'], mix.inputs['Fac'])
    nt.links.new(emit.outputs[0], mix.inputs[1])
    nt.links.new(black.outputs[0], mix.inputs[2])
    add = nt.nodes.new('ShaderNodeAddShader')
    nt.links.new(bsdf_socket, add.inputs[0])
    nt.links.new(mix.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs['Surface'])


def main():
    argv = sys.argv[sys.argv.index('--') + 1:] if '--' in sys.argv else []
    ap = argparse.ArgumentParser(prog='cycles_render.py')
    ap.add_argument('scene')
    ap.add_argument('--out', required=True)
    ap.add_argument('--spp', type=int, required=True)
    ap.add_argument('--seed', type=int, default=0)
    ap.add_argument('--threads', type=int, default=os.cpu_count())
    ap.add_argument('--noise-threshold', type=float, default=0.0,
                    help="Cycles' adaptive sampling with this noise threshold (0: off, every pixel takes --spp)")
    ap.add_argument('--min-spp', type=int, default=16, help="adaptive sampling's minimum samples")
    ap.add_argument('--envgi', help="envgi's binary, to resample a light probe (an envmap's layout) to the "
                    "lat-long map envgi itself renders with (envgi envmap convert)")
    ap.add_argument('-D', action='append', default=[], metavar='name=value')
    a = ap.parse_args(argv)
    sc = Scene(a.scene, dict(d.split('=', 1) for d in a.D))

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    sensor = sc.root.find('sensor')
    if sensor is None or sensor.get('type') not in ('perspective', 'orthographic'):
        fail(f"needs a perspective or orthographic sensor, not '{None if sensor is None else sensor.get('type')}'")
    integ = sc.root.find('integrator')
    if integ is None or integ.get('type') not in ('path', 'direct'):
        fail('needs a path (or direct) integrator')
    # Always a path tracer, as `envgi render --integrator path`: a direct scene gets no depth limit.
    max_depth = int(sc.prop(integ, 'max_depth', -1)) if integ.get('type') == 'path' else -1
    film = sensor.find('film')
    scene.render.resolution_x = int(sc.prop(film, 'width'))
    scene.render.resolution_y = int(sc.prop(film, 'height'))
    scene.render.resolution_percentage = 100

    cam = bpy.data.cameras.new('cam')
    to_world = sc.transform(sensor)
    if sensor.get('type') == 'orthographic':
        # Mitsuba's view is [-1, 1] across (x) on its near plane, which to_world's scale sizes;
        # Blender's ortho_scale is the view's width, with the camera's matrix left unscaled.
        loc, rot, scale = to_world.decompose()
        if abs(scale.x - scale.y) > 1e-5 * abs(scale.x) or scene.render.resolution_x != scene.render.resolution_y:
            fail("an orthographic sensor needs a square film and to_world's x and y scales equal here")
        cam.type = 'ORTHO'
        cam.sensor_fit = 'HORIZONTAL'
        cam.ortho_scale = 2.0 * scale.x
        cam.clip_start = sc.prop(sensor, 'near_clip', 1e-2)
        to_world = Matrix.Translation(loc) @ rot.to_matrix().to_4x4()
    else:
        cam.sensor_fit = 'VERTICAL' if sc.prop(sensor, 'fov_axis', 'x') == 'y' else 'HORIZONTAL'
        cam.angle = math.radians(sc.prop(sensor, 'fov'))
    cobj = bpy.data.objects.new('cam', cam)
    scene.collection.objects.link(cobj)
    # Mitsuba's camera looks along +z with x to its left; Blender's along -z with x to its right.
    cobj.matrix_world = Y_UP_TO_Z_UP @ to_world @ Matrix.Diagonal((-1.0, 1.0, -1.0, 1.0))
    scene.camera = cobj

    emitters = [e for e in sc.root if e.tag == 'emitter']
    maps = [e for e in emitters if e.get('type') == 'envmap']
    if len(maps) > 1 or any(e.get('type') not in ('envmap', 'directional', 'point') for e in emitters):
        fail('needs at most one envmap, and directional and point emitters, outside the shapes')
    world = bpy.data.worlds.new('world')
    scene.world = world
    world.use_nodes = True
    nt = world.node_tree
    if not maps:  # lit by its other lights alone: a black world
        nt.nodes['Background'].inputs['Strength'].default_value = 0.0
    else:
        add_envmap(sc, nt, maps[0], a.envgi)
    for k, e in enumerate(x for x in emitters if x.get('type') != 'envmap'):
        add_delta_light(sc, scene, e, k)

    i = 0
    for e in (c for c in sc.root if c.tag == 'shape'):
        t = e.get('type')
        if t == 'shapegroup':  # drawn only through its instances
            continue
        if t == 'instance':
            ref = next((c for c in e if c.tag == 'ref'), None)
            group = sc.ids.get(ref.get('id')) if ref is not None else None
            if group is None or group.get('type') != 'shapegroup':
                fail("an instance needs a <ref> to a shapegroup")
            for member in (c for c in group if c.tag == 'shape'):
                add_shape(sc, member, i, sc.transform(e))
                i += 1
            continue
        add_shape(sc, e, i)
        i += 1
    render(sc, scene, a, max_depth)


def latlong_file(sc, env, envgi):
    """The envmap's file as a lat-long map: itself, or for envgi's `layout` (a light probe) the
    map envgi resamples it to as the scene loads, written by `envgi envmap convert`."""
    path = sc.path(sc.prop(env, 'filename'))
    layout = sc.prop(env, 'layout', 'latlong')
    if layout == 'latlong':
        return path
    if not envgi:
        fail(f"an envmap of layout '{layout}' needs --envgi, to resample it to lat-long as envgi does")
    tmp = tempfile.mkdtemp(prefix='cycles_render_')
    atexit.register(shutil.rmtree, tmp, True)  # Blender reads the pixels only as it renders
    out = os.path.join(tmp, 'latlong.exr')
    r = subprocess.run([envgi, '-q', 'envmap', 'convert', path, '--layout', layout, '-o', out],
                       capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"envgi envmap convert failed: {r.stderr.strip()}")
    return out


def add_delta_light(sc, scene, e, k):
    """Mitsuba's directional emitter (irradiance E along `direction`) as a sun of angle 0, whose
    strength is its irradiance; its point emitter (intensity I at `position`) as a point lamp of
    radius 0, whose power P gives I = P / (4 pi). Blender keeps the colour's largest channel in
    the strength."""
    if next((c for c in e if c.tag == 'transform'), None) is not None:
        fail(f"a {e.get('type')} emitter with a to_world is not supported here")
    directional = e.get('type') == 'directional'
    value = sc.prop(e, 'irradiance' if directional else 'intensity', (1.0,) * 3)
    if not isinstance(value, tuple):
        fail(f"a {e.get('type')} emitter's value must be an rgb value here")
    peak = max(value)
    light = bpy.data.lights.new(f'light{k}', 'SUN' if directional else 'POINT')
    light.color = tuple(v / peak for v in value) if peak > 0 else (0.0, 0.0, 0.0)
    if directional:
        light.angle = 0.0
        light.energy = peak
    else:
        light.shadow_soft_size = 0.0
        light.energy = 4 * math.pi * peak
    obj = bpy.data.objects.new(f'light{k}', light)
    scene.collection.objects.link(obj)
    if directional:  # a sun shines along its own -z
        d = (Y_UP_TO_Z_UP.to_3x3() @ sc.point(e, 'direction', (0, 0, 1))).normalized()
        obj.matrix_world = d.to_track_quat('-Z', 'Y').to_matrix().to_4x4()
    else:
        obj.matrix_world = Matrix.Translation(Y_UP_TO_Z_UP @ sc.point(e, 'position', (0, 0, 0)))


def add_envmap(sc, nt, env, envgi=None):
    nt.nodes.clear()
    tex = nt.nodes.new('ShaderNodeTexEnvironment')
    tex.image = bpy.data.images.load(latlong_file(sc, env, envgi))
    tex.interpolation = 'Linear'
    coord = nt.nodes.new('ShaderNodeTexCoord')
    mapping = nt.nodes.new('ShaderNodeMapping')
    turn = Matrix.Rotation(math.radians(ENV_TURN_DEG), 3, 'Z')
    if env.find('transform') is not None:
        # Mitsuba looks the map up at to_world^-1 d (its frame, y up): here at
        # turn . Y . to_world^-1 . Y^-1 d, with Y Mitsuba's frame to Blender's (z up).
        r = sc.transform(env).to_3x3()
        e = r @ r.transposed()
        if r.determinant() < 0 or any(abs(e[i][j] - (i == j)) > 1e-4 for i in range(3) for j in range(3)):
            fail("an envmap's to_world must be a rotation here")
        y = Y_UP_TO_Z_UP.to_3x3()
        turn = turn @ y @ r.transposed() @ y.inverted()
    mapping.inputs['Rotation'].default_value = turn.to_euler('XYZ')
    bg = nt.nodes.new('ShaderNodeBackground')
    bg.inputs['Strength'].default_value = sc.prop(env, 'scale', 1.0)
    out = nt.nodes.new('ShaderNodeOutputWorld')
    nt.links.new(coord.outputs['Generated'], mapping.inputs['Vector'])
    nt.links.new(mapping.outputs['Vector'], tex.inputs['Vector'])
    nt.links.new(tex.outputs['Color'], bg.inputs['Color'])
    nt.links.new(bg.outputs['Background'], out.inputs['Surface'])


def render(sc, scene, a, max_depth):
    scene.render.engine = 'CYCLES'
    c = scene.cycles
    c.device = 'CPU'
    c.samples = a.spp
    c.seed = a.seed
    c.use_adaptive_sampling = a.noise_threshold > 0.0
    if c.use_adaptive_sampling:
        c.adaptive_threshold = a.noise_threshold
        c.adaptive_min_samples = a.min_spp
    c.use_denoising = False
    c.pixel_filter_type = 'BOX'
    c.filter_width = 1.0
    c.sample_clamp_direct = 0.0  # no clamping, no glossy blur: an unbiased path tracer, as envgi's
    c.sample_clamp_indirect = 0.0
    c.blur_glossy = 0.0
    c.caustics_reflective = c.caustics_refractive = True
    # Mitsuba's max_depth counts path segments (2 = direct light); Cycles counts bounces (0 = direct).
    bounces = 1024 if max_depth < 0 else max(0, max_depth - 2)
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = c.transmission_bounces = bounces
    c.transparent_max_bounces = bounces
    scene.render.threads_mode = 'FIXED'
    scene.render.threads = a.threads
    scene.view_settings.view_transform = 'Standard'
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.image_settings.color_mode = 'RGB'
    scene.render.image_settings.color_depth = '32'
    scene.render.filepath = a.out
    t = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    print(f'cycles render: {time.perf_counter() - t:.4f} s', flush=True)


main()
