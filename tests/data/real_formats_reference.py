"""Regenerates real_formats_planes.csv: per-plane min/max/sum of the confocal sample files in
../shared/data/real-formats as trusted Python readers decode them. Not run by the tests.

    python3 -m venv /tmp/v && /tmp/v/bin/pip install numpy pylibCZIrw nd2 liffile
    /tmp/v/bin/python tests/data/real_formats_reference.py > tests/data/real_formats_planes.csv

Readers used (versions of the run that wrote the CSV): pylibCZIrw 6.1.0 (CZI; Bgr24 planes
come back as (y, x, 3) in B, G, R order = our S = 0, 1, 2), nd2 0.12.0 (ND2), liffile 2026.2.16
(LIF; its λ and Λ axes are our lambda_emission and lambda_excitation). Keys list t, z, c and
then the extra axes in name order, as contactscope's PlaneIndex::all does.
"""
import os
import sys

import numpy as np

ROOT = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "data", "real-formats")


def row(file, series, key, plane):
    p = plane.astype(np.int64)
    print(f"{file},{series},{key},{p.min()},{p.max()},{p.sum()}")


def czi():
    from pylibCZIrw import czi as pyczi
    for f in sorted(os.listdir(os.path.join(ROOT, "czi"))):
        with pyczi.open_czi(os.path.join(ROOT, "czi", f)) as doc:
            bb = doc.total_bounding_box
            rng = lambda k: range(*bb.get(k, (0, 1)))
            for t in rng("T"):
                for z in rng("Z"):
                    for c in rng("C"):
                        for h in rng("H"):
                            plane = {"T": t, "Z": z, "C": c}
                            if "H" in bb and bb["H"] != (0, 1):
                                plane["H"] = h
                            a = doc.read(plane=plane)
                            extra = f";H={h}" if "H" in plane else ""
                            if a.shape[2] == 1:
                                row("czi/" + f, 0, f"t={t};z={z};c={c}{extra}", a[..., 0])
                            else:
                                for s in range(a.shape[2]):
                                    row("czi/" + f, 0, f"t={t};z={z};c={c}{extra};S={s}", a[..., s])


def nd2file():
    import nd2
    with nd2.ND2File(os.path.join(ROOT, "nd2", "cluster.nd2")) as f:
        a = f.asarray()
        for t, z, c in np.ndindex(*a.shape[:3]):
            row("nd2/cluster.nd2", 0, f"t={t};z={z};c={c}", a[t, z, c])


def lif():
    import liffile
    names = {"T": "t", "Z": "z", "C": "c", "λ": "lambda_emission", "Λ": "lambda_excitation"}
    path = os.path.join(ROOT, "lif", "LeicaLASX_wavelength-sweep_example.lif")
    with liffile.LifFile(path) as f:
        for s, im in enumerate(f.images):
            a = im.asarray()
            dims = im.dims[:-2]
            for idx in np.ndindex(*a.shape[:-2]):
                d = {names[k]: v for k, v in zip(dims, idx)}
                base = [f"{k}={d.get(k, 0)}" for k in ("t", "z", "c")]
                extra = [f"{k}={d[k]}" for k in sorted(d) if k not in ("t", "z", "c")]
                row("lif/" + os.path.basename(path), s, ";".join(base + extra), a[idx])


print("file,series,plane,min,max,sum")
czi()
nd2file()
lif()
