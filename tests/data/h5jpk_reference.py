"""Reference numbers for JPK HDF5 exports (tests/formats/reference_readers.rs), from AFMReader's
own reader (`AFMReader.h5_jpk.load_h5jpk`, AFMReader 0.0.7):

    python tests/data/h5jpk_reference.py DIR/*.h5-jpk > tests/data/h5jpk_reference.csv

One row per height channel and frame (`height_trace`, `height_retrace`; AFMReader reads only
square grids, from `ilength`): the grid, the pixel size (`ulength/ilength`), the points with a
value, and min, max and rms (about the mean) in metres (AFMReader gives nm).
"""
import os
import sys

import numpy as np
from AFMReader.h5_jpk import load_h5jpk

print("file,channel,nx,ny,dx_m,valid_points,min_m,max_m,rms_m")
for path in sorted(sys.argv[1:]):
    for channel, direction in (("height_trace", "trace"), ("height_retrace", "retrace")):
        frames, nm_per_pixel, _ = load_h5jpk(path, channel=channel)
        for k, frame in enumerate(frames):
            values = np.asarray(frame, dtype=np.float64) * 1e-9
            ny, nx = values.shape
            values = values[np.isfinite(values)]
            rms = np.sqrt(np.mean((values - values.mean()) ** 2))
            name = f"height ({direction}, frame {k + 1})" if len(frames) > 1 else \
                f"height ({direction})"
            print(f"{os.path.basename(path)},\"{name}\",{nx},{ny},{float(nm_per_pixel) * 1e-9!r},"
                  f"{values.size},{float(values.min())!r},{float(values.max())!r},{float(rms)!r}")
