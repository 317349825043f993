"""Small surfalize `.sflz` files of our own, written by surfalize itself (fixtures/sflz/):

    python tests/data/sflz_fixture.py fixtures/sflz

Heights from a formula (a tilted, rippled 48 x 36 map with a few unmeasured points), saved with
each of the layout's compressions, unit and quantisation choices surfalize offers:

* `zlib_u4.sflz`: zlib, heights quantised to uint32 with the invalid-point sentinel, in um;
* `lzma_f8.sflz`: LZMA (an .xz stream), float64 heights in nm, and a uint8 camera image layer;
* `none_i2.sflz`: no compression, heights quantised to int16, in mm, every point measured.

The reference numbers are surfalize's own reading of these files (sflz_reference.py).
"""
import pathlib
import sys

import numpy as np
from surfalize import Surface
from surfalize.image import Image

out = pathlib.Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)

ny, nx = 36, 48
y, x = np.mgrid[0:ny, 0:nx].astype(np.float64)
heights_um = 0.8 + 0.01 * x - 0.02 * y + 0.35 * np.sin(x / 4.0) * np.cos(y / 5.0)
with_gaps = heights_um.copy()
with_gaps[3, 5] = np.nan
with_gaps[20, 40:44] = np.nan

step_um = (0.625, 0.5)
camera = (127 + 100 * np.sin((x + y) / 6.0)).astype(np.uint8)

Surface(with_gaps, *step_um).save(out / "zlib_u4.sflz", compression="zlib", dtype="<u4",
                                  unit="um")
Surface(with_gaps, *step_um, image_layers={"Camera": Image(camera)}).save(
    out / "lzma_f8.sflz", compression="lzma", dtype="<f8", unit="nm")
Surface(heights_um, *step_um).save(out / "none_i2.sflz", compression="none", dtype="<i2",
                                   unit="mm")
