#!/usr/bin/env python3
"""Grabs the X display and checks what rviz drew: advisory arrows and a framed road.

    screenshot_check.py [--save FILE] [--image FILE]

Reads $DISPLAY (or --image, a saved screenshot). Prints one line of counts; exits 0 when
  - advisory-arrow pixels (the colours of palcas_sumo_bridge's advisoryColour for LEFT,
    RIGHT and ACCELERATE) number at least --min-arrow-px, and
  - road pixels (the asphalt of the lane bands) span at least --min-road-span of the
    screen's width without touching its left or right edge (the whole road, framed);
else 1. The colours are the markers' own: rviz draws these markers unlit.
"""
import argparse
import sys

import numpy as np
from PIL import Image, ImageGrab

# RGB of the markers (rviz_markers.cpp) and how far a drawn pixel may stray (antialiasing).
ARROWS = {"left": (255, 230, 0), "right": (255, 51, 255), "accelerate": (255, 38, 25)}
ROAD = (77, 77, 84)
TOLERANCE = 30
ROAD_TOLERANCE = 10


def near(rgb, colour, tolerance):
    """Mask of the pixels within tolerance of colour in every channel."""
    return (np.abs(rgb - np.array(colour, dtype=np.int16)) <= tolerance).all(axis=2)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--save", help="write the screenshot here (PNG)")
    ap.add_argument("--image", help="check this screenshot instead of grabbing the display")
    ap.add_argument("--min-arrow-px", type=int, default=150)
    ap.add_argument("--min-road-span", type=float, default=0.8)
    a = ap.parse_args()
    image = Image.open(a.image) if a.image else ImageGrab.grab(xdisplay=None)
    image = image.convert("RGB")
    if a.save:
        image.save(a.save)
    rgb = np.asarray(image, dtype=np.int16)
    height, width = rgb.shape[:2]
    arrows = {name: int(near(rgb, colour, TOLERANCE).sum()) for name, colour in ARROWS.items()}
    road_columns = np.flatnonzero(near(rgb, ROAD, ROAD_TOLERANCE).sum(axis=0) >= 3)
    arrow_px = sum(arrows.values())
    first, last = (int(road_columns[0]), int(road_columns[-1])) if road_columns.size else (-1, -1)
    span = (last - first + 1) / width if road_columns.size else 0.0
    margin = 5
    inside = road_columns.size > 0 and first >= margin and last < width - margin
    print("screen %dx%d: arrow px %d (%s); road spans %.0f%% of the width (columns %d..%d)%s"
          % (width, height, arrow_px, ", ".join("%s %d" % kv for kv in arrows.items()), 100 * span,
             first, last, "" if inside else ", not inside the screen"))
    ok = arrow_px >= a.min_arrow_px and span >= a.min_road_span and inside
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
