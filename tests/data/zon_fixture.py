"""Writes fixtures/zon/tiny.zon (members zstd-compressed, `KPK1`) and tiny-plain.zon (members
stored as they are, `KPK0`): small Keyence ZON files in the layout SurfaceTopography's ZONReader
documents (a 4-byte magic, the size of a BMP preview, the preview, 8 bytes, a ZIP archive whose
members are named by Keyence's UUIDs), for the tests of contactscope's reader:

    python tests/data/zon_fixture.py fixtures/zon      # needs numpy and zstandard

A 20 × 14 map of int32 counts (10 nm each: a tilted bowl with a step), rows padded to 88 bytes;
a validity mask with the values 1, 2 and 3 (not measured) and 4 (a bit SurfaceTopography's rule
ignores: measured); a colour image and three XML documents that are not read (device, scan time: SurfaceTopography
needs them).
"""
import io
import os
import struct
import sys
import zipfile

import numpy as np
import zstandard

NX, NY, PAD = 20, 14, 8
OUT = sys.argv[1]

y, x = np.mgrid[:NY, :NX]
counts = (300 * (x - 9.5) ** 2 - 150 * (y - 6.5) ** 2 + 4000 * (x > 12) - 7).astype("<i4")
mask = np.zeros((NY, NX), np.uint8)
mask[0, :3] = 1
mask[5, 7] = 2
mask[9, 2:4] = 3
mask[13, -2:] = 1
mask[3, 10] = 4


def array(values, value_bytes, row_bytes):
    rows = values.reshape(NY, -1).view(np.uint8).reshape(NY, -1)
    padded = np.zeros((NY, row_bytes), np.uint8)
    padded[:, : rows.shape[1]] = rows
    return struct.pack("<4I", NX, NY, value_bytes, row_bytes) + padded.tobytes()


BOM = b"\xef\xbb\xbf"
members = {
    "686613b8-27b5-4a29-8ffc-438c2780873e": BOM + b'<?xml version="1.0" encoding="utf-8"?>\r\n'
    b"<Calibration><XYCalibration><MeterPerPixel>2.5E-06</MeterPerPixel></XYCalibration>"
    b"<ZCalibration><MeterPerUnit>1E-08</MeterPerUnit></ZCalibration></Calibration>",
    "cbc1d39b-215f-4d56-a20e-cf8e5f570755": BOM + b'<?xml version="1.0" encoding="utf-8"?>\r\n'
    b"<DeviceIndivisuals><DeviceModelName>contactscope fixture</DeviceModelName>"
    b"<DeviceSerialId>#0</DeviceSerialId>"
    b"</DeviceIndivisuals>",
    "1d35862b-3b48-4df2-9235-833ef590b043": BOM + b'<?xml version="1.0" encoding="utf-8"?>\r\n'
    b'<ScanInformations Version="1.0.0.0"><ScanDateTime>11/30/2026 12:00:00 +00:00'
    b"</ScanDateTime></ScanInformations>",
    "4cdb0c75-5706-48cc-a9a1-adf395d609ae": array(counts, 4, NX * 4 + PAD),
    "9e7ca6dd-0e6a-4d7b-8986-f0a7b773c916": array(mask, 1, NX),
    "ee329ad1-e7ac-4db2-94cb-4bacba072d7b": array(
        np.full((NY, NX, 3), 128, np.uint8), 3, NX * 3),
}
# A 2 × 2 24-bit BMP as the preview.
pixels = b"\x00\x00\xff\x00\xff\x00\x00\x00" * 2
bmp = b"BM" + struct.pack("<IHHI", 54 + len(pixels), 0, 0, 54) + struct.pack(
    "<IiiHHIIiiII", 40, 2, 2, 1, 24, 0, len(pixels), 2835, 2835, 0, 0) + pixels
for name, magic, pack in [("tiny.zon", b"KPK1", zstandard.ZstdCompressor().compress),
                          ("tiny-plain.zon", b"KPK0", lambda b: b)]:
    archive = io.BytesIO()
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_STORED) as z:
        for key, data in members.items():
            z.writestr(key, pack(data))
    with open(os.path.join(OUT, name), "wb") as f:
        f.write(magic + struct.pack("<I", len(bmp)) + bmp + struct.pack("<II", 4, 2)
                + archive.getvalue())
