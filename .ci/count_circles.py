#!/usr/bin/env python3
"""Counts the coloured circles in a screenshot PNG and fails unless there are enough.

Usage: count_circles.py PICTURE.png MIN_CIRCLES [MAX_CIRCLES]

Standard library only (the PNG is read by png.py). A pixel is "coloured" when its channels
differ by more than 60 (the arena, background and HUD are grey); circles are 4-connected blobs
of coloured pixels of at least 12 pixels.
"""
import sys

from png import read_png


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
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__)
    path, minimum = sys.argv[1], int(sys.argv[2])
    maximum = int(sys.argv[3]) if len(sys.argv) == 4 else None
    blobs = count_blobs(*read_png(path))
    most = "" if maximum is None else f", at most {maximum}"
    print(f"{path}: {blobs} coloured circles (need at least {minimum}{most})")
    if blobs < minimum or (maximum is not None and blobs > maximum):
        sys.exit(1)


if __name__ == "__main__":
    main()
