#!/usr/bin/env python3
"""Writes scenes/textures/uv-grid.png: a 512x256 test texture for the sphere's lat-long (u, v),
8x4 cells whose hue follows u and whose brightness follows v, thin dark lines between cells, a
bright marker in the top-left cell (u < 1/8, v < 1/4) so that flips and turns show. Standard
library only (zlib + struct), so that the file can be made again anywhere. Own work, CC0."""
import colorsys
import struct
import sys
import zlib

W, H = 512, 256
CELLS_X, CELLS_Y = 8, 4

def pixel(x, y):
    cx, cy = x * CELLS_X // W, y * CELLS_Y // H
    fx, fy = (x * CELLS_X) % W, (y * CELLS_Y) % H
    if fx < 4 or fy < 4:
        return (30, 30, 30)
    if cx == 0 and cy == 0 and 24 < fx < 40 and 24 < fy < 40:
        return (250, 250, 250)
    r, g, b = colorsys.hsv_to_rgb((cx + 0.5) / CELLS_X, 0.65, 0.35 + 0.6 * (cy + 0.5) / CELLS_Y)
    checker = 0.85 if (cx + cy) % 2 else 1.0
    return tuple(int(round(255 * c * checker)) for c in (r, g, b))

def png(width, height, rows):
    def chunk(kind, data):
        return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data) & 0xffffffff)
    raw = b''.join(b'\x00' + bytes(c for p in row for c in p) for row in rows)
    return (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', width, height, 8, 2, 0, 0, 0)) +
            chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))

if __name__ == '__main__':
    out = sys.argv[1] if len(sys.argv) > 1 else 'scenes/textures/uv-grid.png'
    with open(out, 'wb') as f:
        f.write(png(W, H, [[pixel(x, y) for x in range(W)] for y in range(H)]))
