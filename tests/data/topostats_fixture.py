"""Writes fixtures/topostats/tiny.topostats: a TopoStats-layout HDF5 file (the keys TopoStats
writes and AFMReader's load_topostats reads) small enough to commit, with heights that the Rust
test recomputes from the same formula.

    python tests/data/topostats_fixture.py fixtures/topostats/tiny.topostats   # h5py 3.16
"""
import sys

import h5py
import numpy as np

ny, nx = 6, 8
i, j = np.mgrid[0:ny, 0:nx]
image = 0.5 * i - 0.25 * j + 0.125 * i * j  # nm, levelled
with h5py.File(sys.argv[1], "w") as f:
    f["image"] = image
    f["image_original"] = image + 3.0 + 0.5 * j  # nm, before levelling
    f["pixel_to_nm_scaling"] = 2.5
    f["topostats_file_version"] = 0.2
    f["grain_masks/above"] = (image > 1).astype(np.int64)
