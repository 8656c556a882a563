#!/usr/bin/env python3
"""Writes scenes/textures/bumps-normal.png, the example normal map: a 4 x 4 grid of smooth
domes, as a tangent-space normal map (rgb = (n + 1) / 2, x along u, y along v, z out of the
surface), 8 bits, to be read with raw = true. Standard library only, so that the bundled file
can be made again anywhere: python3 scripts/make_normal_map.py [out.png] [size]."""
import math
import struct
import sys
import zlib


def normal(x, y, cells=4, radius=0.42, height=0.22):
    """The domes' normal at (x, y) in [0, 1)^2: h = height (1 - (d / r)^2)^2 inside each dome."""
    cx, cy = (x * cells) % 1.0 - 0.5, (y * cells) % 1.0 - 0.5
    d2 = (cx * cx + cy * cy) / (radius * radius)
    if d2 >= 1.0:
        return 0.0, 0.0, 1.0
    # dh/dcx = height * 2 (1 - d2) * (-2 cx / r^2), per cell; times `cells` per unit of (x, y).
    k = -4.0 * height * (1.0 - d2) / (radius * radius) * cells
    gx, gy = k * cx, k * cy
    n = (-gx, -gy, 1.0)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(c / length for c in n)


def height(x, y, cells=4, radius=0.42):
    """The same domes' height at (x, y), scaled to [0, 1]: (1 - (d / r)^2)^2 inside each dome
    (a bump map of it, read raw, with scale 0.22 / cells, has the normals above)."""
    cx, cy = (x * cells) % 1.0 - 0.5, (y * cells) % 1.0 - 0.5
    d2 = (cx * cx + cy * cy) / (radius * radius)
    return (1.0 - d2) ** 2 if d2 < 1.0 else 0.0


def write_png(path, size, texel=None):
    """The normal map, or with texel=f(x, y) -> (r, g, b) in [0, 1] any other image."""
    texel = texel or (lambda x, y: tuple((c + 1.0) * 0.5 for c in normal(x, y)))
    rows = []
    for j in range(size):
        row = bytearray([0])  # filter type 0 for each scanline
        for i in range(size):
            c = texel((i + 0.5) / size, (j + 0.5) / size)
            row += bytes(max(0, min(255, round(v * 255.0))) for v in c)
        rows.append(bytes(row))
    def chunk(tag, data):
        return struct.pack('>I', len(data)) + tag + data + struct.pack('>I', zlib.crc32(tag + data) & 0xffffffff)
    png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', size, size, 8, 2, 0, 0, 0))
    png += chunk(b'IDAT', zlib.compress(b''.join(rows), 9)) + chunk(b'IEND', b'')
    with open(path, 'wb') as f:
        f.write(png)


def write_height_png(path, size):
    """The domes as a height field (grey), for Mitsuba's bumpmap."""
    write_png(path, size, lambda x, y: (height(x, y),) * 3)


if __name__ == '__main__':
    out = sys.argv[1] if len(sys.argv) > 1 else 'scenes/textures/bumps-normal.png'
    write_png(out, int(sys.argv[2]) if len(sys.argv) > 2 else 256)
