"""Reference numbers for Createc `.dat` images (tests/formats/reference_readers.rs), from
ProbeFlow's own decoder (`probeflow.io.readers.createc_dat.read_createc_dat_report`, the reader
SPMQT-Lab's Createc samples come with; SPMQT-Lab/Createc-to-Nanonis-file-conversion at 3e96103,
MIT), run from a checkout of it:

    PYTHONPATH=CHECKOUT python tests/data/createc_reference.py DIR/*.dat > tests/data/createc_reference.csv

One row per Z plane (forward and backward): the grid ProbeFlow decodes (first column dropped,
lines not scanned trimmed), the points with a value and min, max and rms (about the mean) in
metres. Two numbers are not ProbeFlow's, and the columns say how they are made:

* heights: ProbeFlow's decoded DAC counts (`raw_channels_dac`) times its `z_m_per_dac`, in
  double precision (ProbeFlow multiplies the float32 counts in float32);
* pixel size: `Length x[A]` / `Num.X` (and y), the header's step (`Delta X [Dac]` ×
  `Dacto[A]xy`); ProbeFlow's scan keeps the whole `Length` as the range of the columns and lines
  it keeps.
"""
import os
import sys

import numpy as np
from probeflow.io.readers.createc_dat import read_createc_dat_report

print("file,channel,nx,ny,dx_m,dy_m,valid_points,min_m,max_m,rms_m")
for path in sorted(sys.argv[1:]):
    report = read_createc_dat_report(path)
    header = report.original_header
    dx = float(header["Length x[A]"]) * 1e-10 / report.original_Nx
    dy = float(header["Length y[A]"]) * 1e-10 / report.original_Ny
    for info in report.channel_info:
        if info.semantic != "z":
            continue
        counts = np.asarray(report.raw_channels_dac[info.native_index], dtype=np.float64)
        values = counts * report.scale_factors["z_m_per_dac"]
        ny, nx = values.shape
        values = values[np.isfinite(values)]
        rms = np.sqrt(np.mean((values - values.mean()) ** 2))
        name = info.name.replace(" forward", " (forward)").replace(" backward", " (backward)")
        print(f"{os.path.basename(path)},{name},{nx},{ny},{dx!r},{dy!r},{values.size},"
              f"{float(values.min())!r},{float(values.max())!r},{float(rms)!r}")
