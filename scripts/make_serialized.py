#!/usr/bin/env python3
"""Writes meshes as one Mitsuba .serialized file (version 4, single precision, zlib), by the
format's description: each mesh a header and a zlib stream, then the meshes' offsets and count.
Reads the meshes with Mitsuba 3 (any shape file it loads: .ply, .obj), so that the file holds
the very vertices Mitsuba sees. For checks only (scripts/crosscheck_mitsuba.py's serialized
configuration); run with the Mitsuba virtual environment's python:
  python scripts/make_serialized.py OUT.serialized MESH.ply [MESH2.ply ...]
"""
import struct
import sys
import zlib

import mitsuba as mi
import numpy as np

mi.set_variant('scalar_rgb')


def block(mesh, name):
    pos = np.array(mesh.vertex_positions_buffer(), dtype=np.float32)
    faces = np.array(mesh.faces_buffer(), dtype=np.uint32)
    flags = 0x1000
    normals = b''
    if mesh.has_vertex_normals():
        flags |= 0x0001
        normals = np.array(mesh.vertex_normals_buffer(), dtype=np.float32).tobytes()
    uvs = b''
    if mesh.has_vertex_texcoords():
        flags |= 0x0002
        uvs = np.array(mesh.vertex_texcoords_buffer(), dtype=np.float32).tobytes()
    body = struct.pack('<I', flags) + name.encode() + b'\0' + struct.pack('<QQ', len(pos) // 3, len(faces) // 3)
    body += pos.tobytes() + normals + uvs + faces.tobytes()
    return struct.pack('<HH', 0x041C, 4) + zlib.compress(body, 6)


def main():
    out, meshes = sys.argv[1], sys.argv[2:]
    data, offsets = b'', []
    for path in meshes:
        m = mi.load_dict({'type': path.rsplit('.', 1)[1], 'filename': path, 'face_normals': True})
        offsets.append(len(data))
        data += block(m, path.rsplit('/', 1)[-1])
    data += b''.join(struct.pack('<Q', o) for o in offsets) + struct.pack('<I', len(meshes))
    open(out, 'wb').write(data)


if __name__ == '__main__':
    main()
