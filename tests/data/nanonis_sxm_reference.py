"""Reference numbers for the Nanonis .sxm samples (tests/formats/reference_readers.rs), from nanonispy's own
reader (`nanonispy.read.Scan`, nanonispy 1.1.0 with numpy 1.23, which that release needs).

    python tests/data/nanonis_sxm_reference.py DIR/*.sxm > tests/data/nanonis_sxm_reference.csv

One row per channel in a length unit and direction: the grid, the pixel size (SCAN_RANGE over
SCAN_PIXELS), the points with a value, and min, max and rms (about the mean) of those values in
metres. nanonispy keeps the stored line order and direction; the statistics do not depend on it.
"""
import os
import sys

import nanonispy as nap
import numpy as np

print("file,channel,nx,ny,dx_m,dy_m,valid_points,min_m,max_m,rms_m")
for path in sorted(sys.argv[1:]):
    scan = nap.read.Scan(path)
    nx, ny = (int(n) for n in scan.header["scan_pixels"])
    range_x, range_y = scan.header["scan_range"]
    info = scan.header["data_info"]
    for name, unit in zip(info["Name"], info["Unit"]):
        if unit != "m":
            continue
        for direction in ("forward", "backward"):
            values = np.asarray(scan.signals[name][direction], dtype=np.float64)
            values = values[np.isfinite(values)]
            rms = np.sqrt(np.mean((values - values.mean()) ** 2))
            print(
                f"{os.path.basename(path)},{name} ({direction}),{nx},{ny},"
                f"{range_x / nx!r},{range_y / ny!r},{values.size},"
                f"{values.min()!r},{values.max()!r},{rms!r}"
            )
