"""Benchmarks of the Python package (issue 13's performance targets; measured, never asserted).

1. Call overhead: `cs.simulate` on a 512² map (4 loads, hardening) against the command line's
   `simulate` on the same .npy (its wall time, which also writes the maps and the plot), and
   the same call with the 16 maps returned as numpy arrays against `maps=False` (the bare
   compute): target ≤ 5 % over the compute.
2. Dask: a sweep of 8 k values (one load ramp each) on LocalCluster(n_workers=2,
   threads_per_worker=1) against the serial loop of the same ramps, target ≥ 1.7×.

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


def bench_dask(size, repeat):
    heights = cs.surface(size, size, PIXEL, rms_height=50e-9, seed=4)
    kwargs = dict(family="hardening", values=K_VALUES, heights=heights, radius=RADIUS)

    def serial(threads):
        cs.set_num_threads(threads)
        try:
            return distributed.sweep(LOADS, PIXEL, MODULUS, client="serial", **kwargs)
        finally:
            cs.set_num_threads(0)

    t_serial_1, _ = best_of(repeat, lambda: serial(1))
    t_serial_all, _ = best_of(repeat, lambda: serial(0))
    from dask.distributed import get_task_stream

    with distributed.local_client(n_workers=2, threads_per_worker=1) as client:
        distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **kwargs)  # warm the workers
        t_dask, all_dask = best_of(
            repeat, lambda: distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **kwargs))
        # How busy the workers were: compute time of the ramps over 2 × the wall time. On an
        # idle machine the speed-up over the 1-thread serial loop is about 2 × this.
        with get_task_stream(client) as stream:
            t = time.perf_counter()
            distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **kwargs)
            wall = time.perf_counter() - t
        busy = sum(s["stop"] - s["start"] for task in stream.data
                   for s in task["startstops"] if s["action"] == "compute"
                   and "_ramp_task" in task["key"])
        same = [np.array_equal(a["areas_m2"], b["areas_m2"]) for a, b in zip(
            distributed.sweep(LOADS, PIXEL, MODULUS, client=client, **kwargs).rows,
            serial(1).rows)]
    return {
        "grid": f"{size}x{size}", "ramps": len(K_VALUES), "loads_per_ramp": len(LOADS),
        "serial_1_thread_s": t_serial_1, "serial_all_cores_s": t_serial_all,
        "dask_2_workers_s": t_dask,
        "speedup_vs_serial_1_thread": t_serial_1 / t_dask,
        "speedup_vs_serial_all_cores": t_serial_all / t_dask,
        "identical_to_serial": all(same), "all_dask": all_dask,
        "ramp_compute_s_on_workers": busy, "worker_utilisation": busy / (2 * wall),
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--size", type=int, default=512, help="grid of the overhead benchmark")
    p.add_argument("--sweep-size", type=int, default=256, help="grid of the Dask sweep")
    args = p.parse_args()
    with tempfile.TemporaryDirectory() as d:
        overhead = bench_overhead(args.size, args.repeat, pathlib.Path(d))
    print(json.dumps({"overhead": overhead}, indent=1))
    dask = bench_dask(args.sweep_size, args.repeat)
    print(json.dumps({"dask": dask}, indent=1))
    print(f"os.cpu_count() = {os.cpu_count()}, load average {os.getloadavg()}")
    # The machine's own share of 2 cores: the same ramps in two plain processes at once.
    one = ("import time, contactscope as cs; cs.set_num_threads(1); "
           f"h = cs.surface({args.sweep_size}, {args.sweep_size}, {PIXEL}, rms_height=50e-9, "
           "seed=4); t = time.perf_counter(); "
           f"[cs.ramp(h, {PIXEL}, {MODULUS}, 'hardening', k, {LOADS}, radius={RADIUS}) "
           f"for k in {K_VALUES[:4]}]; print(time.perf_counter() - t)")
    alone = float(subprocess.run([sys.executable, "-c", one], capture_output=True, text=True,
                                 check=True).stdout)
    pair = [subprocess.Popen([sys.executable, "-c", one], stdout=subprocess.PIPE, text=True)
            for _ in range(2)]
    together = max(float(p.communicate()[0]) for p in pair)
    print(json.dumps({"two_plain_processes": {"alone_s": alone, "two_at_once_s": together,
                                               "parallel_speedup": 2 * alone / together}}))


if __name__ == "__main__":
    main()
