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


BIG, SMALL = 3.0, 1.0


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: make-torus.py N OUT.ply|OUT.obj")
    n = int(sys.argv[1])
    if n < 3:
        sys.exit("N must be at least 3")
    random.seed(7)
    if sys.argv[2].endswith(".obj"):
        write_textured_obj(n, sys.argv[2])
    else:
        write_ply(n, sys.argv[2])


def positions(n):
    """The n x n vertices, row by row, their radius jittered (seeded)."""
    for i in range(n):
        u = 2 * math.pi * i / n
        for j in range(n):
            v = 2 * math.pi * j / n
            r = SMALL * (1 + 0.01 * random.random())
            x = (BIG + r * math.cos(v)) * math.cos(u)
            y = (BIG + r * math.cos(v)) * math.sin(u)
            yield x, y, r * math.sin(v)


def quads(n):
    """Each quad's corners (i, j) in order around it, and whether it is cut
    along its first diagonal (seeded): the torus's faces, row by row."""
    for i in range(n):
        for j in range(n):
            corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
            yield i, corners, random.random() < 0.5


def triangles(corners, first_diagonal):
    a, b, c, d = corners
    return [(a, b, c), (a, c, d)] if first_diagonal else [(a, b, d), (b, c, d)]


def write_ply(n, path):
    """The torus as a binary PLY of float positions."""
    with open(path, "wb") as out:
        out.write(
            (
                "ply\nformat binary_little_endian 1.0\n"
                f"element vertex {n * n}\n"
                "property float x\nproperty float y\nproperty float z\n"
                f"element face {2 * n * n}\n"
                "property list uchar int vertex_indices\nend_header\n"
            ).encode()
        )
        out.write(b"".join(struct.pack("<fff", *p) for p in positions(n)))
        buf = bytearray()
        for i, corners, first in quads(n):
            index = [(ci % n) * n + cj % n for ci, cj in corners]
            for t in triangles(index, first):
                buf += struct.pack("<Biii", 3, *t)
            if len(buf) > 1 << 24:
                out.write(buf)
                buf = bytearray()
        out.write(buf)


def write_textured_obj(n, path):
    """The same torus as an OBJ: positions as the PLY's (rounded to f32),
    texture coordinates (i/n, j/n) on an (n+1) x (n+1) grid, so that the
    texture wraps at a seam, and the smooth torus's normal per vertex."""
    f32 = struct.Struct("<f")
    with open(path, "w") as out:
        lines = []
        for p in positions(n):
            p = [f32.unpack(f32.pack(c))[0] for c in p]
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
        for i, corners, first in quads(n):
            corner = ["%d/%d/%d" % ((ci % n) * n + cj % n + 1, ci * (n + 1) + cj + 1, (ci % n) * n + cj % n + 1) for ci, cj in corners]
            for t in triangles(corner, first):
                lines.append("f %s %s %s\n" % t)
            if len(lines) > 1 << 16:
                out.write("".join(lines))
                lines = []
        out.write("".join(lines))


if __name__ == "__main__":
    main()
