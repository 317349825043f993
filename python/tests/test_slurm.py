"""Dask on a real Slurm. `scripts/slurm-test` starts a one-node Slurm on this machine (as root)
and runs this file; elsewhere it is skipped. The cluster is the configuration documented in
python/README.md, executed as written there but for its queue and account lines."""

import os
import pathlib
import re
import subprocess
import time

import numpy as np
import pytest

import contactscope as cs

PARTITION = os.environ.get("CONTACTSCOPE_SLURM_PARTITION")
if not PARTITION:
    pytest.skip("Dask on Slurm: run scripts/slurm-test (it starts a one-node Slurm as root)",
                allow_module_level=True)
pytest.importorskip("dask_jobqueue", reason="Dask on Slurm needs dask-jobqueue")
from contactscope import distributed as dd  # noqa: E402

from dask_faults import when_busy  # noqa: E402

README = pathlib.Path(__file__).resolve().parents[1] / "README.md"
SPEC = dict(nx=128, ny=128, pixel_size=1e-7, rms_height=5e-8, hurst=0.8)
LOADS = [2e-5, 4e-5, 8e-5]
RADIUS = 20e-6


def documented_configuration():
    """The README's SLURMCluster block, and the same block for this Slurm: the queue line
    names the test partition, the account line is left out (this Slurm keeps no accounts)."""
    section = README.read_text().split("### On a Slurm cluster", 1)[1]
    block = section.split("```python\n", 1)[1].split("```", 1)[0]
    ours = []
    for line in block.splitlines():
        if re.match(r"\s*account=", line):
            continue
        if re.match(r"\s*queue=", line):
            line = re.sub(r'queue="[^"]*"', f'queue="{PARTITION}"', line)
        ours.append(line)
    return block, "\n".join(ours) + "\n"


def jobs():
    """This partition's jobs: (job ID, state)."""
    out = subprocess.run(["squeue", "-h", "-p", PARTITION, "-o", "%i %T"], check=True,
                         capture_output=True, text=True).stdout
    return [tuple(line.split()) for line in out.splitlines() if line.strip()]


@pytest.fixture(scope="module")
def slurm(tmp_path_factory):
    block, ours = documented_configuration()
    removed = [x for x in block.splitlines() if x not in ours.splitlines()]
    added = [x for x in ours.splitlines() if x not in block.splitlines()]
    assert [x.split("=")[0].strip() for x in removed] == ["queue", "account"], removed
    assert [x.split("=")[0].strip() for x in added] == ["queue"], added
    before = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("slurm-jobs"))  # where the jobs' --output files go
    namespace = {}
    exec(compile(ours, str(README), "exec"), namespace)
    cluster, client = namespace["cluster"], namespace["client"]
    yield cluster, client
    client.close()
    cluster.close()
    os.chdir(before)
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline and jobs():
        time.sleep(0.5)
    assert not jobs(), "closing the cluster cancels its jobs"


def test_the_workers_are_slurm_jobs(slurm):
    cluster, client = slurm
    script = cluster.job_script()
    assert f"#SBATCH -p {PARTITION}" in script
    assert "#SBATCH --mem=" in script and "#SBATCH -t 01:00:00" in script
    assert "--output=dask-worker-%j.out" in script
    ids = client.run(lambda: os.environ.get("SLURM_JOB_ID"))
    assert len(ids) == 2 and len(set(ids.values())) == 2 and None not in ids.values()
    running = {i for i, state in jobs() if state == "RUNNING"}
    assert set(ids.values()) <= running
    # The workers import the package from the venv the client runs in.
    versions = client.run(lambda: __import__("contactscope").__version__)
    assert set(versions.values()) == {cs.__version__}


def test_a_sweep_on_slurm_equals_serial(slurm):
    _, client = slurm
    h = cs.surface(seed=1, **SPEC)
    kwargs = dict(family="hardening", values=[1e15, 4e15, 16e15], heights=h, surface_spec=SPEC,
                  seeds=[2, 3], radius=RADIUS)
    on_slurm = dd.sweep(LOADS, 1e-7, 1e9, client=client, **kwargs)
    serial = dd.sweep(LOADS, 1e-7, 1e9, client="serial", **kwargs)
    assert len(on_slurm.rows) == len(serial.rows) == 9
    for a, b in zip(on_slurm.rows, serial.rows):
        assert (a["surface"], a["seed"], a["parameter"], a["error"]) == (
            b["surface"], b["seed"], b["parameter"], b["error"])
        np.testing.assert_array_equal(a["areas_m2"], b["areas_m2"])
    # Each job has one core: each worker's contactscope pool has one thread.
    assert set(client.run(cs.get_num_threads).values()) == {1}


