#!/usr/bin/env python3
"""Writes the small model files the loader tests read: PLY, OBJ and STL in the forms scanners,
archives and CAD tools write (strips, polygons, big-endian, extra properties, vertex colours,
negative indices, wrong counts, cut files). Run from this folder; the files are committed."""
import math
import struct

# A unit cube centred on the origin; faces as outward (counter-clockwise) quads.
CUBE_V = [(x - 0.5, y - 0.5, z - 0.5) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_Q = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
CUBE_T = [t for a, b, c, d in CUBE_Q for t in ((a, b, c), (a, c, d))]


def prism(sides=6):
    """A hexagonal prism (radius 0.5, height 1): two n-gon caps and quad sides, outward."""
    v = [(0.5 * math.cos(2 * math.pi * i / sides), 0.5 * math.sin(2 * math.pi * i / sides), z)
         for z in (-0.5, 0.5) for i in range(sides)]
    faces = [tuple(reversed(range(sides))), tuple(range(sides, 2 * sides))]
    faces += [(i, (i + 1) % sides, sides + (i + 1) % sides, sides + i) for i in range(sides)]
    return v, faces


def write(name, data):
    with open(name, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


def ply_tristrips():
    """ASCII; one strip per cube face (p0 p1 p3 p2), the strips joined by -1 restarts."""
    indices = []
    for a, b, c, d in CUBE_Q:
        indices += ([-1] if indices else []) + [a, b, d, c]
    head = "ply\nformat ascii 1.0\ncomment strips as Stanford's range scans store them\n"
    head += "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
    head += "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
    body = "".join("%g %g %g\n" % p for p in CUBE_V)
    return head + body + "%d %s\n" % (len(indices), " ".join(map(str, indices)))


def ply_big_endian_quads():
    """Binary big-endian; quads; extra per-vertex properties (confidence, intensity, a list);
    uchar vertex colours (red on top, blue below); an extra face property; an element to skip."""
    head = ("ply\nformat binary_big_endian 1.0\nobj_info scanner: none\n"
            "element vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
            "property float confidence\nproperty uchar intensity\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n"
            "property list uchar float extra\n"
            "element face 6\nproperty uchar flags\nproperty list uchar int vertex_indices\n"
            "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n")
    body = b""
    for i, (x, y, z) in enumerate(CUBE_V):
        color = (255, 0, 0) if z > 0 else (0, 0, 255)
        body += struct.pack(">ffffB", x, y, z, 0.9, 7) + bytes(color) + b"\xff"
        body += struct.pack(">Bff", 2, 1.5, -2.5)
    for q in CUBE_Q:
        body += struct.pack(">BB4i", 1, 4, *q)
    body += struct.pack(">ii", 0, 1)
    return head.encode() + body


def ply_polygons():
    """ASCII hexagonal prism: two hexagons and six quads, float vertex colours (mid grey)."""
    v, faces = prism()
    head = ("ply\nformat ascii 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
            "property double z\nproperty float diffuse_red\nproperty float diffuse_green\n"
            "property float diffuse_blue\nelement face %d\nproperty list uchar uint vertex_index\n"
            "end_header\n" % (len(v), len(faces)))
    body = "".join("%r %r %r 0.5 0.5 0.5\n" % p for p in v)
    body += "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces)
    return head + body


def obj_negative_ngons():
    """Hexagonal prism with negative (relative) indices, hexagon caps, and a material library
    that is not there."""
    v, faces = prism()
    text = "mtllib missing.mtl\nusemtl grey\n" + "".join("v %r %r %r\n" % p for p in v)
    text += "".join("f %s\n" % " ".join(str(i - len(v)) for i in f) for f in faces)
    return text


def stl_ascii(triangles, name="cube"):
    out = "solid %s\n" % name
    for t in triangles:
        out += "  facet normal 0 0 0\n    outer loop\n"
        out += "".join("      vertex %g %g %g\n" % CUBE_V[i] for i in t)
        out += "    endloop\n  endfacet\n"
    return out + "endsolid %s\n" % name


def stl_binary(triangles, count):
    data = b"binary STL written by make_meshes.py".ljust(80, b" ") + struct.pack("<I", count)
    for t in triangles:
        data += struct.pack("<3f", 0, 0, 0)
        data += b"".join(struct.pack("<3f", *CUBE_V[i]) for i in t) + b"\0\0"
    return data


def main():
    write("cube_tristrips.ply", ply_tristrips())
    write("cube_quads_big_endian_colors.ply", ply_big_endian_quads())
    write("prism_polygons.ply", ply_polygons())
    write("prism_negative_ngons.obj", obj_negative_ngons())
    ascii_cube = stl_ascii(CUBE_T)
    write("cube_ascii.stl", ascii_cube)
    # Cut in the middle of the seventh facet, as an interrupted download leaves it.
    seventh = ascii_cube.index("facet normal", 0)
    for _ in range(6):
        seventh = ascii_cube.index("facet normal", seventh + 1)
    write("cube_ascii_cut.stl", ascii_cube[:ascii_cube.index("vertex", seventh) + 20])
    write("cube_ascii_empty_solid.stl", ascii_cube + "solid empty\nendsolid empty\n")
    write("cube_inward.stl", stl_ascii([(a, c, b) for a, b, c in CUBE_T], "inward"))
    write("cube_binary_count_0.stl", stl_binary(CUBE_T, 0))
    write("cube_binary_count_99.stl", stl_binary(CUBE_T, 99))


if __name__ == "__main__":
    main()
