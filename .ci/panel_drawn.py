#!/usr/bin/env python3
"""Fails unless the app's live panel is drawn in a screenshot PNG.

Usage: panel_drawn.py PICTURE.png

The panel is an egui window docked at the top right. In the box it covers, at least 30 % of the
pixels must be egui's window fill (grey 27, which nothing else in the app draws: the arena's
backdrop is blue-grey, the background near black) and at least 100 must be drawn in one of the
solver colours of the rolling plots (its lines and legend).
"""
import sys

from png import read_png

FILL = (27, 27, 27)
SOLVER_COLOURS = {(215, 48, 39), (35, 139, 69), (33, 113, 181), (160, 120, 230)}


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    path = sys.argv[1]
    width, height, channels, rows = read_png(path)
    fill = lines = total = 0
    for y in range(60, min(400, height)):
        line = rows[y]
        for x in range(max(0, width - 320), width - 20):
            pixel = tuple(line[x * channels:x * channels + 3])
            total += 1
            fill += pixel == FILL
            lines += pixel in SOLVER_COLOURS
    share = fill / max(total, 1)
    print(f"{path}: panel fill {share:.0%} of its box (need 30 %), {lines} plot-line pixels (need 100)")
    if share < 0.3 or lines < 100:
        sys.exit(1)


if __name__ == "__main__":
    main()
