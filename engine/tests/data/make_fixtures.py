#!/usr/bin/env python3
"""Writes the small fixture files the format readers are tested on (engine/src/formats).

Run from this folder: python3 make_fixtures.py. Standard library only.
Meshes: a unit cube (8 vertices, 12 triangles, outward winding). Clouds: the five points
POINTS below, in every supported encoding; the organised clouds add one NaN pixel.
"""
import struct

CUBE_VERTICES = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
                 (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
# Quads (1-based, outward): bottom, front, right, back, left, top.
CUBE_QUADS = [(1, 4, 3, 2), (1, 2, 6, 5), (2, 3, 7, 6), (3, 4, 8, 7), (4, 1, 5, 8), (5, 6, 7, 8)]
CUBE_TRIANGLES = [t for a, b, c, d in CUBE_QUADS for t in ((a, b, c), (a, c, d))]

POINTS = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 2.0, 0.0), (0.0, 0.0, -3.5), (0.25, -0.5, 1.5)]
NAN = float("nan")
ORGANISED = [POINTS[0], (NAN, NAN, NAN)] + POINTS[1:]  # 3 x 2 image, 2nd pixel without return


def g(v):
    return "nan" if v != v else "%g" % v


def write(name, data):
    with open(name, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


def cube_obj():
    lines = ["# unit cube in two objects, exercising the OBJ syntax the reader meets",
             "mtllib cube.mtl", "o lower"]
    for i, v in enumerate(CUBE_VERTICES):
        extra = " 0.5 0.5 0.5" if i == 6 else (" 1.0" if i == 0 else "")  # colour, weight
        lines.append("v %s%s" % (" ".join(g(c) for c in v), extra))
    lines += ["vt 0 0", "vt 1 0", "vt 1 1", "vn 0 0 -1", "usemtl grey", "s off"]
    lines.append("f 1/1/1 4/2/1 3/3/1 2/1/1")          # bottom, v/vt/vn
    lines.append("f 1//1 2//1 6//1 5//1")              # front, v//vn
    lines.append("g sides")
    lines.append("f 2/1 3/2 7/3 6/1")                  # right, v/vt
    lines.append("f 3 4 8 7")                          # back
    lines.append("f\t4 1  5 8 ")                       # left, odd spacing
    lines.append("l 1 2")                              # a line: ignored
    lines += ["o upper", "f -4 -3 -2 -1"]              # top, relative indices
    write("cube.obj", "\r\n".join(lines[:3]) + "\r\n" + "\n".join(lines[3:]) + "\n")


def cube_stl_ascii():
    out = ["solid cube"]
    for t in CUBE_TRIANGLES:
        out += ["  facet normal 0 0 0", "    outer loop"]
        out += ["      vertex %s" % " ".join("%e" % c for c in CUBE_VERTICES[i - 1]) for i in t]
        out += ["    endloop", "  endfacet"]
    out.append("endsolid cube")
    write("cube_ascii.stl", "\n".join(out) + "\n")


def cube_stl_binary(header):
    data = header.ljust(80, b"\0") + struct.pack("<I", len(CUBE_TRIANGLES))
    for t in CUBE_TRIANGLES:
        data += struct.pack("<3f", 0, 0, 0)
        for i in t:
            data += struct.pack("<3f", *CUBE_VERTICES[i - 1])
        data += struct.pack("<H", 0)
    return data


def pcd_header(fields, sizes, types, width, height, data):
    return ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS %s\nSIZE %s\n"
            "TYPE %s\nCOUNT %s\nWIDTH %d\nHEIGHT %d\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %d\n"
            "DATA %s\n" % (fields, sizes, types, " ".join("1" * len(sizes.split())),
                           width, height, width * height, data)).encode()


def lzf_compress(data):
    """Greedy LZF (liblzf format): literal runs of up to 32 bytes, back-references of 3 to
    264 bytes at most 8192 bytes back."""
    out, literal, i = bytearray(), bytearray(), 0

    def flush():
        while literal:
            run = literal[:32]
            out.append(len(run) - 1)
            out.extend(run)
            del literal[:32]

    while i < len(data):
        best_len, best_off = 0, 0
        for j in range(max(0, i - 8192), i):
            n = 0
            while n < 264 and i + n < len(data) and data[j + n] == data[i + n]:
                n += 1
            if n > best_len:
                best_len, best_off = n, i - j
        if best_len >= 3:
            flush()
            length, off = best_len - 2, best_off - 1
            if length < 7:
                out.append((length << 5) | (off >> 8))
            else:
                out.append((7 << 5) | (off >> 8))
                out.append(length - 7)
            out.append(off & 0xFF)
            i += best_len
        else:
            literal.append(data[i])
            i += 1
    flush()
    return bytes(out)


def pcds():
    rows = ["%s %s %s %d" % (g(x), g(y), g(z), k) for k, (x, y, z) in enumerate(POINTS)]
    write("points_ascii.pcd", pcd_header("x y z intensity", "4 4 4 2", "F F F U", 5, 1, "ascii")
          + ("\n".join(rows) + "\n").encode())
    body = b"".join(struct.pack("<3fI", x, y, z, 0xFF0000) for x, y, z in POINTS)
    write("points_binary.pcd", pcd_header("x y z rgb", "4 4 4 4", "F F F U", 5, 1, "binary") + body)
    # binary_compressed: each field's values for all points together (x..., y..., z..., i...).
    columns = b"".join(struct.pack("<5f", *[p[a] for p in POINTS]) for a in range(3))
    columns += struct.pack("<5f", *[1.0] * 5)
    packed = lzf_compress(columns)
    write("points_binary_compressed.pcd",
          pcd_header("x y z intensity", "4 4 4 4", "F F F F", 5, 1, "binary_compressed")
          + struct.pack("<II", len(packed), len(columns)) + packed)
    rows = ["%s %s %s" % tuple(g(c) for c in p) for p in ORGANISED]
    write("organised_nan_ascii.pcd", pcd_header("x y z", "4 4 4", "F F F", 3, 2, "ascii")
          + ("\n".join(rows) + "\n").encode())
    body = b"".join(struct.pack("<3d", *p) for p in ORGANISED)
    write("organised_nan_binary.pcd", pcd_header("x y z", "8 8 8", "F F F", 3, 2, "binary") + body)


def plys():
    head = "ply\nformat %s 1.0\ncomment uavex fixture\nelement vertex 5\n%send_header\n"
    props = "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
    face = "element face 1\nproperty list uchar int vertex_indices\n"
    rows = "".join("%s %s %s 200\n" % tuple(g(c) for c in p) for p in POINTS)
    write("points_ascii.ply", head % ("ascii", props + face) + rows + "3 0 1 2\n")
    body = b"".join(struct.pack("<3fB", *p, 200) for p in POINTS)
    write("points_binary_le.ply", (head % ("binary_little_endian", props)).encode() + body)
    props = "property double x\nproperty double y\nproperty double z\n"
    body = b"".join(struct.pack(">3d", *p) for p in POINTS)
    write("points_binary_be.ply", (head % ("binary_big_endian", props)).encode() + body)


if __name__ == "__main__":
    cube_obj()
    cube_stl_ascii()
    write("cube_binary.stl", cube_stl_binary(b"binary unit cube, uavex fixture"))
    write("cube_binary_solid_header.stl", cube_stl_binary(b"solid cube written by a CAD tool"))
    pcds()
    plys()
