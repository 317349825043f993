"""Dask: a loopback-only LocalCluster(n_workers=2, threads_per_worker=1); sweeps and fits on it
equal the serial path exactly, and the fit agrees with the library's own."""

import csv
import json
import math
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import contactscope as cs

distributed = pytest.importorskip("dask.distributed")
from contactscope import distributed as dd  # noqa: E402

from dask_faults import when_busy  # noqa: E402

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
    spec = dict(nx=128, ny=128, pixel_size=1e-7, rms_height=5e-8, hurst=0.8)
    h = cs.surface(seed=5, **spec)
    kwargs = dict(family="hardening", values=list(np.geomspace(1e15, 1e16, 12)), heights=h,
                  radius=RADIUS)
    serial = dd.sweep(LOADS, 1e-7, 1e9, client="serial", **kwargs)
    with dd.local_client(n_workers=2, threads_per_worker=1) as c:
        pids = c.run(os.getpid)
        victim_address, victim = sorted(pids.items())[0]
        killer, killed = when_busy(c, victim_address, lambda: os.kill(victim, signal.SIGKILL))
        on_dask = dd.sweep(LOADS, 1e-7, 1e9, client=c, **kwargs)
        killer.join(timeout=5)
        assert killed.is_set(), "the worker was killed while it held tasks"
        assert victim not in c.run(os.getpid).values(), "a new worker process took its place"
    assert len(on_dask.rows) == len(serial.rows) == 12
    for a, b in zip(on_dask.rows, serial.rows):
        assert a["error"] is None and a["parameter"] == b["parameter"]
        np.testing.assert_array_equal(a["areas_m2"], b["areas_m2"])


def test_thread_plan_shares_each_machine_s_cores():
    one = {"host": "a", "job": None, "cpus": 2, "nthreads": 1}
    two_singles = {"w1": one, "w2": dict(one)}
    # A sweep: one thread per single-thread worker; a lone task (a Brent step): both cores.
    assert dd.thread_plan(two_singles, 8) == {"w1": 1, "w2": 1}
    assert dd.thread_plan(two_singles, 1) == {"w1": 2, "w2": 2}
    # One 4-thread worker in a 4-core Slurm job: its pool of 4 shared by its 4 tasks.
    job = {"w": {"host": "n1", "job": "17", "cpus": 4, "nthreads": 4}}
    assert dd.thread_plan(job, 8) == {"w": 4}
    # Two Slurm jobs of 1 core each on one node do not share: each is its own allocation.
    jobs = {"a": {"host": "n1", "job": "1", "cpus": 1, "nthreads": 1},
            "b": {"host": "n1", "job": "2", "cpus": 1, "nthreads": 1}}
    assert dd.thread_plan(jobs, 1) == {"a": 1, "b": 1}
    # More Dask threads than cores: the pools never outgrow the cores.
    over = {"w": {"host": "a", "job": None, "cpus": 2, "nthreads": 4}}
    assert dd.thread_plan(over, 8) == {"w": 2}
    # 16 single-thread workers on 16 cores running a 7-point grid: 2 threads each (14 in use).
    many = {f"w{i}": {"host": "a", "job": None, "cpus": 16, "nthreads": 1} for i in range(16)}
    assert set(dd.thread_plan(many, 7).values()) == {2}
    assert set(dd.thread_plan(many, 100).values()) == {1}


