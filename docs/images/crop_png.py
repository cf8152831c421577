#!/usr/bin/env python3
"""Crops the same rectangle out of several 8-bit RGB or RGBA PNGs (as softrast writes them), enlarges
each by an integer factor (nearest neighbour, so single pixels stay visible) and writes them side
by side, 4 pixels apart, into one PNG. Standard library only.

Usage: crop_png.py OUT.png X Y W H SCALE IN.png [IN.png ...]"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, width = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace != 0:
                sys.exit(f"{path}: expected 8-bit RGB or RGBA, not interlaced")
            bpp = 4 if colour == 6 else 3
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        prev = line
        if bpp == 3:  # to RGBA
            line = bytearray(b"".join(bytes(line[i:i + 3]) + b"\xff" for i in range(0, stride, 3)))
        rows.append(line)
    return width, height, rows


def write_png(path, width, height, rows):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def main():
    if len(sys.argv) < 8:
        sys.exit(__doc__)
    out = sys.argv[1]
    x, y, w, h, scale = (int(v) for v in sys.argv[2:7])
    images = [read_png(p) for p in sys.argv[7:]]
    gap = 4
    total_w = len(images) * w * scale + (len(images) - 1) * gap
    rows = [bytearray(b"\xff\xff\xff\xff" * total_w) for _ in range(h * scale)]
    for k, (iw, ih, src) in enumerate(images):
        if x + w > iw or y + h > ih:
            sys.exit(f"{sys.argv[7 + k]}: the crop leaves the {iw}x{ih} image")
        left = k * (w * scale + gap)
        for yy in range(h * scale):
            line = src[y + yy // scale]
            for xx in range(w * scale):
                i = (x + xx // scale) * 4
                o = (left + xx) * 4
                rows[yy][o:o + 4] = line[i:i + 4]
    write_png(out, total_w, h * scale, rows)


main()
