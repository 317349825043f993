"""Small surfalize `.sflz` files of the earlier layout (surfalize 0.17.1, which writes no unit and
keeps the height range in the file header), written by surfalize itself (fixtures/sflz/):

    python tests/data/sflz_earlier_fixture.py fixtures/sflz

The heights of sflz_fixture.py (µm) without unmeasured points: `earlier_zlib_u4.sflz` (zlib,
quantised to uint32, a uint8 `Camera` layer) and `earlier_lzma_f8.sflz` (LZMA, float64). The
reference numbers are surfalize 0.17.1's own reading (sflz_reference.py run with it).
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
camera = (127 + 100 * np.sin((x + y) / 6.0)).astype(np.uint8)

Surface(heights_um, 0.625, 0.5, image_layers={"Camera": Image(camera)}).save(
    out / "earlier_zlib_u4.sflz", compression="zlib", dtype="<u4")
Surface(heights_um, 0.625, 0.5).save(out / "earlier_lzma_f8.sflz", compression="lzma",
                                     dtype="<f8")