def test_workers_get_their_share_of_the_cores(client):
    """On the module's cluster (2 single-thread workers on this machine), a sweep leaves each
    worker's pool at its share of the cores and a fit's lone Brent step at all of them."""
    cpus = dd._cpus()
    h = cs.surface(seed=1, **SPEC)
    dd.sweep(LOADS, 2e-7, 1e9, values=[1e15, 2e15, 4e15, 8e15], heights=h, radius=RADIUS,
             client=client)
    assert set(client.run(cs.get_num_threads).values()) == {max(1, cpus // 2)}
    dd.fit_hardening(LOADS, [1e-12, 2e-12, 4e-12], h, 2e-7, 1e9, radius=RADIUS, grid=3,
                     ln_tolerance=1.0, client=client)
    # The last tasks were the standard error's three ramps, at most 2 running at once.
    assert set(client.run(cs.get_num_threads).values()) == {max(1, cpus // 2)}
    fixed = dd.sweep(LOADS, 2e-7, 1e9, values=[1e15, 2e15], heights=h, radius=RADIUS,
                     client=client, threads_per_task=3)
    assert set(client.run(cs.get_num_threads).values()) == {3}
    assert all(r["error"] is None for r in fixed.rows)
    # A lone task (elastic: one ramp) gets every core of its machine.
    dd.fit_hardening(LOADS, [1e-12, 2e-12, 4e-12], h, 2e-7, 1e9, radius=RADIUS,
                     family="elastic", client=client)
    assert cpus in client.run(cs.get_num_threads).values()


def test_a_worker_with_several_dask_threads_gets_a_pool_for_all_of_them():
    """One worker running 2 tasks at once: the sweep's plan gives its pool the machine's cores
    (2 tasks sharing them), and a worker missing from a plan (one that joined later) gets one
    thread per Dask thread, never one thread for all of its tasks."""
    cpus = dd._cpus()
    with dd.local_client(n_workers=1, threads_per_worker=2) as c:
        assert c.submit(dd._pool_size, ({}, 1), pure=False).result() == 2
        assert c.submit(dd._pool_size, ({"tcp://elsewhere:1": 5}, 3), pure=False).result() == 6
        h = cs.surface(seed=1, **SPEC)
        r = dd.sweep(LOADS, 2e-7, 1e9, values=[1e15, 4e15, 16e15], heights=h, radius=RADIUS,
                     client=c)
        assert list(c.run(cs.get_num_threads).values()) == [max(1, cpus)]
    serial = dd.sweep(LOADS, 2e-7, 1e9, values=[1e15, 4e15, 16e15], heights=h, radius=RADIUS,
                      client="serial")
    for a, b in zip(r.rows, serial.rows):
        np.testing.assert_array_equal(a["areas_m2"], b["areas_m2"])


def test_a_ramp_that_does_not_converge_fills_its_row_with_the_error(client):
    h = cs.surface(seed=1, **SPEC)
    # Within 20 iterations the soft material's ramp converges, the hard one's does not.
    kwargs = dict(family="hardening", values=[1e15, 16e15], heights=h, radius=RADIUS,
                  max_iterations=20)
    with pytest.raises(cs.ConvergenceError):
        cs.ramp(h, 2e-7, 1e9, "hardening", 16e15, LOADS, radius=RADIUS, max_iterations=20)
    r = dd.sweep(LOADS, 2e-7, 1e9, client=client, **kwargs)
    assert r.rows[1]["areas_m2"] is None and "20 iterations" in r.rows[1]["error"]
    assert r.rows[0]["error"] is None
    serial = dd.sweep(LOADS, 2e-7, 1e9, client="serial", **kwargs)
    np.testing.assert_array_equal(r.rows[0]["areas_m2"], serial.rows[0]["areas_m2"])
    assert r.rows[1]["error"] == serial.rows[1]["error"]


def test_a_sweep_on_the_gpu_equals_the_cpu_or_says_why_not(client):
    """device= reaches every worker's ramp: with a usable GPU the areas equal the CPU's (the
    GPU solver gives the same contact maps), without one each row says why; "auto" falls back
    to the CPU; an unknown device is refused before any task."""
    h = cs.surface(seed=1, **SPEC)
    kwargs = dict(values=[1e15, 4e15], heights=h, radius=RADIUS, client=client)
    cpu = dd.sweep(LOADS, 2e-7, 1e9, **kwargs)
    gpu = dd.sweep(LOADS, 2e-7, 1e9, device="cuda", **kwargs)
    auto = dd.sweep(LOADS, 2e-7, 1e9, device="auto", **kwargs)
    for g, a, c in zip(gpu.rows, auto.rows, cpu.rows):
        if g["error"] is not None:  # no usable GPU (or a build without CUDA) on this worker
            assert g["areas_m2"] is None and "GPU" in g["error"] and "\n" not in g["error"]
        else:
            np.testing.assert_array_equal(g["areas_m2"], c["areas_m2"])
        np.testing.assert_array_equal(a["areas_m2"], c["areas_m2"])
    with pytest.raises(cs.InputError, match="not one of cpu, cuda, auto"):
        dd.sweep(LOADS, 2e-7, 1e9, device="gpu", **kwargs)


def test_serial_sweeps_and_fits_report_each_ramp(capsys):
    """progress=True in this process (client="serial", or client=None with one task or one
    core): a line per ramp done, with the count where it is known; nothing without it."""
    h = cs.surface(seed=1, **SPEC)
    kwargs = dict(values=[1e15, 4e15, 16e15], heights=h, radius=RADIUS, client="serial")
    dd.sweep(LOADS, 2e-7, 1e9, progress=True, **kwargs)
    assert capsys.readouterr().err.splitlines() == [
        f"contactscope: ramp {i} of 3 done" for i in (1, 2, 3)]
    dd.sweep(LOADS, 2e-7, 1e9, **kwargs)
    assert capsys.readouterr().err == ""
    truth = cs.ramp(h, 2e-7, 1e9, "hardening", 4e15, LOADS, radius=RADIUS).areas_m2
    dd.fit_hardening(LOADS, truth, h, 2e-7, 1e9, radius=RADIUS, grid=3, ln_tolerance=0.5,
                     client="serial", progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert lines[:4] == ["contactscope: hardening fit: 3 ramps over the search grid"] + [
        f"contactscope: ramp {i} of 3 done" for i in (1, 2, 3)]
    assert lines[4] == "contactscope: ramp 1 done" and lines[5].startswith(
        "contactscope: Brent step: k_MPa_per_nm = ")
    assert lines[-3:] == [f"contactscope: ramp {i} of 3 done" for i in (1, 2, 3)]


def test_a_sweep_writes_its_folder_whole(client, tmp_path):

    h = cs.surface(seed=1, **SPEC)
    out = tmp_path / "sweep"
    r = dd.sweep(LOADS, 2e-7, 1e9, family="hardness", values=[1e5, 1e9], heights=h,
                 radius=RADIUS, client=client, out=out)
    assert sorted(p.name for p in out.iterdir()) == [".contactscope-run.json", "sweep.csv",
                                                     "sweep.json"]
    rows = list(csv.DictReader((out / "sweep.csv").open()))
    assert [k for k in rows[0]] == ["surface", "seed", "model", "hardness_MPa", "force_mN",
                                    "area_um2", "edge_contact", "error"]
    assert len(rows) == 2 * len(LOADS)
    assert float(rows[0]["hardness_MPa"]) == pytest.approx(0.1)
    assert rows[0]["area_um2"] == "" and "exceeds" in rows[0]["error"]
    assert [float(x["area_um2"]) for x in rows[3:]] == pytest.approx(
        [a * 1e12 for a in r.rows[1]["areas_m2"]], rel=1e-15)
    # to_pandas() has the table's columns, in SI units, with the same values.
    pd = pytest.importorskip("pandas", reason="to_pandas() needs pandas, an optional dependency")
    df = r.to_pandas()
    table = pd.read_csv(out / "sweep.csv", keep_default_na=False)
    si = {"hardness_MPa": ("hardness_pa", 1e6), "force_mN": ("force_n", 1e-3),
          "area_um2": ("area_m2", 1e-12)}
    assert list(df.columns) == [si.get(c, (c,))[0] for c in table.columns]
    for column, (name, factor) in si.items():
        mine = df[name].to_numpy(dtype=float)
        theirs = pd.to_numeric(table[column], errors="coerce").to_numpy() * factor
        np.testing.assert_allclose(mine, theirs, rtol=1e-12, equal_nan=True)
    assert list(df["model"]) == list(table["model"])
    summary = json.loads((out / "sweep.json").read_text())
    assert summary["loads_mN"] == pytest.approx([f * 1e3 for f in LOADS])
    assert summary["failed"] == 1 and summary["ramps"] == 2 and summary["device"] == "cpu"
    # A second run replaces the folder as a whole; a folder of someone else's is refused
    # before any ramp runs, and nothing in it changes.
    dd.sweep(LOADS, 2e-7, 1e9, values=[4e15], heights=h, radius=RADIUS, client="serial",
             out=out)
    assert len(list(csv.DictReader((out / "sweep.csv").open()))) == len(LOADS)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")

    class NoTasks:  # a client that fails any use: the refusal must come first
        def __getattr__(self, name):
            raise AssertionError(f"client.{name} used before the folder was checked")

    with pytest.raises(cs.FileError, match="not written by contactscope"):
        dd.sweep(LOADS, 2e-7, 1e9, values=[4e15], heights=h, radius=RADIUS, client=NoTasks(),
                 out=mine)
    assert [p.name for p in mine.iterdir()] == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["mine", "sweep"]


def _descendants(pid):
    """Process IDs below ``pid`` (Linux /proc)."""
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    parent = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
            children.setdefault(parent, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def test_an_interrupted_sweep_leaves_no_folder_and_no_workers(tmp_path):
    """Ctrl-C (SIGINT) to a script while its sweep's ramps run on the cluster the sweep
    started: the script stops with KeyboardInterrupt, writes no output folder (nor a staging
    folder beside it), and the cluster's worker processes are gone."""
    if not sys.platform.startswith("linux"):
        pytest.skip("reads /proc to find the worker processes")
    script = tmp_path / "interrupted.py"
    # The script turns Ctrl-C into KeyboardInterrupt itself, as Python does for a user at a
    # terminal: launched from a process that ignores SIGINT (a CI job started in the background),
    # it would inherit the ignoring, and the signal would do nothing.
    script.write_text(
        "import signal\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "import sys\n"
        "import numpy as np\n"
        "import contactscope as cs\n"
        "from contactscope import distributed as dd\n"
        "if __name__ == '__main__':\n"
        "    h = cs.surface(256, 256, 1e-7, rms_height=5e-8, hurst=0.8, seed=5)\n"
        "    dd.sweep([2e-5, 4e-5, 8e-5], 1e-7, 1e9, values=list(np.geomspace(1e15, 1e16, 60)),\n"
        "             heights=h, radius=20e-6, progress=True, out=sys.argv[1])\n")
    out = tmp_path / "results"
    p = subprocess.Popen([sys.executable, str(script), str(out)], stderr=subprocess.PIPE,
                         text=True, cwd=tmp_path)
    try:
        lines = []
        for line in p.stderr:  # the sweep prints the dashboard's address once it has a client
            lines.append(line)
            if "Dask dashboard at" in line:
                break
        assert any("Dask dashboard at http://127.0.0.1:" in x for x in lines), "".join(lines)
        time.sleep(1.5)  # the ramps are running on the workers
        workers = _descendants(p.pid)
        assert workers, "the sweep's cluster has worker processes"
        p.send_signal(signal.SIGINT)
        rest = p.communicate(timeout=60)[1]
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode != 0
    assert "KeyboardInterrupt" in rest
    assert sorted(x.name for x in tmp_path.iterdir()) == ["interrupted.py"]
    deadline = time.monotonic() + 20
    while time.monotonic() < deadline and any(os.path.exists(f"/proc/{w}") for w in workers):
        time.sleep(0.2)
    left = [w for w in workers if os.path.exists(f"/proc/{w}")
            and open(f"/proc/{w}/stat").read().rsplit(")", 1)[1].split()[0] != "Z"]
    assert not left, f"worker processes still running: {left}"
