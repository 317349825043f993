#!/usr/bin/env bash
# Inputs on a distant server (issue 45; results in docs/performance.md): the 40 × 1024² uint16
# load series of benches/ome_zarr.sh as an uncompressed TIFF (84 MB) and an uncompressed
# OME-Zarr 0.5 store, served over http:// by benches/python/distant_server.py, which answers
# each request after LATENCY_MS and paces each connection to 100 MB/s (a cloud bucket from a
# lab). `threshold` (the reader's throughput) and `analyze` are timed REPEAT times at 0, 20 and
# 50 ms; with BEFORE=path/to/an/older/contactscope the two builds alternate, run for run.
#
#   cargo build --release && PYTHON=/path/to/venv/bin/python benches/remote_latency.sh
#   (the venv needs numpy, zarr>=3 and tifffile for benches/ome_zarr.sh's data)
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
export BIN=${CONTACTSCOPE_BIN:-$ROOT/target/release/contactscope}
export BEFORE=${BEFORE:-}
export DIR=${BENCH_DIR:-/tmp/cs-zarr-bench}
export REPEAT=${REPEAT:-3}
export SERVER=$ROOT/benches/python/distant_server.py
PYTHON=${PYTHON:-python3}
[ -x "$BIN" ] || { echo "build first: cargo build --release" >&2; exit 1; }
[ -f "$DIR/done" ] || REPEAT=1 PYTHON="$PYTHON" "$ROOT/benches/ome_zarr.sh" >/dev/null
"$PYTHON" - <<'PY'
import os, shutil, statistics, subprocess, sys, time
builds = {"now": os.environ["BIN"]}
if os.environ["BEFORE"]:
    builds = {"before": os.environ["BEFORE"], **builds}
DIR, REPEAT = os.environ["DIR"], int(os.environ["REPEAT"])
print("| round trip | input | command | build | runs s | median s | MB/s |")
print("|---|---|---|---|---|---|---|")
for latency in (0, 20, 50):
    env = dict(os.environ, LATENCY_MS=str(latency), STREAM_MBPS="100")
    server = subprocess.Popen([sys.executable, os.environ["SERVER"], DIR], stdout=subprocess.PIPE,
                              text=True, env=env)
    base = f"http://127.0.0.1:{int(server.stdout.readline())}"
    for name, axis in (("raw.tif", []), ("raw.ome.zarr", ["--load-axis", "t"])):
        for command in (["threshold"], ["analyze", "--forces", "4mN..400mN:40", "--quiet"]):
            args = [command[0], f"{base}/{name}", *axis, *command[1:]]
            times = {b: [] for b in builds}
            for _ in range(REPEAT):
                for build, binary in builds.items():
                    out = os.path.join(DIR, "out-far")
                    shutil.rmtree(out, ignore_errors=True)
                    extra = ["--out", out] if command[0] == "analyze" else []
                    t = time.perf_counter()
                    subprocess.run([binary, *args, *extra], check=True, capture_output=True)
                    times[build].append(time.perf_counter() - t)
            for build, ts in times.items():
                m = statistics.median(ts)
                runs = " ".join(f"{t:.3f}" for t in ts)
                print(f"| {latency} ms | {name} | {command[0]} | {build} | {runs} | {m:.3f} "
                      f"| {83.886 / m:.0f} |", flush=True)
    server.terminate()
PY
