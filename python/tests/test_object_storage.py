"""Inputs on object storage (issue 45): ``s3://bucket/key`` and ``http(s)://`` URLs wherever a
micrograph path is given, tested against moto's S3 server started on loopback (the server
zarr-python's and s3fs's own tests use). A TIFF and OME-Zarr stores (NGFF 0.4 and 0.5) analyse
from the bucket with the same threshold and areas as from disk; a missing key, a missing bucket and
a connection killed on every try give one line naming the URL, a non-zero exit and no output
folder; connections killed mid-response a few times are retried to the same numbers; Python reads
the same planes through ``AWS_ENDPOINT_URL``.

moto is an optional test dependency (``scripts/test-all`` installs it); without it these tests
are skipped with a message."""

import csv
import logging
import os
import socket
import subprocess
import threading

import numpy as np
import pytest

import contactscope as cs
from conftest import _binary

moto_server = pytest.importorskip("moto.server", reason="moto[server] is needed (pip install 'moto[server]')")
boto3 = pytest.importorskip("boto3")

FORCES = "2mN,4mN,8mN"


@pytest.fixture(scope="module")
def s3(tmp_path_factory, series_tif):
    """A moto S3 server on loopback with bucket ``lab`` holding the series as a TIFF and as
    OME-Zarr stores written by ome-zarr-py (NGFF 0.4 and 0.5); objects are public-read so that
    they can also be read as plain HTTP."""
    logging.getLogger("werkzeug").setLevel(logging.ERROR)
    server = moto_server.ThreadedMotoServer(ip_address="127.0.0.1", port=0, verbose=False)
    server.start()
    host, port = server.get_host_and_port()
    endpoint = f"http://{host}:{port}"
    client = boto3.client("s3", endpoint_url=endpoint, aws_access_key_id="test",
                          aws_secret_access_key="test", region_name="us-east-1")
    client.create_bucket(Bucket="lab")
    tif, _ = series_tif
    client.upload_file(str(tif), "lab", "2026/series.tif", ExtraArgs={"ACL": "public-read"})
    stores = {}
    d = tmp_path_factory.mktemp("stores")
    data = np.asarray(cs.read_image(tif).images)
    for version in ("0.4", "0.5"):
        store = d / f"series-{version}.ome.zarr"
        _write_store(store, data, version)
        for f in sorted(store.rglob("*")):
            if f.is_file():
                key = f"2026/{store.name}/{f.relative_to(store).as_posix()}"
                client.upload_file(str(f), "lab", key, ExtraArgs={"ACL": "public-read"})
        stores[version] = store
    yield {"endpoint": endpoint, "client": client, "tif": tif, "stores": stores}
    server.stop()


def _write_store(path, data, version):
    zarr = pytest.importorskip("zarr")
    pytest.importorskip("ome_zarr")
    from ome_zarr.format import FormatV04, FormatV05
    from ome_zarr.io import parse_url
    from ome_zarr.writer import write_image
    fmt = FormatV04() if version == "0.4" else FormatV05()
    root = zarr.group(store=parse_url(str(path), mode="w", fmt=fmt).store,
                      zarr_format=2 if version == "0.4" else 3)
    write_image(data, root, axes="tyx", fmt=fmt, scale_factors=(2,),
                scale={"t": 1.0, "y": 0.2, "x": 0.2},
                axes_units={"y": "micrometer", "x": "micrometer"})


def _run(*args, endpoint=None, env_endpoint=None):
    """Run the command line with credentials in the environment; (exit status, stdout, stderr)."""
    binary = _binary()
    if binary is None or not binary.exists():
        pytest.skip("no contactscope binary (cargo build --release, or set CONTACTSCOPE_BIN)")
    env = dict(os.environ, AWS_ACCESS_KEY_ID="test", AWS_SECRET_ACCESS_KEY="test",
               AWS_REGION="us-east-1")
    for k in ("AWS_ENDPOINT_URL", "AWS_ENDPOINT_URL_S3", "AWS_PROFILE"):
        env.pop(k, None)
    if env_endpoint:
        env["AWS_ENDPOINT_URL"] = env_endpoint
    extra = ["--endpoint-url", endpoint] if endpoint else []
    done = subprocess.run([str(binary), *map(str, args), *extra], capture_output=True, text=True,
                          timeout=300, env=env)
    return done.returncode, done.stdout, done.stderr


def _areas(out):
    with open(out / "areas.csv", newline="") as f:
        return [(r["force_mN"], r["area_um2"], r["threshold"]) for r in csv.DictReader(f)]


def test_a_tiff_in_a_bucket_analyses_as_on_disk(s3, tmp_path):
    rc, _, err = _run("analyze", s3["tif"], "--forces", FORCES, "--out", tmp_path / "disk")
    assert rc in (0, 4), err
    rc, _, err = _run("analyze", "s3://lab/2026/series.tif", "--forces", FORCES, "--out",
                      tmp_path / "s3", endpoint=s3["endpoint"])
    assert rc in (0, 4), err
    assert _areas(tmp_path / "s3") == _areas(tmp_path / "disk")


