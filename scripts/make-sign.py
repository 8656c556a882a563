#!/usr/bin/env python3
"""Writes scenes/textures/sign.png: a 64x16 "sign", the letters ENVGI in 2x2-pixel dots (amber,
255 in red) on a dark panel (6 in each channel, 2e-3 once sRGB-decoded): an emission texture of
high contrast, where drawing a light's points by its texture pays most. Standard library only
(zlib + struct). Own work, CC0."""
import struct
import sys
import zlib

W, H = 64, 16
FONT = {'E': ["111", "100", "110", "100", "111"], 'N': ["101", "111", "111", "111", "101"],
        'V': ["101", "101", "101", "101", "010"], 'G': ["111", "100", "101", "101", "111"],
        'I': ["111", "010", "010", "010", "111"]}
PANEL = 6

def main(path):
    img = [[PANEL] * W for _ in range(H)]
    x0 = 6
    for ch in "ENVGI":
        for r, row in enumerate(FONT[ch]):
            for c, bit in enumerate(row):
                if bit == '1':
                    for dy in range(2):
                        for dx in range(2):
                            img[3 + 2 * r + dy][x0 + 2 * c + dx] = 255
        x0 += 11
    def rgb(v):
        return (v, v // 2 + v // 3, v // 4) if v > PANEL else (v, v, v)
    raw = b''.join(b'\x00' + bytes(c for v in row for c in rgb(v)) for row in img)
    def chunk(tag, data):
        return struct.pack('>I', len(data)) + tag + data + struct.pack('>I', zlib.crc32(tag + data) & 0xffffffff)
    png = (b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', W, H, 8, 2, 0, 0, 0)) +
           chunk(b'IDAT', zlib.compress(raw, 9)) + chunk(b'IEND', b''))
    with open(path, 'wb') as f:
        f.write(png)

if __name__ == '__main__':
    main(sys.argv[1] if len(sys.argv) > 1 else 'scenes/textures/sign.png')
