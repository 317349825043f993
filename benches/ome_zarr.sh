#!/usr/bin/env bash
# OME-Zarr against TIFF (issue 45; results in docs/performance.md): one load series of
# 40 × 1024² uint16 (84 MB of samples: a disc growing over the loads, Poisson noise, 12-bit) as
#
#   * an uncompressed TIFF and a zstd TIFF (tifffile; zstd needs imagecodecs),
#   * OME-Zarr 0.5 (Zarr v3) uncompressed, zstd level 3, blosc lz4 + bitshuffle, and
#     OME-Zarr 0.4 (Zarr v2) uncompressed, one chunk per plane (zarr-python),
#
# each timed REPEAT times (page cache warm) for `threshold` (one pass: read and histogram every
# plane; the reader's throughput) and `analyze` (both passes, intervals, fits, plots). Medians
# are printed as a markdown table, with the ratio to the uncompressed TIFF.
#
#   cargo build --release && PYTHON=/path/to/venv/bin/python benches/ome_zarr.sh
#   (the venv needs numpy, zarr>=3, tifffile, imagecodecs)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${CONTACTSCOPE_BIN:-$ROOT/target/release/contactscope}
DIR=${BENCH_DIR:-/tmp/cs-zarr-bench}
PYTHON=${PYTHON:-python3}
REPEAT=${REPEAT:-5}
[ -x "$BIN" ] || { echo "build first: cargo build --release" >&2; exit 1; }
mkdir -p "$DIR"
cd "$DIR"
if [ ! -f done ]; then
  "$PYTHON" - <<'PY'
import shutil
import numpy as np, tifffile, zarr
from zarr.codecs import BloscCodec, ZstdCodec
rng = np.random.default_rng(3)
T, Y, X = 40, 1024, 1024
yy, xx = np.mgrid[:Y, :X]
data = np.empty((T, Y, X), np.uint16)
for t in range(T):
    r = 50 + 10 * t
    data[t] = np.minimum(rng.poisson(100 + 1500 * (((yy - 512) ** 2 + (xx - 512) ** 2) < r * r)), 4095)
tifffile.imwrite("raw.tif", data, resolution=(5, 5), imagej=True, metadata={"unit": "um", "axes": "TYX"})
tifffile.imwrite("zstd.tif", data, compression="zstd", resolution=(5, 5), imagej=False,
                 resolutionunit="MICROMETER")
axes = [{"name": "t", "type": "time"}, {"name": "y", "type": "space", "unit": "micrometer"},
        {"name": "x", "type": "space", "unit": "micrometer"}]
def store(name, compressors, fmt=3):
    shutil.rmtree(name, ignore_errors=True)
    g = zarr.open_group(name, mode="w", zarr_format=fmt)
    ms = [{"axes": axes, "datasets": [{"path": "0", "coordinateTransformations": [
        {"type": "scale", "scale": [1, 0.2, 0.2]}]}]}]
    if fmt == 3:
        g.attrs["ome"] = {"version": "0.5", "multiscales": ms}
    else:
        ms[0]["version"] = "0.4"
        g.attrs["multiscales"] = ms
    g.create_array("0", shape=data.shape, chunks=(1, Y, X), dtype="uint16",
                   compressors=compressors)[:] = data
store("raw.ome.zarr", None)
store("raw_v2.ome.zarr", None, fmt=2)
store("zstd.ome.zarr", ZstdCodec(level=3))
store("blosc.ome.zarr", BloscCodec(cname="lz4", clevel=5, shuffle="bitshuffle"))
PY
  touch done
fi
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
time_of() { local s e; s=$(date +%s.%N); "$@" >/dev/null 2>&1; e=$(date +%s.%N); echo "$e - $s" | bc -l; }
echo "| input | threshold s | read GB/s | analyze s | analyze ÷ TIFF |"
echo "|---|---|---|---|---|"
base=""
for f in raw.tif zstd.tif raw.ome.zarr raw_v2.ome.zarr blosc.ome.zarr zstd.ome.zarr; do
  axis=(); case $f in *.zarr) axis=(--load-axis t);; esac
  th=$(for i in $(seq "$REPEAT"); do time_of "$BIN" threshold "$f" "${axis[@]}"; done | median)
  an=$(for i in $(seq "$REPEAT"); do rm -rf out; time_of "$BIN" analyze "$f" "${axis[@]}" \
       --forces 4mN..400mN:40 --out out --quiet; done | median)
  [ -z "$base" ] && base=$an
  printf "| %s | %.3f | %.2f | %.3f | %.2f |\n" "$f" "$th" "$(echo "83.886 / $th / 1000" | bc -l)" \
    "$an" "$(echo "$an / $base" | bc -l)"
done
