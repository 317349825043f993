"""Dask: a loopback-only LocalCluster(n_workers=2, threads_per_worker=1); sweeps and fits on it
equal the serial path exactly, and the fit agrees with the library's own."""

import math

import numpy as np
import pytest

import contactscope as cs

distributed = pytest.importorskip("dask.distributed")
from contactscope import distributed as dd  # noqa: E402

SPEC = dict(nx=64, ny=64, pixel_size=2e-7, rms_height=1e-7, hurst=0.8)
LOADS = [2e-5, 4e-5, 8e-5]
RADIUS = 20e-6


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1",
                                       dashboard_address="127.0.0.1:0", processes=True)
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_cluster_listens_on_loopback_only(client):
    info = client.scheduler_info()
    assert info["address"].startswith("tcp://127.0.0.1:")
    assert len(info["workers"]) == 2
    assert all(w.startswith("tcp://127.0.0.1:") for w in info["workers"])


def test_sweep_equals_serial(client):
    h = cs.surface(seed=1, **SPEC)
    kwargs = dict(family="hardening", values=[1e15, 4e15, 16e15], heights=h,
                  surface_spec=SPEC, seeds=[2, 3], radius=RADIUS)
    on_dask = dd.sweep(LOADS, 2e-7, 1e9, client=client, **kwargs)
    serial = dd.sweep(LOADS, 2e-7, 1e9, client="serial", **kwargs)
    assert len(on_dask.rows) == len(serial.rows) == 9
    for a, b in zip(on_dask.rows, serial.rows):
        assert (a["surface"], a["seed"], a["parameter"]) == (b["surface"], b["seed"],
                                                             b["parameter"])
        np.testing.assert_array_equal(a["areas_m2"], b["areas_m2"])
    # Each ramp is the library's: the first surface's ramp at k = 4 MPa/nm.
    ref = cs.ramp(h, 2e-7, 1e9, "hardening", 4e15, LOADS, radius=RADIUS)
    np.testing.assert_array_equal(on_dask.rows[1]["areas_m2"], ref.areas_m2)
    # A softer material (smaller k) gives more area at every load.
    assert (on_dask.rows[0]["areas_m2"] >= on_dask.rows[2]["areas_m2"]).all()
    pytest.importorskip("pandas", reason="to_pandas() needs pandas, an optional dependency")
    df = on_dask.to_pandas()
    assert len(df) == 9 * len(LOADS)


def test_sweep_reports_infeasible_values(client):
    h = cs.surface(seed=1, **SPEC)
    # 0.1 MPa over the 12.8 µm map carries 16 µN, less than the loads: infeasible.
    r = dd.sweep(LOADS, 2e-7, 1e9, family="hardness", values=[1e5, 1e9], heights=h,
                 radius=RADIUS, client=client)
    assert r.rows[0]["areas_m2"] is None and "exceeds" in r.rows[0]["error"]
    assert r.rows[1]["error"] is None


def test_fit_equals_serial_and_library(client):
    h = cs.surface(seed=4, **SPEC)
    truth = cs.ramp(h, 2e-7, 1e9, "hardening", 4e15, LOADS, radius=RADIUS).areas_m2
    kwargs = dict(radius=RADIUS, grid=5)
    on_dask = dd.fit_hardening(LOADS, truth, h, 2e-7, 1e9, client=client, **kwargs)
    serial = dd.fit_hardening(LOADS, truth, h, 2e-7, 1e9, client="serial", **kwargs)
    assert on_dask.parameter == serial.parameter
    assert on_dask.misfit == serial.misfit
    assert on_dask.trace == serial.trace
    np.testing.assert_array_equal(on_dask.areas_m2, serial.areas_m2)
    library = cs.fit_hardening(LOADS, truth, h, 2e-7, 1e9, **kwargs)
    # Both searches end in the same misfit valley (areas are whole pixels, so the valley is flat).
    assert on_dask.misfit <= library.misfit + 1e-3
    assert math.log(on_dask.parameter / library.parameter) == pytest.approx(0.0, abs=0.1)
    assert on_dask.parameter == pytest.approx(4e15, rel=0.2)
    # The client= argument of the top-level function goes the same way.
    via_top = cs.fit_hardening(LOADS, truth, h, 2e-7, 1e9, client=client, **kwargs)
    assert via_top.parameter == on_dask.parameter


