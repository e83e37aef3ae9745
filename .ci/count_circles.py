#!/usr/bin/env python3
"""Counts the coloured circles in a screenshot PNG and fails unless there are enough.

Usage: count_circles.py PICTURE.png MIN_CIRCLES

Standard library only (zlib): decodes 8-bit RGB/RGBA non-interlaced PNGs, the kind the app
writes. A pixel is "coloured" when its channels differ by more than 60 (the arena, background
and HUD are grey); circles are 4-connected blobs of coloured pixels of at least 12 pixels.
"""
import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG file")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {2: 3, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        sys.exit(f"{path}: unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(line)
        prev = line
    return width, height, channels, rows


def count_blobs(width, height, channels, rows, min_pixels=12):
    coloured = [[False] * width for _ in range(height)]
    for y, line in enumerate(rows):
        for x in range(width):
            r, g, b = line[x * channels:x * channels + 3]
            coloured[y][x] = max(r, g, b) - min(r, g, b) > 60
    seen = [[False] * width for _ in range(height)]
    blobs = 0
    for y in range(height):
        for x in range(width):
            if not coloured[y][x] or seen[y][x]:
                continue
            stack, size = [(x, y)], 0
            seen[y][x] = True
            while stack:
                cx, cy = stack.pop()
                size += 1
                for nx, ny in ((cx + 1, cy), (cx - 1, cy), (cx, cy + 1), (cx, cy - 1)):
                    if 0 <= nx < width and 0 <= ny < height and coloured[ny][nx] and not seen[ny][nx]:
                        seen[ny][nx] = True
                        stack.append((nx, ny))
            blobs += size >= min_pixels
    return blobs


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    path, minimum = sys.argv[1], int(sys.argv[2])
    blobs = count_blobs(*read_png(path))
    print(f"{path}: {blobs} coloured circles (need at least {minimum})")
    if blobs < minimum:
        sys.exit(1)


main()
