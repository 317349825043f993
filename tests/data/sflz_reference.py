"""Reference numbers for surfalize `.sflz` files (tests/formats/reference_readers.rs), from
surfalize's own reader (`surfalize.Surface.load`, surfalize 0.19.2):

    python tests/data/sflz_reference.py fixtures/sflz/*.sflz > tests/data/sflz_reference.csv

One row per file: the height layer's grid, the pixel size, the points with a value and min, max
and rms (about the mean) in metres (surfalize gives micrometres).
"""
import os
import sys

import numpy as np
from surfalize import Surface

print("file,channel,nx,ny,dx_m,dy_m,valid_points,min_m,max_m,rms_m")
for path in sorted(sys.argv[1:]):
    surface = Surface.load(path)
    values = np.asarray(surface.data, dtype=np.float64) * 1e-6
    ny, nx = values.shape
    values = values[np.isfinite(values)]
    rms = np.sqrt(np.mean((values - values.mean()) ** 2))
    print(f"{os.path.basename(path)},topography,{nx},{ny},{surface.step_x * 1e-6!r},"
          f"{surface.step_y * 1e-6!r},{values.size},{float(values.min())!r},"
          f"{float(values.max())!r},{float(rms)!r}")