def test_fit_bad_input_fails_before_tasks():
    h = cs.surface(seed=4, **SPEC)
    with pytest.raises(ValueError):
        dd.fit_hardening([1e-5], [1e-12], h, 2e-7, 1e9, client="serial")
    with pytest.raises(ValueError):
        dd.fit_hardening(LOADS, [1e-12] * 3, h, 2e-7, 1e9, family="plastic", client="serial")
    with pytest.raises(ValueError):
        dd.sweep(LOADS, 2e-7, 1e9, client="serial")


def test_brent_finds_minimum():
    calls = []

    def f(x):
        calls.append(x)
        return (x - 0.3) ** 2 + 1.0

    x = dd.brent_minimum(f, -1.0, 2.0, 1e-6)
    assert x == pytest.approx(0.3, abs=1e-5)
    assert len(calls) < 30


def test_tasks_undo_the_worker_environment_s_malloc_thresholds(tmp_path):
    """In a process started like a Dask worker (``MALLOC_TRIM_THRESHOLD_`` set), the solver's
    buffers fault in afresh at every load until a task sets glibc's thresholds back; counted in
    a subprocess, minor page faults of one 256² ramp before and after."""
    import os
    import subprocess
    import sys

    if not sys.platform.startswith("linux"):
        pytest.skip("glibc's mallopt: Linux only")
    script = tmp_path / "faults.py"
    script.write_text(
        "import resource, contactscope as cs\n"
        "from contactscope import distributed as dd\n"
        "cs.set_num_threads(1)\n"
        "h = cs.surface(256, 256, 128e-9, rms_slope=0.1, rolloff=4e-6, cutoff=512e-9, seed=7)\n"
        "def faults():\n"
        "    f = resource.getrusage(resource.RUSAGE_SELF).ru_minflt\n"
        "    cs.ramp(h, 128e-9, 3.7e9, 'hardening', 4e15, [4e-3, 40e-3, 400e-3], radius=290e-6)\n"
        "    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - f\n"
        "faults()\n"
        "before = faults()\n"
        "tuned = dd._tune_malloc()\n"
        "faults()\n"
        "print(before, faults(), tuned)\n")
    env = dict(os.environ, MALLOC_TRIM_THRESHOLD_="65536")
    out = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True,
                         check=True).stdout.split()
    before, after, tuned = int(out[0]), int(out[1]), out[2] == "True"
    if not tuned:
        pytest.skip("not glibc: mallopt unavailable")
    assert after * 3 < before, f"minor faults per ramp: {before} before, {after} after"
    # Without the variable nothing is changed.
    env.pop("MALLOC_TRIM_THRESHOLD_")
    out = subprocess.run([sys.executable, "-c",
                          "from contactscope import distributed as dd; print(dd._tune_malloc())"],
                         env=env, capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False"]


def test_a_worker_killed_mid_sweep_loses_nothing():
    """SIGKILL one of two worker processes while its ramps run: Dask reruns the lost tasks (they
    are pure), its nanny starts a new worker, and the sweep returns every row, equal to the
    serial path's."""
    import os
    import signal
    import threading
    import time

    spec = dict(nx=128, ny=128, pixel_size=1e-7, rms_height=5e-8, hurst=0.8)
    h = cs.surface(seed=5, **spec)
    kwargs = dict(family="hardening", values=list(np.geomspace(1e15, 1e16, 12)), heights=h,
                  radius=RADIUS)
    serial = dd.sweep(LOADS, 1e-7, 1e9, client="serial", **kwargs)
    with dd.local_client(n_workers=2, threads_per_worker=1) as c:
        pids = c.run(os.getpid)
        victim_address, victim = sorted(pids.items())[0]
        killed = threading.Event()

        def kill_when_busy():
            deadline = time.monotonic() + 60
            while time.monotonic() < deadline and not killed.is_set():
                if c.processing().get(victim_address):
                    os.kill(victim, signal.SIGKILL)
                    killed.set()
                    return
                time.sleep(0.01)

        killer = threading.Thread(target=kill_when_busy, daemon=True)
        killer.start()
        on_dask = dd.sweep(LOADS, 1e-7, 1e9, client=c, **kwargs)
        killer.join(timeout=5)
        assert killed.is_set(), "the worker was killed while it held tasks"
        assert victim not in c.run(os.getpid).values(), "a new worker process took its place"
    assert len(on_dask.rows) == len(serial.rows) == 12
    for a, b in zip(on_dask.rows, serial.rows):
        assert a["error"] is None and a["parameter"] == b["parameter"]
        np.testing.assert_array_equal(a["areas_m2"], b["areas_m2"])
