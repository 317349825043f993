"""Benchmarks of the Python package (issue 13's performance targets; measured, never asserted).

1. Call overhead: `cs.simulate` on a 512² map (4 loads, hardening) against the command line's
   `simulate` on the same .npy (its wall time, which also writes the maps and the plot), and
   the same call with the 16 maps returned as numpy arrays against `maps=False` (the bare
   compute): target ≤ 5 % over the compute.
2. Dask: a sweep of 8 k values (one load ramp each): a ramp inside a worker against the same
   ramp in a plain process (target within 5 %), 1 → 2 single-thread workers (target ≥ 1.9×),
   the automatic cluster against the serial loop on all cores (target: never slower).

Run from the repository root after `cargo build --release` and installing the package:
    python python/benches/bench.py [--repeat 3] [--size 512]
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

import contactscope as cs
from contactscope import distributed

ROOT = pathlib.Path(__file__).resolve().parents[2]
BIN = pathlib.Path(os.environ.get("CONTACTSCOPE_BIN", ROOT / "target" / "release" / "contactscope"))
PIXEL = 100e-9
MODULUS = 1e9
RADIUS = 20e-6
LOADS = [20e-6, 40e-6, 80e-6, 160e-6]
K_VALUES = [1e15, 1.5e15, 2e15, 3e15, 4e15, 6e15, 8e15, 12e15]


def best_of(repeat, fn):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t)
    return min(times), times


def bench_overhead(size, repeat, tmp):
    heights = cs.surface(size, size, PIXEL, rms_height=50e-9, seed=3)
    npy = tmp / "s.npy"
    np.save(npy, heights)
    loads = ",".join(f"{f * 1e6:g}" for f in LOADS) + "uN"
    cli_args = [str(BIN), "simulate", "--topography", str(npy), "--pixel-size", "100nm",
                "--detrend", "none", "--radius", "20um", "--modulus", "1GPa",
                "--model", "hardening", "--hardening", "4MPa/nm", "--forces", loads, "-q"]

    def cli():
        out = tmp / f"sim-{time.monotonic_ns()}"
        subprocess.run(cli_args + ["--out", str(out)], check=True, capture_output=True)

    def py(maps):
        return lambda: cs.simulate(heights, PIXEL, MODULUS, LOADS, "hardening", k=4e15,
                                   radius=RADIUS, maps=maps)

    cli()  # warm the page cache
    t_cli, all_cli = best_of(repeat, cli)
    # Interleaved, so that a busy spell of a shared machine hits both alike.
    all_maps, all_py = [], []
    for _ in range(2 * repeat):
        all_py.append(best_of(1, py(False))[0])
        all_maps.append(best_of(1, py(True))[0])
    t_py_maps, t_py = min(all_maps), min(all_py)
    return {
        "grid": f"{size}x{size}", "loads": len(LOADS),
        "cli_wall_s": t_cli, "python_maps_s": t_py_maps, "python_no_maps_s": t_py,
        "overhead_vs_cli_pct": 100 * (t_py_maps / t_cli - 1),
        # What crossing the boundary costs: the maps as numpy arrays over the bare compute.
        "maps_over_compute_pct": 100 * (t_py_maps / t_py - 1),
        "all": {"cli": all_cli, "python_maps": all_maps, "python_no_maps": all_py},
    }


def _timed_ramp(h, k, threads):
    """One ramp where it runs (this process or a worker): its wall and CPU seconds."""
    distributed._threads(({}, threads))
    t, c = time.perf_counter(), time.process_time()
    cs.ramp(h, PIXEL, MODULUS, "hardening", k, LOADS, radius=RADIUS)
    return time.perf_counter() - t, time.process_time() - c


def bench_dask(size, repeat):
    """The targets of the Dask path, measured side by side in one run (best of ``repeat``):
    a ramp in a worker against the same ramp in this process with the same threads; a sweep
    on 1 and on 2 single-thread workers; the automatic cluster (``local_client()``: one
    worker per core) against the serial loop on all cores; identical results."""
    import dask
    from dask.distributed import Client, LocalCluster, get_task_stream

    heights = cs.surface(size, size, PIXEL, rms_height=50e-9, seed=4)
    kwargs = dict(family="hardening", values=K_VALUES, heights=heights, radius=RADIUS)

    def serial(threads):
        cs.set_num_threads(threads)
        try:
            return distributed.sweep(LOADS, PIXEL, MODULUS, client="serial", **kwargs)
        finally:
            cs.set_num_threads(0)

    reference = serial(0)
    # 1. One ramp (k = 4 MPa/nm), 1 thread: in this process, then inside a worker.
    here = sorted(_timed_ramp(heights, 4e15, 1)[0] for _ in range(repeat + 1))[:repeat]
    cs.set_num_threads(0)

    def sweep_on(n_workers):
        with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
            cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, host="127.0.0.1",
                                   dashboard_address="127.0.0.1:0")
        with cluster, Client(cluster) as client:
            h = client.scatter(heights, broadcast=True)
            inside = sorted(client.submit(_timed_ramp, h, 4e15, 1, pure=False).result()[0]
                            for _ in range(repeat + 1))[:repeat]
            # One thread per task, as the serial 1-thread loop (the automatic plan would give a
            # lone single-thread worker every core).
            one = dict(kwargs, threads_per_task=1)
            distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **one)  # warm
            t, _ = best_of(repeat, lambda: distributed.sweep(LOADS, PIXEL, MODULUS,
                                                             client=client, **one))
            with get_task_stream(client) as stream:
                rows = distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **one).rows
        ramps = [s["stop"] - s["start"] for task in stream.data for s in task["startstops"]
                 if s["action"] == "compute" and "_ramp_task" in task["key"]]
        return t, inside, rows, ramps

    def best_split(durations):
        """The shortest time two workers could finish these ramps in (every split tried)."""
        total, n = sum(durations), len(durations)
        return min(max(part, total - part) for part in (
            sum(d for i, d in enumerate(durations) if mask >> i & 1) for mask in range(2 ** n)))

    t_serial_1, _ = best_of(repeat, lambda: serial(1))
    t_serial_all, _ = best_of(repeat, lambda: serial(0))
    t_one, inside, rows_one, _ = sweep_on(1)
    t_two, _, rows_two, ramps_two = sweep_on(2)
    # 3. What a user gets without choosing: local_client() (one worker per core, threads
    # planned), the cluster already up; and client=None, which starts and stops one per call.
    with distributed.local_client() as client:
        distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **kwargs)
        t_auto, _ = best_of(repeat, lambda: distributed.sweep(LOADS, PIXEL, MODULUS,
                                                              client=client, **kwargs))
        workers = len(client.nthreads())
    t_none, _ = best_of(1, lambda: distributed.sweep(LOADS, PIXEL, MODULUS, **kwargs))
    same = all(np.array_equal(a["areas_m2"], b["areas_m2"])
               for rows in (rows_one, rows_two) for a, b in zip(rows, reference.rows))
    return {
        "grid": f"{size}x{size}", "ramps": len(K_VALUES), "loads_per_ramp": len(LOADS),
        "ramp_in_process_1_thread_s": min(here), "ramp_in_worker_1_thread_s": min(inside),
        "worker_over_process": min(inside) / min(here),
        "serial_1_thread_s": t_serial_1, "serial_all_cores_s": t_serial_all,
        "dask_1_worker_s": t_one, "dask_2_workers_s": t_two,
        "scaling_1_to_2_workers": t_one / t_two,
        # The ramps' lengths bound the scaling: their best split over two workers.
        "ramps_on_2_workers_s": ramps_two, "best_split_of_those_ramps_s": best_split(ramps_two),
        "scaling_bound_from_ramp_lengths": sum(ramps_two) / best_split(ramps_two),
        "auto_workers": workers, "dask_auto_s": t_auto,
        "serial_all_cores_over_dask_auto": t_serial_all / t_auto,
        "client_none_with_cluster_start_s": t_none,
        "identical_to_serial": same,
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--size", type=int, default=512, help="grid of the overhead benchmark")
    p.add_argument("--sweep-size", type=int, default=256, help="grid of the Dask sweep")
    p.add_argument("--dask-only", action="store_true", help="only the Dask benchmark")
    args = p.parse_args()
    if not args.dask_only:
        with tempfile.TemporaryDirectory() as d:
            overhead = bench_overhead(args.size, args.repeat, pathlib.Path(d))
        print(json.dumps({"overhead": overhead}, indent=1))
    dask = bench_dask(args.sweep_size, args.repeat)
    print(json.dumps({"dask": dask}, indent=1))
    print(f"os.cpu_count() = {os.cpu_count()}, load average {os.getloadavg()}")
    # The machine's own share of 2 cores: the sweep's 8 ramps in two plain processes at once
    # (no Dask) against one alone, three times: how much two concurrent ramps slow each other.
    one = ("import time, contactscope as cs; cs.set_num_threads(1); "
           f"h = cs.surface({args.sweep_size}, {args.sweep_size}, {PIXEL}, rms_height=50e-9, "
           "seed=4); "
           f"cs.ramp(h, {PIXEL}, {MODULUS}, 'hardening', 4e15, {LOADS}, radius={RADIUS}); "
           "t = time.perf_counter(); "
           f"[cs.ramp(h, {PIXEL}, {MODULUS}, 'hardening', k, {LOADS}, radius={RADIUS}) "
           f"for k in {K_VALUES}]; print(time.perf_counter() - t)")
    for _ in range(3):
        alone = float(subprocess.run([sys.executable, "-c", one], capture_output=True,
                                     text=True, check=True).stdout)
        pair = [subprocess.Popen([sys.executable, "-c", one], stdout=subprocess.PIPE, text=True)
                for _ in range(2)]
        together = max(float(p.communicate()[0]) for p in pair)
        print(json.dumps({"two_plain_processes": {
            "alone_s": alone, "two_at_once_s": together,
            "each_ramp_slower_when_two_run": together / alone,
            "parallel_speedup": 2 * alone / together}}))


if __name__ == "__main__":
    main()
