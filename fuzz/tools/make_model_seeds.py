#!/usr/bin/env python3
# Writes the seeds of the ply and stl fuzz targets (fuzz/corpus/ply, fuzz/corpus/stl; committed,
# run this only to change them): ASCII and binary files of both endiannesses, every integer and
# float type, lists with uchar and ushort counts, extra elements, colours inside and outside
# [0, 1], and the STL cases load_model must tell apart (a binary file whose header starts with
# "solid", a degenerate facet, zero normals).
import os
import struct
import sys

root = sys.argv[1] if len(sys.argv) > 1 else "fuzz/corpus"
ply = os.path.join(root, "ply")
stl = os.path.join(root, "stl")
os.makedirs(ply, exist_ok=True)
os.makedirs(stl, exist_ok=True)


def write(path, data):
    with open(path, "wb") as f:
        f.write(data.encode() if isinstance(data, str) else data)


write(os.path.join(ply, "ascii_colours"), """ply
format ascii 1.0
comment a triangle with normals, uvs and colours
element vertex 3
property float x
property float y
property float z
property float nx
property float ny
property float nz
property float s
property float t
property uchar red
property uchar green
property uchar blue
property uchar alpha
element face 1
property list uchar int vertex_indices
end_header
0 0 0 0 0 1 0 0 255 0 0 255
1 0 0 0 0 1 1 0 0 255 0 255
0 1 0 0 0 1 0 1 0 0 255 128
3 0 1 2
""")
write(os.path.join(ply, "ascii_colours_out_of_range"), """ply
format ascii 1.0
comment colours past [0, 1] (clamped by the loader)
element vertex 3
property float x
property float y
property float z
property float red
property char green
property int blue
element face 1
property list uchar int vertex_indices
end_header
0 0 0 2.5 -100 -7
1 0 0 -1 127 2147483647
0 1 0 0.5 0 1
3 0 1 2
""")
write(os.path.join(ply, "ascii_quad_extra_elements"), """ply
format ascii 1.0
obj_info made by hand
element vertex 4
property double x
property double y
property double z
property float texture_u
property float texture_v
element face 1
property list uchar uint vertex_index
element edge 2
property int vertex1
property int vertex2
element material 1
property float diffuse_red
end_header
-1 -1 0 0 0
1 -1 0 1 0
1 1 0 1 1
-1 1 0 0 1
4 0 1 2 3
0 1
1 2
0.5
""")

CODES = {"float": "f", "double": "d", "uchar": "B", "char": "b", "ushort": "H", "short": "h",
         "int": "i", "uint": "I"}


def binary_cube(endian, format_name, position, index, count, colour):
    header = "ply\nformat %s 1.0\nelement vertex 8\n" % format_name
    header += "".join("property %s %s\n" % (position, axis) for axis in "xyz")
    if colour:
        header += "property ushort r\nproperty ushort g\nproperty ushort b\n"
    header += "element face 6\nproperty list %s %s vertex_indices\nend_header\n" % (count, index)
    out = bytearray(header.encode())
    for i in range(8):
        corner = ((i & 1) * 2 - 1, ((i >> 1) & 1) * 2 - 1, ((i >> 2) & 1) * 2 - 1)
        out += struct.pack(endian + CODES[position] * 3, *corner)
        if colour:
            out += struct.pack(endian + "HHH", i * 8000, 65535 - i * 8000, 30000)
    for face in [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]:
        out += struct.pack(endian + CODES[count], 4) + struct.pack(endian + CODES[index] * 4, *face)
    return bytes(out)


write(os.path.join(ply, "binary_le_cube"),
      binary_cube("<", "binary_little_endian", "float", "int", "uchar", True))
write(os.path.join(ply, "binary_be_cube"),
      binary_cube(">", "binary_big_endian", "double", "ushort", "uchar", False))
write(os.path.join(ply, "binary_le_short_counts"),
      binary_cube("<", "binary_little_endian", "float", "uint", "ushort", False))

write(os.path.join(stl, "ascii_facet"), """solid tri
facet normal 0 0 1
  outer loop
    vertex 0 0 0
    vertex 1 0 0
    vertex 0 1 0
  endloop
endfacet
endsolid tri
""")
write(os.path.join(stl, "ascii_two_facets_no_normal"), """solid
  facet normal 0 0 0
    outer loop
      vertex 0 0 0
      vertex 1e3 0 0
      vertex 0 -2.5e-2 1
    endloop
  endfacet
  facet normal 0 0 -1
    outer loop
      vertex 0 0 0
      vertex 0 1 0
      vertex 1 0 0
    endloop
  endfacet
endsolid
""")


def binary_stl(header, triangles):
    out = bytearray(header.ljust(80, b" ")[:80]) + struct.pack("<I", len(triangles))
    for normal, corners in triangles:
        out += struct.pack("<3f", *normal)
        for corner in corners:
            out += struct.pack("<3f", *corner)
        out += struct.pack("<H", 0)
    return bytes(out)


up = ((0, 0, 1), ((0, 0, 0), (1, 0, 0), (0, 1, 0)))
unset = ((0, 0, 0), ((0, 0, 0), (0, 1, 0), (-1, 0, 0)))
point = ((0, 0, 1), ((1, 1, 1), (1, 1, 1), (1, 1, 1)))
write(os.path.join(stl, "binary_two"), binary_stl(b"binary stl", [up, unset]))
write(os.path.join(stl, "binary_header_says_solid"), binary_stl(b"solid but binary", [up]))
write(os.path.join(stl, "binary_degenerate"), binary_stl(b"x", [point, up]))
