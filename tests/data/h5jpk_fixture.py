"""A tiny file in the layout of JPK's HDF5 export (`.h5-jpk`), written with h5py
(fixtures/jpk/tiny.h5-jpk):

    python tests/data/h5jpk_fixture.py fixtures/jpk/tiny.h5-jpk

The layout of AFMReader's `sample_0.h5-jpk` (JPK SPM 8.1): root attribute `file-format-info` =
`JPK SCAN`; `Measurement_000` with the scan grid (5 points over 20 nm along the fast axis, 4 lines
over 12 nm); channels `height` trace and retrace (int32 counts shaped (points, frames), 2
frames, `net-encoder.scaling` −2e-15 m per count + 3e-7 m) and `phase` (degrees). Raw counts:
1000·line + 10·column + 100000·frame, + 7 on the retrace; lines stored bottom first.
"""
import sys

import h5py
import numpy as np

NX, NY, FRAMES = 5, 4, 2
line, column = np.divmod(np.arange(NX * NY), NX)

with h5py.File(sys.argv[1], "w") as f:
    f.attrs["file-format-info"] = np.bytes_(b"JPK SCAN")
    f.attrs["file-format-version"] = np.bytes_(b"3.0")
    m = f.create_group("Measurement_000")
    m.attrs["position-pattern.grid.ilength"] = np.int32(NX)
    m.attrs["position-pattern.grid.jlength"] = np.int32(NY)
    m.attrs["position-pattern.grid.ulength"] = np.float64(20e-9)
    m.attrs["position-pattern.grid.vlength"] = np.float64(12e-9)
    m.attrs["position-pattern.grid.unit.unit"] = np.bytes_(b"m")
    for k, (name, retrace, unit, dataset) in enumerate([
            (b"height", b"false", b"m", "Height"),
            (b"height", b"true", b"m", "Height"),
            (b"phase", b"false", b"deg", "Phase")]):
        c = m.create_group(f"Channel_{k:03d}")
        c.attrs["channel.name"] = np.bytes_(name)
        c.attrs["retrace"] = np.bytes_(retrace)
        c.attrs["net-encoder.scaling.multiplier"] = np.float64(-2e-15)
        c.attrs["net-encoder.scaling.offset"] = np.float64(3e-7)
        c.attrs["net-encoder.scaling.unit.unit"] = np.bytes_(unit)
        raw = np.stack([1000 * line + 10 * column + 100000 * frame + (7 if retrace == b"true" else 0)
                        for frame in range(FRAMES)], axis=1).astype(np.int32)
        c.create_dataset(dataset, data=raw)
        c.create_dataset("thumbnail", data=np.zeros((4, 1), np.int32))
