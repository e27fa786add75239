#!/usr/bin/env python3
"""Writes a bumpy torus as a binary PLY, to measure delmesh beyond the
dragon's size (docs/performance-history.md, session 55), or, for a name
ending in .obj, as an OBJ with texture coordinates and normals per vertex
(a seam where the texture wraps), to measure the cost of attributes
(session 75):

    scripts/make-torus.py N OUT.ply      (N x N vertices, 2 N^2 triangles)
    scripts/make-torus.py N OUT.obj      (the same, textured)
    /usr/bin/time -v target/release/delmesh -i OUT.ply -o out.ply

N = 2000 gives 4M vertices and 8M triangles (152 MB, about 5 s in CPython).
The radius is jittered by up to 1% and each quad's diagonal chosen at
random (seeded: the same mesh every time), so that many edges are not
Delaunay and must be split. Standard library only.
"""
import math
import random
import struct
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: make-torus.py N OUT.ply")
    n = int(sys.argv[1])
    if n < 3:
        sys.exit("N must be at least 3")
    random.seed(7)
    big, small = 3.0, 1.0
    if sys.argv[2].endswith(".obj"):
        write_textured_obj(n, big, small, sys.argv[2])
        return
    with open(sys.argv[2], "wb") as out:
        out.write(
            (
                "ply\nformat binary_little_endian 1.0\n"
                f"element vertex {n * n}\n"
                "property float x\nproperty float y\nproperty float z\n"
                f"element face {2 * n * n}\n"
                "property list uchar int vertex_indices\nend_header\n"
            ).encode()
        )
        buf = bytearray()
        for i in range(n):
            u = 2 * math.pi * i / n
            for j in range(n):
                v = 2 * math.pi * j / n
                r = small * (1 + 0.01 * random.random())
                x = (big + r * math.cos(v)) * math.cos(u)
                y = (big + r * math.cos(v)) * math.sin(u)
                buf += struct.pack("<fff", x, y, r * math.sin(v))
        out.write(buf)
        buf = bytearray()
        for i in range(n):
            i1 = (i + 1) % n
            for j in range(n):
                j1 = (j + 1) % n
                a, b, c, d = i * n + j, i1 * n + j, i1 * n + j1, i * n + j1
                if random.random() < 0.5:
                    buf += struct.pack("<Biii", 3, a, b, c) + struct.pack("<Biii", 3, a, c, d)
                else:
                    buf += struct.pack("<Biii", 3, a, b, d) + struct.pack("<Biii", 3, b, c, d)
            if len(buf) > 1 << 24:
                out.write(buf)
                buf = bytearray()
        out.write(buf)


def write_textured_obj(n, big, small, path):
    """The same torus as an OBJ: positions as the PLY's (rounded to f32),
    texture coordinates (i/n, j/n) on an (n+1) x (n+1) grid, so that the
    texture wraps at a seam, and the smooth torus's normal per vertex."""
    f32 = struct.Struct("<f")
    with open(path, "w") as out:
        lines = []
        for i in range(n):
            u = 2 * math.pi * i / n
            for j in range(n):
                v = 2 * math.pi * j / n
                r = small * (1 + 0.01 * random.random())
                x = (big + r * math.cos(v)) * math.cos(u)
                y = (big + r * math.cos(v)) * math.sin(u)
                p = [f32.unpack(f32.pack(c))[0] for c in (x, y, r * math.sin(v))]
                lines.append("v %r %r %r\n" % tuple(p))
        for i in range(n + 1):
            for j in range(n + 1):
                lines.append("vt %r %r\n" % (i / n, j / n))
        for i in range(n):
            u = 2 * math.pi * i / n
            for j in range(n):
                v = 2 * math.pi * j / n
                lines.append("vn %.6f %.6f %.6f\n" % (math.cos(v) * math.cos(u), math.cos(v) * math.sin(u), math.sin(v)))
        out.write("".join(lines))
        lines = []
        for i in range(n):
            for j in range(n):
                corner = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                a, b, c, d = ["%d/%d/%d" % ((ci % n) * n + cj % n + 1, ci * (n + 1) + cj + 1, (ci % n) * n + cj % n + 1) for ci, cj in corner]
                if random.random() < 0.5:
                    lines.append("f %s %s %s\nf %s %s %s\n" % (a, b, c, a, c, d))
                else:
                    lines.append("f %s %s %s\nf %s %s %s\n" % (a, b, d, b, c, d))
            out.write("".join(lines))
            lines = []


if __name__ == "__main__":
    main()
