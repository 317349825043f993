"""Writes fixtures/jpk/tiny.jpk: a TIFF laid out as JPK's image files are (JPKImageSpec: an
8-bit thumbnail page with the scan grid in JPK's tags, then int32 channel pages with their
calibration slots), small enough to commit; the Rust test recomputes its heights.

    python tests/data/jpk_fixture.py fixtures/jpk/tiny.jpk   # tifffile 2026.3.3

Pages: a `height` retrace (default slot `calibrated`: raw·(−2e−15) + 3e−6 m), a `height` trace
(same slots), and a `vDeflection` trace in newtons (refused as heights). Grid: 5 × 4 points
over 2e−8 × 1.6e−8 m (4 nm pixels).
"""
import sys

import numpy as np
import tifffile

ny, nx = 4, 5
i, j = np.mgrid[0:ny, 0:nx]
raw = (1000 * i + 10 * j).astype(np.int32)


def slot(k, name, unit, scaling, multiplier=None, offset=None):
    base = 32912 + 48 * k
    tags = [(base, "s", 0, name, True)]
    if unit is not None:
        tags.append((base + 18, "s", 0, unit, True))
    tags.append((base + 19, "s", 0, scaling, True))
    if multiplier is not None:
        tags += [(base + 20, "d", 1, multiplier, True), (base + 21, "d", 1, offset, True)]
    return tags


def channel(name, retrace, slots, default):
    return [(32848, "s", 0, name, True), (32849, "h", 1, retrace, True),
            (32896, "i", 1, len(slots), True), (32897, "s", 0, default, True)] + [
        t for k, s in enumerate(slots) for t in slot(k, *s)]


height_slots = [("raw", None, "NullScaling"), ("nominal", "m", "LinearScaling", -2e-15, 3e-6),
                ("calibrated", "m", "LinearScaling", -1.5e-15, 2.5e-6)]
force_slots = [("raw", None, "NullScaling"), ("force", "N", "LinearScaling", 1e-12, 0.0)]
first = [(32768, "s", 0, "6.0.41", True), (32834, "d", 1, 2e-8, True),
         (32835, "d", 1, 1.6e-8, True), (32838, "i", 1, nx, True), (32839, "i", 1, ny, True),
         (32848, "s", 0, "thumbnail", True)]
with tifffile.TiffWriter(sys.argv[1]) as tif:
    tif.write(np.zeros((ny, nx), np.uint8), extratags=first)
    tif.write(raw, extratags=channel("height", 1, height_slots, "calibrated"))
    tif.write(raw + 5, extratags=channel("height", 0, height_slots, "calibrated"))
    tif.write(raw, extratags=channel("vDeflection", 0, force_slots, "force"))
