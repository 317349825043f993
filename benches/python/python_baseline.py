#!/usr/bin/env python3
"""tifffile + scikit-image baseline for the contactscope series benchmark.

Does the same work as `contactscope analyze` (without plots and summary.json) on the same files:

1. load every page (tifffile.imread of each file, or of all pages of a multi-page file) into one
   (n, h, w) uint16 array;
2. one global Otsu threshold over all images together: skimage.filters.threshold_otsu on the
   whole concatenated (n, h, w) array (skimage bins integer images one bin per level and uses
   float32 counts);
3. per image: contact pixels (value > t), mean intensity over contact, integrated intensity,
   background mean, 8-connected patches with skimage.measure.label(mask, connectivity=2)
   (count, and largest size via np.bincount);
4. write a CSV (areas in um^2 from the file's X/YResolution, as contactscope does).

Timing: time.perf_counter around steps 1-4, one warm-up run, then the best (and median) of
--runs runs, page cache warm. Imports and interpreter start-up are not timed.

Usage:
    python_baseline.py [--runs 5] [--out DIR] [--forces 4,...,400mN] NAME=PATH [NAME=PATH ...]
        PATH is a folder (every .tif/.tiff in natural order) or one multi-page TIFF.
    python_baseline.py --to-lzw SRC DST
        re-save the TIFF(s) of SRC (file or folder) with compression='lzw' into DST, keeping
        ImageDescription and X/YResolution, so contactscope reads the same calibration.

Prints one JSON object: per layout the timings (s), the phase split of the best run, the
threshold, total contact pixels and per-image contact pixels; plus versions and peak RSS.
"""

import argparse
import csv
import json
import os
import platform
import re
import resource
import statistics
import sys
import time

import numpy as np
import skimage
import tifffile
from skimage.filters import threshold_otsu
from skimage.measure import label


def natural_key(name):
    return [int(p) if p.isdigit() else p for p in re.split(r"(\d+)", name)]


def tiff_files(path):
    if os.path.isdir(path):
        names = [n for n in os.listdir(path) if n.lower().endswith((".tif", ".tiff"))]
        return [os.path.join(path, n) for n in sorted(names, key=natural_key)]
    return [path]


def pixel_area_um2(path):
    """Pixel area from XResolution/YResolution in pixels per micron (ImageJ, unit=micron)."""
    with tifffile.TiffFile(path) as tif:
        tags = tif.pages[0].tags
        xr = tags["XResolution"].value
        yr = tags["YResolution"].value
    return (xr[1] / xr[0]) * (yr[1] / yr[0])


def parse_forces(text, n):
    if not text:
        return [float("nan")] * n
    m = re.fullmatch(r"(.*?)(mN|N)", text.strip())
    factor = 1.0 if m.group(2) == "mN" else 1e3
    values = [float(v) * factor for v in m.group(1).split(",")]
    if len(values) != n:
        sys.exit(f"{len(values)} forces for {n} images")
    return values


def analyse(files, forces_mn, csv_path):
    """The whole job; returns (phase times, threshold, per-image contact pixels)."""
    t0 = time.perf_counter()
    if len(files) == 1:
        stack = tifffile.imread(files[0])  # all pages of the multi-page file
        if stack.ndim == 2:
            stack = stack[np.newaxis]
    else:
        stack = np.stack([tifffile.imread(f) for f in files])
    area = pixel_area_um2(files[0])
    t1 = time.perf_counter()
    t = threshold_otsu(stack)  # one global Otsu over the concatenated array
    t2 = time.perf_counter()
    rows = []
    for i, img in enumerate(stack):
        mask = img > t
        n_contact = int(np.count_nonzero(mask))
        total = int(img.sum(dtype=np.int64))
        integrated = int(img[mask].sum(dtype=np.int64))
        n_bg = img.size - n_contact
        mean = integrated / n_contact if n_contact else float("nan")
        background = (total - integrated) / n_bg if n_bg else float("nan")
        labels = label(mask, connectivity=2)
        sizes = np.bincount(labels.ravel())
        patches = len(sizes) - 1
        largest = int(sizes[1:].max()) if patches else 0
        a = n_contact * area
        force = forces_mn[i]
        rows.append(
            [
                files[0] if len(files) == 1 else files[i],
                i if len(files) == 1 else 0,
                force,
                t,
                n_contact,
                a,
                mean,
                integrated,
                background,
                patches,
                largest * area,
                force / a * 1e3 if a > 0 else float("nan"),
                (a / np.pi) ** 0.5,
            ]
        )
    t3 = time.perf_counter()
    with open(csv_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(
            [
                "image", "page", "force_mN", "threshold", "contact_pixels", "area_um2",
                "mean_intensity", "integrated_intensity", "background_mean", "patches",
                "largest_patch_um2", "mean_pressure_MPa", "equivalent_radius_um",
            ]
        )
        w.writerows(rows)
    t4 = time.perf_counter()
    phases = {"load": t1 - t0, "otsu": t2 - t1, "measure": t3 - t2, "csv": t4 - t3}
    return phases, t, [r[4] for r in rows]


def to_lzw(src, dst):
    os.makedirs(dst, exist_ok=True)
    for path in tiff_files(src):
        with tifffile.TiffFile(path) as tif:
            page = tif.pages[0]
            description = page.tags["ImageDescription"].value
            xr = page.tags["XResolution"].value
            yr = page.tags["YResolution"].value
            data = tif.asarray()  # all pages
        tifffile.imwrite(
            os.path.join(dst, os.path.basename(path)),
            data,
            photometric="minisblack",
            compression="lzw",
            description=description,
            metadata=None,
            resolution=(xr, yr),
            resolutionunit=1,  # NONE: ImageJ-style pixels per micron
        )


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("layouts", nargs="*", help="NAME=PATH")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--out", default="/tmp/cs-bench/python-out")
    ap.add_argument("--forces", default="")
    ap.add_argument("--to-lzw", nargs=2, metavar=("SRC", "DST"))
    args = ap.parse_args()
    if args.to_lzw:
        to_lzw(*args.to_lzw)
        return
    os.makedirs(args.out, exist_ok=True)
    report = {
        "python": platform.python_version(),
        "numpy": np.__version__,
        "tifffile": tifffile.__version__,
        "scikit-image": skimage.__version__,
        "runs": args.runs,
        "layouts": {},
    }
    for spec in args.layouts:
        name, path = spec.split("=", 1)
        files = tiff_files(path)
        n = len(files) if len(files) > 1 else len(tifffile.TiffFile(files[0]).pages)
        forces = parse_forces(args.forces, n)
        csv_path = os.path.join(args.out, f"{name}.csv")
        analyse(files, forces, csv_path)  # warm-up (page cache, imports, caches)
        totals, best = [], None
        for _ in range(args.runs):
            t0 = time.perf_counter()
            phases, t, contact = analyse(files, forces, csv_path)
            total = time.perf_counter() - t0
            totals.append(total)
            if best is None or total < best[0]:
                best = (total, phases)
        report["layouts"][name] = {
            "path": path,
            "images": n,
            "best_s": min(totals),
            "median_s": statistics.median(totals),
            "mean_s": statistics.mean(totals),
            "sd_s": statistics.stdev(totals) if len(totals) > 1 else 0.0,
            "runs_s": totals,
            "best_phases_s": best[1],
            "threshold": float(t),
            "contact_pixels_total": int(sum(contact)),
            "contact_pixels": [int(c) for c in contact],
            "csv": csv_path,
        }
    report["peak_rss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