def test_fit_hardening_on_slurm_equals_serial(slurm):
    _, client = slurm
    h = cs.surface(seed=4, **SPEC)
    truth = cs.ramp(h, 1e-7, 1e9, "hardening", 4e15, LOADS, radius=RADIUS).areas_m2
    on_slurm = dd.fit_hardening(LOADS, truth, h, 1e-7, 1e9, radius=RADIUS, grid=5,
                                client=client)
    serial = dd.fit_hardening(LOADS, truth, h, 1e-7, 1e9, radius=RADIUS, grid=5,
                              client="serial")
    assert on_slurm.parameter == serial.parameter
    assert on_slurm.parameter_se == serial.parameter_se
    assert on_slurm.trace == serial.trace
    np.testing.assert_array_equal(on_slurm.areas_m2, serial.areas_m2)
    assert on_slurm.parameter == pytest.approx(4e15, rel=0.2)


def test_a_job_cancelled_mid_sweep_loses_nothing(slurm):
    """`scancel` of one worker's job while it holds ramps (Slurm preempting it, say): Dask
    reruns its tasks on the other worker and every row still equals the serial path's."""
    _, client = slurm
    h = cs.surface(seed=5, **SPEC)
    kwargs = dict(family="hardening", values=list(np.geomspace(1e15, 1e16, 10)), heights=h,
                  radius=RADIUS)
    serial = dd.sweep(LOADS, 1e-7, 1e9, client="serial", **kwargs)
    ids = client.run(lambda: os.environ["SLURM_JOB_ID"])
    victim_address, victim = sorted(ids.items())[0]
    canceller, cancelled = when_busy(client, victim_address, lambda: subprocess.run(
        ["scancel", "--signal=KILL", "--full", victim], check=True))
    on_slurm = dd.sweep(LOADS, 1e-7, 1e9, client=client, **kwargs)
    canceller.join(timeout=5)
    assert cancelled.is_set(), "the job was cancelled while its worker held ramps"
    assert victim not in {i for i, _ in jobs()}
    assert len(on_slurm.rows) == 10
    for a, b in zip(on_slurm.rows, serial.rows):
        assert a["error"] is None and a["parameter"] == b["parameter"]
        np.testing.assert_array_equal(a["areas_m2"], b["areas_m2"])


def test_a_batch_on_slurm_equals_the_command_line(slurm, cli, tmp_path):
    """The same samplesheet as a batch on the command line and as Dask tasks in Slurm jobs:
    the same tables, byte for byte; every series' folder and record written by the workers."""
    _, client = slurm
    for i in range(4):
        folder = tmp_path / f"s{i}"
        folder.mkdir()
        s = cs.synth_series(128, 128, 200e-9, [1e-3, 2e-3, 4e-3], seed=20 + i)
        cs.write_tiff(folder / "series.tif", s.images, 200e-9)
    (tmp_path / "sheet.csv").write_text(
        "id,input,forces,sample\n" + "".join(
            f's{i},s{i}/series.tif,"1,2,4mN",{"ab"[i % 2]}\n' for i in range(4)))
    cli("batch", "--samplesheet", tmp_path / "sheet.csv", "--out", tmp_path / "cli", "-q")
    result = dd.batch(tmp_path / "sheet.csv", tmp_path / "slurm", client=client)
    assert result.outcome["analysed"] == 4 and result.outcome["failed"] == 0
    for name in ["images.csv", "series.csv", "images.parquet", "series.parquet"]:
        assert (tmp_path / "cli" / name).read_bytes() == (tmp_path / "slurm" / name).read_bytes()
    for i in range(4):
        assert (tmp_path / "slurm" / "series" / f"s{i}" / "areas.csv").is_file()
        assert (tmp_path / "slurm" / "records" / f"s{i}.json").is_file()
