#!/usr/bin/env bash
# Inputs on object storage against the same files on disk (issue 45; results in
# docs/performance.md): the 40 × 1024² uint16 load series of benches/ome_zarr.sh (84 MB of
# samples) as an uncompressed TIFF and an uncompressed OME-Zarr 0.5 store, put into a bucket of
# moto's S3 server started on loopback, each timed REPEAT times for `threshold` (one pass: the
# reader's throughput) and `analyze` (the whole job), from disk (page cache warm), from
# s3:// (signed) and from http:// (the same objects, public-read, unsigned). The server's own
# ceiling is printed beside: the time boto3 takes to GET every object (or every 4 MiB range of
# the TIFF, as our reader asks for it) one after the other.
#
#   cargo build --release && PYTHON=/path/to/venv/bin/python benches/object_storage.sh
#   (the venv needs numpy, zarr>=3, tifffile and moto[server]); with S3S_FS=path/to/s3s-fs
#   (`cargo install s3s-fs --features binary`) the same rows against that server too
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
export BIN=${CONTACTSCOPE_BIN:-$ROOT/target/release/contactscope}
export DIR=${BENCH_DIR:-/tmp/cs-zarr-bench}
export REPEAT=${REPEAT:-5}
PYTHON=${PYTHON:-python3}
[ -x "$BIN" ] || { echo "build first: cargo build --release" >&2; exit 1; }
# The data of the OME-Zarr bench (it writes them once, then times its own table).
[ -f "$DIR/done" ] || REPEAT=1 PYTHON="$PYTHON" "$ROOT/benches/ome_zarr.sh" >/dev/null
"$PYTHON" - <<'PY'
import logging, os, pathlib, shutil, socket, statistics, subprocess, tempfile, time
import boto3
from moto.server import ThreadedMotoServer

logging.getLogger("werkzeug").setLevel(logging.ERROR)
BIN, DIR, REPEAT = os.environ["BIN"], pathlib.Path(os.environ["DIR"]), int(os.environ["REPEAT"])
servers, stops = [], []
moto = ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
moto.start()
stops.append(moto.stop)
host, port = moto.get_host_and_port()
servers.append(("moto", f"http://{host}:{port}"))
# s3s-fs (`cargo install s3s-fs --features binary`), a server in Rust over a folder: what a
# server that is not the bottleneck gives (S3S_FS=path/to/s3s-fs).
if os.environ.get("S3S_FS"):
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]
    root = tempfile.mkdtemp(prefix="s3s-")
    proc = subprocess.Popen([os.environ["S3S_FS"], "--host", "127.0.0.1", "--port", str(free),
                             "--access-key", "bench", "--secret-key", "bench", root],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    stops.append(lambda: (proc.terminate(), shutil.rmtree(root, ignore_errors=True)))
    for _ in range(100):
        try:
            socket.create_connection(("127.0.0.1", free), timeout=0.1).close()
            break
        except OSError:
            time.sleep(0.1)
    servers.append(("s3s-fs", f"http://127.0.0.1:{free}"))

keys = {"raw.tif": ["raw.tif"], "raw.ome.zarr": []}
for f in sorted((DIR / "raw.ome.zarr").rglob("*")):
    if f.is_file():
        keys["raw.ome.zarr"].append("raw.ome.zarr/" + f.relative_to(DIR / "raw.ome.zarr").as_posix())
clients = {}
for label, endpoint in servers:
    s3 = clients[label] = boto3.client("s3", endpoint_url=endpoint, aws_access_key_id="bench",
                                       aws_secret_access_key="bench", region_name="us-east-1")
    s3.create_bucket(Bucket="lab")
    # Public-read for the unsigned http:// rows (moto only).
    extra = {"ACL": "public-read"} if label == "moto" else {}
    for ks in keys.values():
        for key in ks:
            s3.upload_file(str(DIR / key), "lab", key, ExtraArgs=extra)

def timed(args, endpoint):
    env = dict(os.environ, AWS_ACCESS_KEY_ID="bench", AWS_SECRET_ACCESS_KEY="bench",
               AWS_ENDPOINT_URL=endpoint)
    times = []
    for _ in range(REPEAT):
        shutil.rmtree(DIR / "out-s3", ignore_errors=True)
        t = time.perf_counter()
        subprocess.run([BIN, *args], env=env, check=True, capture_output=True)
        times.append(time.perf_counter() - t)
    return statistics.median(times)

def ceiling(name, s3):
    times = []
    for _ in range(REPEAT):
        t = time.perf_counter()
        if name.endswith(".tif"):
            size = s3.head_object(Bucket="lab", Key=name)["ContentLength"]
            for at in range(0, size, 4 << 20):
                s3.get_object(Bucket="lab", Key=name,
                              Range=f"bytes={at}-{min(size, at + (4 << 20)) - 1}")["Body"].read()
        else:
            for k in keys[name]:
                s3.get_object(Bucket="lab", Key=k)["Body"].read()
        times.append(time.perf_counter() - t)
    return statistics.median(times)

print("| input | from | threshold s | read MB/s | analyze s | analyze ÷ disk | server alone s |")
print("|---|---|---|---|---|---|---|")
for name in ("raw.tif", "raw.ome.zarr"):
    axis = ["--load-axis", "t"] if name.endswith(".zarr") else []
    rows = [("disk", str(DIR / name), None, None)]
    for label, endpoint in servers:
        rows.append((f"s3:// ({label})", f"s3://lab/{name}", endpoint, clients[label]))
        if label == "moto":
            rows.append((f"http:// ({label})", f"{endpoint}/lab/{name}", endpoint,
                         clients[label]))
    base = None
    for where, path, endpoint, s3 in rows:
        th = timed(["threshold", path, *axis], endpoint or servers[0][1])
        an = timed(["analyze", path, *axis, "--forces", "4mN..400mN:40", "--out",
                    str(DIR / "out-s3"), "--quiet"], endpoint or servers[0][1])
        base = base or an
        server_s = "" if s3 is None else f"{ceiling(name, s3):.3f}"
        print(f"| {name} | {where} | {th:.3f} | {83.886 / th:.0f} | {an:.3f} | {an / base:.2f} "
              f"| {server_s} |", flush=True)
for stop in stops:
    stop()
PY
