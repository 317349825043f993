"""Regenerates surface_topography_maps.csv: every channel of every file of a folder as
SurfaceTopography reads it (grid, pixel size, channel names, valid points, height statistics in
metres). Not run by the tests; run by hand on SurfaceTopography's `test/file_format_examples`:

    python3 -m venv /tmp/st && /tmp/st/bin/pip install SurfaceTopography==1.27.1 netCDF4 h5py
    /tmp/st/bin/python tests/data/surface_topography_reference.py FOLDER \
        > tests/data/surface_topography_maps.csv

Conventions: SurfaceTopography keeps arrays as (x, y); contactscope as (y, x) rows, so `nx` here
is SurfaceTopography's first axis. Heights are converted to metres with the topography's `unit`;
masked points are invalid. rms is about the mean of the valid points. A file SurfaceTopography
does not read, or reads only when told a physical size, is listed with `status` saying so.
"""
import math
import os
import sys
import warnings

import numpy as np

METRES = {
    "m": 1.0, "mm": 1e-3, "µm": 1e-6, "μm": 1e-6, "um": 1e-6, "nm": 1e-9, "pm": 1e-12,
    "Å": 1e-10, "A": 1e-10, "km": 1e3,
}

COLUMNS = ("file,status,reader,channel_index,channel,channels,dim,nx,ny,dx_m,dy_m,valid,"
           "min_m,max_m,mean_m,rms_m")


def row(**kw):
    print(",".join(str(kw.get(c, "")) for c in COLUMNS.split(",")))


def describe(folder, name):
    from SurfaceTopography import open_topography
    path = os.path.join(folder, name)
    try:
        reader = open_topography(path)
    except Exception as e:  # noqa: BLE001 - the reference records what the reader says
        row(file=name, status="unreadable:" + type(e).__name__)
        return
    names = ";".join(c.name.replace(",", " ").replace(";", " ") for c in reader.channels)
    for i, ch in enumerate(reader.channels):
        base = dict(file=name, reader=type(reader).__name__, channel_index=i,
                    channel=ch.name.replace(",", " ").replace(";", " "), channels=names,
                    dim=ch.dim)
        try:
            t = reader.topography(channel_index=i)
        except Exception as e:  # noqa: BLE001
            kind = "needs-size" if ch.physical_sizes is None else "unreadable"
            row(status=f"{kind}:{type(e).__name__}", **base)
            continue
        # A file without a unit (xyz and column text) is reported as stored ("unitless").
        status = "ok" if t.unit is not None else "ok-unitless"
        unit = METRES.get(t.unit) if t.unit is not None else 1.0
        if unit is None:
            row(status=f"unit:{str(t.unit).replace(',', ' ')}", **base)
            continue
        h = np.ma.masked_invalid(t.heights()) if not t.has_undefined_data else \
            np.ma.masked_array(t.heights(), mask=np.ma.getmaskarray(t.heights()))
        valid = h.compressed().astype(float) * unit
        mean = float(valid.mean())
        rms = math.sqrt(((valid - mean) ** 2).mean())
        if t.dim == 2:
            nx, ny = t.nb_grid_pts
            dx, dy = (float(s) * unit / n for s, n in zip(t.physical_sizes, t.nb_grid_pts))
            dy = repr(dy)
        else:
            nx, ny = t.nb_grid_pts[0], 1
            dx, dy = float(t.physical_sizes[0]) * unit / nx, ""
        row(status=status, nx=nx, ny=ny, dx_m=repr(dx), dy_m=dy, valid=valid.size,
            min_m=repr(float(valid.min())), max_m=repr(float(valid.max())), mean_m=repr(mean),
            rms_m=repr(rms), **base)


def main():
    folder = sys.argv[1]
    warnings.simplefilter("ignore")
    print(COLUMNS)
    for name in sorted(os.listdir(folder)):
        describe(folder, name)


if __name__ == "__main__":
    main()
