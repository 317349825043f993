"""Reference numbers for JPK TIFFs (tests/formats/reference_readers.rs), from AFMReader's own
reader (`AFMReader.jpk.load_jpk`, AFMReader 0.0.7, which applies the default calibration slot
and gives heights and amplitudes in nm):

    python tests/data/jpk_reference.py DIR > tests/data/jpk_reference.csv

AFMReader names a channel `<name>_<trace|retrace>` and keeps the last page of a name, so the
second `measuredHeight` page of a QI map is the one it reads (ours: `measuredHeight (trace, 2)`).
"""
import os
import sys

import numpy as np
from AFMReader.jpk import load_jpk

FILES = {
    "sample_0.jpk": [
        ("height_trace", "height (trace)"),
        ("height_retrace", "height (retrace)"),
        ("measuredHeight_trace", "measuredHeight (trace)"),
        ("amplitude_retrace", "amplitude (retrace)"),
    ],
    "sample_0.jpk-qi-image": [
        ("height_trace", "height (trace)"),
        ("measuredHeight_trace", "measuredHeight (trace, 2)"),
    ],
}

print("file,channel,nx,ny,dx_m,valid_points,min_m,max_m,rms_m")
for name, channels in FILES.items():
    for theirs, ours in channels:
        image, nm_per_pixel = load_jpk(os.path.join(sys.argv[1], name), channel=theirs)
        values = np.asarray(image, dtype=np.float64) * 1e-9
        ny, nx = values.shape
        values = values[np.isfinite(values)]
        rms = np.sqrt(np.mean((values - values.mean()) ** 2))
        print(f"{name},\"{ours}\",{nx},{ny},{float(nm_per_pixel) * 1e-9!r},{values.size},"
              f"{float(values.min())!r},{float(values.max())!r},{float(rms)!r}")
