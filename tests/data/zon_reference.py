"""Reference numbers for Keyence `.zon` files (tests/formats/reference_readers.rs), from
SurfaceTopography's own reader (`ZONReader`, SurfaceTopography 1.27.1):

    python tests/data/zon_reference.py fixtures/zon/*.zon [test_1.zon] > tests/data/zon_reference.csv

One row per file: the grid (`nx` is SurfaceTopography's first axis, x), the pixel size, the
points with a value and min, max and rms (about the mean) of the heights in metres. `channel`
is contactscope's name for the one height channel (SurfaceTopography calls it `default`).
"""
import os
import sys
import warnings

import numpy as np
from SurfaceTopography import open_topography

warnings.filterwarnings("ignore")
print("file,channel,nx,ny,dx_m,dy_m,valid_points,min_m,max_m,rms_m")
for path in sys.argv[1:]:
    reader = open_topography(path)
    assert type(reader).__name__ == "ZONReader", type(reader).__name__
    t = reader.topography()
    assert t.unit == "m", t.unit
    h = np.ma.masked_invalid(t.heights())
    nx, ny = h.shape
    sx, sy = t.physical_sizes
    values = h.compressed().astype(np.float64)
    rms = np.sqrt(np.mean((values - values.mean()) ** 2))
    print(f"{os.path.basename(path)},Height,{nx},{ny},{float(sx / nx)!r},{float(sy / ny)!r},{values.size},"
          f"{float(values.min())!r},{float(values.max())!r},{float(rms)!r}")