@pytest.mark.parametrize("version", ["0.4", "0.5"])
def test_ome_zarr_stores_in_a_bucket_analyse_as_on_disk(s3, tmp_path, version):
    store = s3["stores"][version]
    args = ["--load-axis", "t", "--forces", FORCES]
    rc, _, err = _run("analyze", store, *args, "--out", tmp_path / "disk")
    assert rc in (0, 4), err
    # The endpoint from the command line, then from the environment.
    url = f"s3://lab/2026/{store.name}"
    rc, _, err = _run("analyze", url, *args, "--out", tmp_path / "s3", endpoint=s3["endpoint"])
    assert rc in (0, 4), err
    assert _areas(tmp_path / "s3") == _areas(tmp_path / "disk")
    rc, out, err = _run("info", url, env_endpoint=s3["endpoint"])
    assert rc == 0, err
    assert "ome-zarr" in out and "200.0000 nm" in out
    # Read-only HTTP: the same objects, unsigned, by their URL.
    rc, _, err = _run("analyze", f"{s3['endpoint']}/lab/2026/{store.name}", *args, "--out",
                      tmp_path / "http")
    assert rc in (0, 4), err
    assert _areas(tmp_path / "http") == _areas(tmp_path / "disk")


def test_python_reads_the_same_planes_from_the_bucket(s3, monkeypatch):
    monkeypatch.setenv("AWS_ENDPOINT_URL", s3["endpoint"])
    monkeypatch.setenv("AWS_ACCESS_KEY_ID", "test")
    monkeypatch.setenv("AWS_SECRET_ACCESS_KEY", "test")
    local = np.asarray(cs.read_image(s3["tif"]).images)
    remote = np.asarray(cs.read_image("s3://lab/2026/series.tif").images)
    np.testing.assert_array_equal(remote, local)
    store = np.asarray(cs.read_image(f"s3://lab/2026/{s3['stores']['0.5'].name}",
                                     load_axis="t").images)
    np.testing.assert_array_equal(store, local)


@pytest.mark.parametrize("url,what", [
    ("s3://lab/2026/missing.tif", "no such object (HTTP 404)"),
    ("s3://no-such-bucket/series.tif", "no such object (HTTP 404)"),
])
def test_a_missing_key_or_bucket_is_one_line_and_nothing_written(s3, tmp_path, url, what):
    out = tmp_path / "out"
    rc, stdout, err = _run("analyze", url, "--forces", FORCES, "--out", out,
                           endpoint=s3["endpoint"])
    assert rc == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1 and url in lines[0] and what in lines[0], err
    assert not out.exists()


def test_outputs_are_not_written_to_a_bucket(s3, tmp_path):
    rc, _, err = _run("analyze", "s3://lab/2026/series.tif", "--forces", FORCES, "--out",
                      "s3://lab/results", endpoint=s3["endpoint"])
    assert rc == 1 and "s3://lab/results" in err and "local folder" in err, err
    assert not os.path.exists("s3:")


class KillingProxy:
    """A TCP proxy in front of the server that cuts each of the first ``kills`` connections
    after ``after`` bytes of response (in the middle of a chunk's body); later connections pass
    through. ``kills=None`` cuts every connection."""

    def __init__(self, upstream, kills, after=50_000):
        host, port = upstream.rsplit("/", 1)[-1].split(":")
        self.upstream = (host, int(port))
        self.kills, self.after, self.cut = kills, after, 0
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(16)
        self.endpoint = f"http://127.0.0.1:{self.sock.getsockname()[1]}"
        self.lock = threading.Lock()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                client, _ = self.sock.accept()
            except OSError:
                return
            with self.lock:
                kill = self.kills is None or self.cut < self.kills
                if kill:
                    self.cut += 1
            threading.Thread(target=self._serve, args=(client, kill), daemon=True).start()

    def _serve(self, client, kill):
        server = socket.create_connection(self.upstream)

        def upstream():
            try:
                while data := client.recv(65536):
                    server.sendall(data)
            except OSError:
                pass

        threading.Thread(target=upstream, daemon=True).start()
        sent = 0
        try:
            while data := server.recv(65536):
                if kill and sent + len(data) > self.after:
                    client.sendall(data[: self.after - sent])
                    break
                client.sendall(data)
                sent += len(data)
        except OSError:
            pass
        for s in (client, server):
            try:
                s.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
            s.close()

    def close(self):
        self.sock.close()


def test_connections_killed_mid_response_are_retried_to_the_same_numbers(s3, tmp_path):
    store = s3["stores"]["0.5"]
    args = ["--load-axis", "t", "--forces", FORCES]
    rc, _, err = _run("analyze", store, *args, "--out", tmp_path / "disk")
    assert rc in (0, 4), err
    # The store holds the TIFF's planes: both give the same rows.
    for url in (f"s3://lab/2026/{store.name}", "s3://lab/2026/series.tif"):
        proxy = KillingProxy(s3["endpoint"], kills=3)
        extra = args if "zarr" in url else ["--forces", FORCES]
        out = tmp_path / url.rsplit("/", 1)[-1]
        rc, _, err = _run("analyze", url, *extra, "--out", out, endpoint=proxy.endpoint)
        proxy.close()
        assert rc in (0, 4), err
        assert proxy.cut == 3
        assert _areas(out) == _areas(tmp_path / "disk")


def test_a_connection_killed_on_every_try_is_one_line_and_nothing_written(s3, tmp_path):
    proxy = KillingProxy(s3["endpoint"], kills=None)
    out = tmp_path / "out"
    url = f"s3://lab/2026/{s3['stores']['0.5'].name}"
    rc, _, err = _run("analyze", url, "--load-axis", "t", "--forces", FORCES, "--out", out,
                      endpoint=proxy.endpoint)
    proxy.close()
    assert rc == 1, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and url in lines[0] and "tries" in lines[0], err
    assert not out.exists()
