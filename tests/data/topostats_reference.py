"""Reference numbers for TopoStats files (tests/formats/reference_readers.rs), from AFMReader's own
reader (`AFMReader.topostats.load_topostats`, AFMReader 0.0.7):

    python tests/data/topostats_reference.py DIR/*.topostats > tests/data/topostats_reference.csv

One row per image (`image`, and `image_original` where the file has it): the grid, the pixel
size (`pixel_to_nm_scaling`), the points with a value, and min, max and rms (about the mean) in
metres (TopoStats stores nm).
"""
import os
import sys

import numpy as np
from AFMReader.topostats import load_topostats

print("file,channel,nx,ny,dx_m,valid_points,min_m,max_m,rms_m")
for path in sorted(sys.argv[1:]):
    data = load_topostats(path)
    dx = float(data["pixel_to_nm_scaling"]) * 1e-9
    for channel in ("image", "image_original"):
        if channel not in data:
            continue
        values = np.asarray(data[channel], dtype=np.float64) * 1e-9
        ny, nx = values.shape
        values = values[np.isfinite(values)]
        rms = np.sqrt(np.mean((values - values.mean()) ** 2))
        print(f"{os.path.basename(path)},{channel},{nx},{ny},{dx!r},{values.size},"
              f"{float(values.min())!r},{float(values.max())!r},{float(rms)!r}")
