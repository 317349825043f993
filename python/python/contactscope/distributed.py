"""Parameter sweeps and fits whose load ramps run as Dask tasks.

Each task is one load ramp (a model at one parameter value on one surface) and returns the
ramp's contact areas (m²), not maps: Dask's per-task overhead (a few ms) stays small against
the ramp. Height maps are scattered to the workers once (``client.scatter(..., broadcast=True)``)
and every task refers to them. Surfaces given by seed are generated once each, on a worker, as
tasks of their own.

Threads: by default (``threads_per_task=None``) every worker's contactscope thread pool gets its
share of the cores it may use, so that all tasks together never use more threads than there are
cores (:func:`thread_plan`); with fewer tasks than Dask threads (one Brent step of a fit), each
task gets more. Once per worker process, the first task also resets glibc's malloc thresholds
that Dask's worker environment lowers (:func:`_tune_malloc`).

``client=None`` starts a loopback-only ``LocalCluster`` for the call (one single-thread worker
per core, at most one per task; every listener on 127.0.0.1) and closes it afterwards, or runs
the tasks in this process when there is only one task or one core; ``client="serial"`` runs the
same tasks in this process, one after the other (the reference the Dask results equal exactly).
``out=`` writes a sweep's table as the command line writes its folders: all files or none.

SI units: heights and lengths in m, forces in N, E* in Pa, hardness in Pa, k in Pa/m.
"""

from __future__ import annotations

import builtins
import contextlib
import csv
import ctypes
import io
import itertools
import json
import math
import os
import socket
import sys
from typing import (TYPE_CHECKING, Any, Callable, Dict, Iterator, List, Mapping, Optional,
                    Sequence, Tuple)

import numpy as np

from . import FitResults, Results, _cs, _f64

if TYPE_CHECKING:
    from .archive import BatchResult

__all__ = ["local_client", "sweep", "fit_hardening", "batch", "brent_minimum", "thread_plan"]

#: A misfit standing for an infeasible parameter in the Brent search (misfits are RMS log
#: ratios, of order 1), as in the library's own fit.
INFEASIBLE_MISFIT = 1e6

#: What a task is told about threads: ``None`` (leave this process's setting), or a pool size
#: per worker address with a default: threads per Dask thread for workers that joined later,
#: the pool size itself outside a worker.
Plan = Optional[Tuple[Mapping[str, int], int]]


def _cpus() -> int:
    """The cores this process may run on (its CPU affinity, where the system has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def _worker_facts() -> Dict[str, Any]:
    """Where a worker runs and how many cores it may use: its CPU affinity, within a Slurm job
    also no more than the job's CPUs on this node (``SLURM_CPUS_ON_NODE``). Runs on each worker
    (``client.run``)."""
    cpus = _cpus()
    allocated = os.environ.get("SLURM_CPUS_ON_NODE", "")
    if allocated.isdigit() and int(allocated) > 0:
        cpus = min(cpus, int(allocated))
    return {"host": socket.gethostname(), "job": os.environ.get("SLURM_JOB_ID"), "cpus": cpus}


def thread_plan(workers: Mapping[str, Mapping[str, Any]], tasks: int) -> Dict[str, int]:
    """The size of each worker's contactscope thread pool for ``tasks`` tasks that may run at
    once.

    ``workers`` maps a worker's address to ``host``, ``job`` (a Slurm job ID or ``None``),
    ``cpus`` (cores it may use) and ``nthreads`` (Dask threads, i.e. tasks it runs at once).
    Workers on one host in one job (or outside any job) share that host's cores: with
    ``running = min(their Dask threads, tasks)`` tasks at once, each task is worth
    ``cpus / running`` threads, and a worker's pool, shared by the tasks it runs, gets
    ``cpus × min(nthreads, tasks) // running`` (at least 1). So two single-thread workers on 2
    cores get 1 thread each for a sweep and 2 each for a lone task (a Brent step); a 4-thread
    worker in a 4-core Slurm job gets a pool of 4 shared by its 4 tasks. While as many tasks
    run as the group has Dask threads, the threads in use never exceed its cores.
    """
    tasks = max(1, int(tasks))
    groups: Dict[Tuple[str, Any], Dict[str, Any]] = {}
    for w in workers.values():
        g = groups.setdefault((w["host"], w.get("job")), {"cpus": int(w["cpus"]), "threads": 0})
        g["cpus"] = min(g["cpus"], int(w["cpus"]))
        g["threads"] += int(w["nthreads"])
    plan = {}
    for address, w in workers.items():
        g = groups[(w["host"], w.get("job"))]
        running = max(1, min(g["threads"], tasks))
        plan[address] = max(1, g["cpus"] * min(int(w["nthreads"]), tasks) // running)
    return plan


class _Threads:
    """Thread plans for one client: the workers' facts asked once, a plan per phase."""

    def __init__(self, ex: Any, threads_per_task: Optional[int]) -> None:
        self.fixed = threads_per_task
        self.workers: Optional[Dict[str, Dict[str, Any]]] = None
        if isinstance(ex, _Serial):
            return
        nthreads = ex.nthreads()
        if threads_per_task is None:
            facts = ex.run(_worker_facts)
            self.workers = {a: {**f, "nthreads": nthreads.get(a, 1)} for a, f in facts.items()}
        else:
            self.workers = {a: {"nthreads": n} for a, n in nthreads.items()}

    def plan(self, tasks: int) -> Plan:
        if self.workers is None:  # in this process
            return None if self.fixed is None else ({}, int(self.fixed))
        if self.fixed is not None:
            n = max(1, int(self.fixed))
            return ({a: n * int(w["nthreads"]) for a, w in self.workers.items()}, n)
        return (thread_plan(self.workers, tasks), 1)


def _pool_size(plan: Plan) -> Optional[int]:
    """The pool size a task sets: its worker's entry in the plan; for a worker that joined after
    the plan was made, the plan's default per Dask thread of that worker (so that a worker
    running several tasks at once never squeezes them onto one thread); outside a worker, the
    default itself."""
    if plan is None:
        return None
    sizes, default = plan
    try:
        from distributed import get_worker

        worker = get_worker()
    except (ImportError, ValueError):  # not in a Dask worker
        return default
    if worker.address in sizes:
        return sizes[worker.address]
    return default * max(1, int(worker.state.nthreads))


def _threads(plan: Plan) -> None:
    _tune_malloc()
    n = _pool_size(plan)
    if n is not None and _cs.get_num_threads() != n:
        _cs.set_num_threads(n)


#: glibc malloc thresholds (bytes) that a task sets in a Dask worker process: allocations up to
#: 32 MiB come from the heap, and free memory is returned to the system once 128 MiB of it lie
#: at the heap's top.
MMAP_THRESHOLD = 32 << 20
TRIM_THRESHOLD = 128 << 20
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3  # glibc's mallopt parameters
_malloc_tuned = False


def _tune_malloc() -> bool:
    """Undo, once per process, what Dask's worker environment does to large allocations.

    Dask starts its worker processes with ``MALLOC_TRIM_THRESHOLD_=65536``
    (``distributed.nanny.pre-spawn-environ``), to hand freed memory back to the system early.
    Setting that variable also fixes glibc's mmap threshold at 128 KiB: every solver field and
    FFT buffer above it is then a fresh ``mmap`` whose pages fault in again at every load.
    Measured on the project's 2-core machine, one thread, a 512² hardening ramp (4/40/400 mN)
    three times in one process: with the variable 61 000 minor page faults and 1.72–1.90 s per
    ramp; after these thresholds are set, at most 510 faults and 1.55–1.62 s; a plain process
    without the variable, 2 600–8 200 faults and 1.44–1.72 s. Only where the variable is set (a
    Dask worker, or a process started like one) and only on Linux with glibc; returns whether
    the thresholds were set.
    """
    global _malloc_tuned
    if _malloc_tuned or sys.platform != "linux" or "MALLOC_TRIM_THRESHOLD_" not in os.environ:
        return False
    _malloc_tuned = True
    try:
        libc = ctypes.CDLL("libc.so.6")
        return bool(libc.mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)
                    and libc.mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))
    except (OSError, AttributeError):  # not glibc
        return False


def _ramp_task(heights: np.ndarray, pixel_size: Any, modulus: float, family: str,
               parameter: Optional[float], loads: List[float], radius: Optional[float],
               tolerance: float, max_iterations: int, imaging_fwhm: Optional[float],
               imaging_pixel_size: Any, threads: Plan,
               device: str = "cpu") -> Dict[str, Any]:
    """One load ramp on a worker: areas (m²) and whether contact reached the map's border.
    A parameter the ramp cannot be solved with gives ``error`` (its message) in place of
    areas: an infeasible one (e.g. a hardness too low for the load) or one the solver does not
    converge for within ``max_iterations`` (:class:`contactscope.ConvergenceError`), or a
    ``device="cuda"`` the worker has no usable GPU for."""
    _threads(threads)
    try:
        r = _cs.ramp(heights, pixel_size, modulus, family, parameter, loads, radius, tolerance,
                     max_iterations, imaging_fwhm, imaging_pixel_size, device=device)
    except ValueError as e:  # InputError and ConvergenceError
        return {"areas_m2": None, "edge_contact": False, "error": str(e)}
    return {"areas_m2": np.asarray(r["areas_m2"]), "edge_contact": r["edge_contact"],
            "error": None}


def _surface_task(spec: Dict[str, Any], seed: int, threads: Plan) -> np.ndarray:
    _threads(threads)
    return _cs.surface(spec["nx"], spec["ny"], spec["pixel_size"], spec.get("hurst"),
                       spec.get("rms_height"), spec.get("rms_slope"), spec.get("rolloff"),
                       spec.get("cutoff"), int(seed))["heights"]


@contextlib.contextmanager
def local_client(n_workers: Optional[int] = None,
                 threads_per_worker: int = 1) -> Iterator[Any]:
    """A ``dask.distributed`` client on a new loopback-only ``LocalCluster`` (every listener,
    the dashboard included, on 127.0.0.1), closed on exit. ``n_workers`` defaults to one
    single-thread worker per core this process may use."""
    import dask
    from dask.distributed import Client, LocalCluster

    if n_workers is None:
        n_workers = max(1, _cpus() // max(1, threads_per_worker))
    # One queued task per Dask thread: the default (1.1) lets a single-thread worker hold a
    # second ramp while another worker has none left at a sweep's end.
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
        cluster = LocalCluster(n_workers=n_workers, threads_per_worker=threads_per_worker,
                               host="127.0.0.1", dashboard_address="127.0.0.1:0",
                               processes=True)
    client = Client(cluster)
    try:
        yield client
    finally:
        _close_quietly(client, cluster)


def _close_quietly(client: Any, cluster: Any) -> None:
    """Shut a local cluster down with no task left running (a worker still computing when its
    scheduler goes away logs heartbeat errors and ``CommClosedError`` tracebacks), the client
    first, then the cluster, which stops its workers before its scheduler."""
    try:
        client.cancel(list(client.futures.values()), force=True)
    except Exception:  # noqa: BLE001 - best effort: closing below still happens
        pass
    client.close()
    cluster.close()


class _Serial:
    """The same tasks in this process, in order: the reference for the Dask path. With
    ``report`` set (``progress=True``), each ramp done is a line on stderr."""

    def __init__(self) -> None:
        self.report = False
        self.ramps = 0
        self.expected: Optional[int] = None

    def scatter(self, value: Any, **_: Any) -> Any:
        return value

    def submit(self, fn: Callable, *args: Any, **_: Any) -> Any:
        # Results of earlier tasks stand for their values, as Dask futures do.
        done = _Done(fn(*(a.value if isinstance(a, _Done) else a for a in args)))
        if self.report and fn in (_ramp_task, _batch_task):
            self.ramps += 1
            of = f" of {self.expected}" if self.expected else ""
            what = "ramp" if fn is _ramp_task else "series"
            print(f"contactscope: {what} {self.ramps}{of} done", file=sys.stderr, flush=True)
        return done

    def gather(self, futures: Sequence[Any]) -> List[Any]:
        return [f.result() for f in futures]


class _Done:
    def __init__(self, value: Any) -> None:
        self.value = value

    def result(self) -> Any:
        return self.value


@contextlib.contextmanager
def _executor(client: Any, tasks: int, threads_per_task: Optional[int]) -> Iterator[Any]:
    """The executor of ``client`` (module docs); ``tasks``: how many can run at once."""
    if (isinstance(client, str) and client == "serial") or (client is None
                                                             and min(_cpus(), tasks) <= 1):
        before = _cs.get_num_threads()
        try:
            yield _Serial()
        finally:
            if threads_per_task is not None:
                _cs.set_num_threads(before)
    elif client is None:
        with local_client(n_workers=min(_cpus(), tasks)) as c:
            yield c
    else:
        yield client


def _pure(client: Any) -> Dict[str, Any]:
    # Dask would merge identical submissions (same arguments): that is right for these pure
    # tasks, and the serial executor ignores it.
    return {} if isinstance(client, _Serial) else {"pure": True}


class _Progress:
    """Progress, when asked for. On Dask: the dashboard's address once, then Dask's own progress
    bar per batch of tasks (text in a terminal, a widget in a notebook). In this process: a line
    per ramp done."""

    def __init__(self, ex: Any, on: bool) -> None:
        self.ex = ex
        self.serial = isinstance(ex, _Serial)
        self.on = on
        if on and self.serial:
            ex.report = True
        elif on:
            link = getattr(ex, "dashboard_link", None)
            if link:
                print(f"contactscope: Dask dashboard at {link}", file=sys.stderr, flush=True)

    def expect(self, ramps: Optional[int]) -> None:
        """The number of ramps the next batch holds (``None``: one at a time)."""
        if self.serial:
            self.ex.expected = ramps
            self.ex.ramps = 0

    def __call__(self, futures: Sequence[Any]) -> None:
        if self.on and not self.serial and futures:
            from dask.distributed import progress

            progress(list(futures))

    def note(self, message: str) -> None:
        if self.on:
            print(f"contactscope: {message}", file=sys.stderr, flush=True)


def sweep(loads: Sequence[float], pixel_size: Any, modulus: float, *,
          family: str = "hardening", values: Sequence[Optional[float]] = (None,),
          heights: Any = None, surfaces: Optional[Sequence[Any]] = None,
          surface_spec: Optional[Dict[str, Any]] = None, seeds: Sequence[int] = (),
          radius: Optional[float] = None, tolerance: float = 1e-8,
          max_iterations: int = 5000, imaging_fwhm: Optional[float] = None,
          imaging_pixel_size: Any = None, client: Any = None,
          threads_per_task: Optional[int] = None, progress: bool = False,
          out: Any = None, device: str = "cpu") -> Results:
    """Load ramps over a parameter grid, one Dask task per ramp.

    The grid is every combination of a model parameter in ``values`` (k in Pa/m for
    "hardening", p_Y in Pa for "hardness", ``None`` for "elastic" and "gt") with a surface:
    ``heights`` (one map, m), ``surfaces`` (several maps), and/or ``seeds`` of self-affine
    surfaces described by ``surface_spec`` (keyword arguments of :func:`contactscope.surface`:
    ``nx``, ``ny``, ``pixel_size`` in m, ``hurst``, ``rms_height`` in m, …). Every surface is
    pressed at ``loads`` (N) with a sphere of ``radius`` m on a flat of E* ``modulus`` Pa.

    ``threads_per_task``: contactscope threads per running task (a worker's pool gets this
    times its Dask threads); ``None`` shares each machine's cores among its workers
    (:func:`thread_plan`). ``progress``: print the Dask dashboard's address and show Dask's
    progress bar. ``out``: a folder to write ``sweep.csv`` (one row per ramp and load, units in
    the column names) and ``sweep.json`` into, as the command line writes its folders — only
    once every ramp is back, all files or none. ``device``: where each worker solves its ramps,
    ``"cpu"``, ``"cuda"`` (a worker without a usable GPU gives its rows that error) or
    ``"auto"`` (its GPU where it has one), as :func:`contactscope.simulate`.

    Returns ``rows`` (per ramp: ``surface``, ``seed``, ``family``, ``parameter``, ``areas_m2``,
    ``edge_contact``, ``error``) in grid order; ``to_pandas()`` gives one row per ramp and load.
    A ramp that cannot be solved (infeasible, or not converged) has ``areas_m2`` ``None`` and
    its message in ``error``; the other rows are complete.
    """
    loads = [float(f) for f in loads]
    maps: List[Any] = []
    labels: List[Dict[str, Any]] = []
    if heights is not None:
        maps.append(_f64(heights, 2, "heights"))
        labels.append({"surface": 0, "seed": None})
    for s in surfaces or ():
        labels.append({"surface": len(maps), "seed": None})
        maps.append(_f64(s, 2, "surface"))
    if seeds and not surface_spec:
        raise _cs.InputError("seeds need surface_spec (nx, ny, pixel_size, rms_height, …)")
    if not maps and not seeds:
        raise _cs.InputError("give heights, surfaces or seeds with surface_spec")
    values = list(values)
    _check_device(device)
    if out is not None:  # refused before any ramp runs, as the final write would refuse it
        _cs.check_out_folder(os.fspath(out))
    n_ramps = (len(maps) + len(seeds)) * len(values)
    with _executor(client, n_ramps, threads_per_task) as ex:
        threads = _Threads(ex, threads_per_task)
        show = _Progress(ex, progress)
        futures = [ex.scatter(m, broadcast=True, hash=False) for m in maps]
        for seed in seeds:
            labels.append({"surface": len(futures), "seed": int(seed)})
            futures.append(ex.submit(_surface_task, dict(surface_spec or {}), int(seed),
                                     threads.plan(len(seeds)), **_pure(ex)))
        tasks = []
        grid = list(itertools.product(range(len(futures)), values))
        plan = threads.plan(len(grid))
        show.expect(len(grid))
        for surface, value in grid:
            tasks.append(ex.submit(_ramp_task, futures[surface], pixel_size, float(modulus),
                                   family, None if value is None else float(value), loads,
                                   radius, tolerance, max_iterations, imaging_fwhm,
                                   imaging_pixel_size, plan, device, **_pure(ex)))
        show(tasks)
        outcomes = ex.gather(tasks)
    rows = []
    for (surface, value), result in zip(grid, outcomes):
        rows.append({**labels[surface], "family": family,
                     "parameter": None if value is None else float(value),
                     "loads_n": loads, **result})
    results = _SweepResults(rows=rows)
    if out is not None:
        _write_sweep(out, results, modulus=float(modulus), radius=radius, device=device)
    return results


def _batch_task(task: str, threads: Plan) -> str:
    """One series of a batch on a worker: its folders, thumbnail and record written into the
    batch's folder (which the workers share), the record returned as JSON."""
    _threads(threads)
    return _cs.batch_series(task)


def batch(samplesheet: Any, out: Any, *, client: Any = None, base: Any = None,
          patterns: Optional[Sequence[str]] = None, tiff_folders: bool = False,
          rerun: str = "changed", color_by: Optional[str] = None, overlays: bool = False,
          save_masks: bool = False, memory_mib: int = 128, device: str = "cpu",
          threads_per_task: Optional[int] = None, progress: bool = False,
          **options: Any) -> "BatchResult":
    """:func:`contactscope.batch` with one Dask task per series: the same folder, and the same
    tables byte for byte as the command line's ``contactscope batch`` over the same
    samplesheet. The plan (the samplesheet checked, the folder taken, which series changed) and
    the tables are made here; each series to do runs on a worker, which writes its folders,
    thumbnail and record into ``out`` — the workers must see the same file system (a local
    cluster, or a Slurm cluster's shared disk). Paths are made absolute first, so that workers
    started in another folder find the inputs; the ``input`` column keeps the samplesheet's own
    text (a folder walk's ``input`` is then the absolute path).

    ``client``, ``threads_per_task`` and ``progress`` as in :func:`sweep`; the other arguments
    as :func:`contactscope.batch`. A worker lost in the middle of a series loses nothing: Dask
    runs the task again, which rewrites the series' folders whole.
    """
    from .archive import BatchResult, _request

    if not (hasattr(samplesheet, "to_csv") and hasattr(samplesheet, "columns")):
        samplesheet = os.path.abspath(os.fspath(samplesheet))
    if base is not None:
        base = os.path.abspath(os.fspath(base))
    elif hasattr(samplesheet, "to_csv"):
        base = os.getcwd()
    request = _request(samplesheet, os.path.abspath(os.fspath(out)), base, patterns,
                       tiff_folders, rerun, color_by, overlays, save_masks, memory_mib, device,
                       options, "contactscope.distributed.batch")
    plan = _cs.batch_plan(**request)
    tasks = plan.tasks()
    with _executor(client, len(tasks), threads_per_task) as ex:
        threads = _Threads(ex, threads_per_task)
        show = _Progress(ex, progress)
        total, reused = plan.counts()
        show.note(f"batch: {total} series, {len(tasks)} to analyse, {reused} unchanged")
        show.expect(len(tasks))
        per_task = threads.plan(len(tasks))
        # Not pure: a task writes files, and Dask must run each one (none is a duplicate).
        futures = [ex.submit(_batch_task, task, per_task, pure=False) for task in tasks]
        show(futures)
        records = ex.gather(futures)
    return BatchResult(plan.finish(records))


def _parameter_column(family: str) -> Tuple[Optional[str], float]:
    """The CSV column of a family's parameter and the factor from SI to its unit."""
    if family == "hardening":
        return "k_MPa_per_nm", 1e-15
    if family == "hardness":
        return "hardness_MPa", 1e-6
    return None, 1.0


# The SI name of each lab-unit column of sweep.csv: to_pandas() has the same columns, in SI.
_SI_COLUMNS = {"k_MPa_per_nm": "k_pa_per_m", "hardness_MPa": "hardness_pa",
               "force_mN": "force_n", "area_um2": "area_m2"}


def _check_device(device: str) -> None:
    if device not in ("cpu", "cuda", "auto"):
        raise _cs.InputError(f"device '{device}' is not one of cpu, cuda, auto")


def _write_sweep(out: Any, results: "_SweepResults", modulus: float,
                 radius: Optional[float], device: str) -> None:
    """``sweep.csv`` and ``sweep.json`` in lab units (mN, µm², MPa/nm), written as one folder."""
    rows = results["rows"]
    name, factor = _parameter_column(rows[0]["family"] if rows else "elastic")
    text = io.StringIO()
    table = csv.writer(text, lineterminator="\n")
    table.writerow(["surface", "seed", "model"] + ([name] if name else [])
                   + ["force_mN", "area_um2", "edge_contact", "error"])
    records = []
    for r in rows:
        parameter = [] if name is None else [repr(r["parameter"] * factor)]
        areas = r["areas_m2"]
        for i, f in enumerate(r["loads_n"]):
            area = "" if areas is None else repr(float(areas[i]) * 1e12)
            table.writerow([r["surface"], "" if r["seed"] is None else r["seed"], r["family"]]
                           + parameter + [repr(f * 1e3), area,
                                          str(bool(r["edge_contact"])).lower(), r["error"] or ""])
        record = {"surface": r["surface"], "seed": r["seed"], "model": r["family"]}
        if name is not None:
            record[name] = r["parameter"] * factor
        record.update({"areas_um2": None if areas is None else [float(a) * 1e12 for a in areas],
                       "edge_contact": bool(r["edge_contact"]), "error": r["error"]})
        records.append(record)
    summary = {"loads_mN": [f * 1e3 for f in rows[0]["loads_n"]] if rows else [],
               "contact_modulus_GPa": modulus * 1e-9,
               "radius_um": None if radius is None else radius * 1e6,
               "device": device, "ramps": len(rows),
               "failed": sum(r["error"] is not None for r in rows),
               "rows": records}
    _cs.write_folder(os.fspath(out), [("sweep.csv", text.getvalue().encode()),
                                      ("sweep.json", (json.dumps(summary, indent=1) + "\n")
                                       .encode())])


class _SweepResults(Results):
    def to_pandas(self):
        """One row per ramp and load with the columns of ``sweep.csv`` in SI units (``model``,
        ``k_pa_per_m`` or ``hardness_pa`` where ``sweep.csv`` has ``k_MPa_per_nm`` or
        ``hardness_MPa``, ``force_n``, ``area_m2``, ``edge_contact``, ``error``)."""
        import pandas as pd

        records = []
        for r in self["rows"]:
            name, _ = _parameter_column(r["family"])
            areas = r["areas_m2"] if r["areas_m2"] is not None else [math.nan] * len(r["loads_n"])
            for f, a in zip(r["loads_n"], areas):
                record = {"surface": r["surface"], "seed": r["seed"], "model": r["family"]}
                if name is not None:
                    record[_SI_COLUMNS[name]] = r["parameter"]
                record.update({"force_n": f, "area_m2": a, "edge_contact": r["edge_contact"],
                               "error": r["error"]})
                records.append(record)
        return pd.DataFrame(records)


def brent_minimum(f: Callable[[float], float], lo: float, hi: float, tol: float,
                  max_iter: int = 200) -> float:
    """The minimum of ``f`` on [lo, hi] to an absolute tolerance ``tol`` in x, by Brent's method
    (golden section with parabolic steps; R. P. Brent, *Algorithms for Minimization without
    Derivatives*, 1973, ch. 5). One evaluation at a time: each is one Dask task."""
    c = 0.5 * (3.0 - math.sqrt(5.0))
    a, b = lo, hi
    x = w = v = a + c * (b - a)
    fx = fw = fv = f(x)
    d = e = 0.0
    for _ in range(max_iter):
        m = 0.5 * (a + b)
        tol1 = tol
        tol2 = 2.0 * tol1
        if abs(x - m) <= tol2 - 0.5 * (b - a):
            break
        parabolic = False
        if abs(e) > tol1:
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            e_old, e = e, d
            if abs(p) < abs(0.5 * q * e_old) and q * (a - x) < p < q * (b - x):
                d = p / q
                u = x + d
                if (u - a) < tol2 or (b - u) < tol2:
                    d = tol1 if x < m else -tol1
                parabolic = True
        if not parabolic:
            e = (b - x) if x < m else (a - x)
            d = c * e
        u = x + (d if abs(d) >= tol1 else math.copysign(tol1, d if d != 0 else 1.0))
        fu = f(u)
        if fu <= fx:
            if u < x:
                b = x
            else:
                a = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
    return x


def fit_hardening(forces: Sequence[float], areas: Sequence[float], heights: Any,
                  pixel_size: Any, modulus: float, *, radius: Optional[float] = None,
                  family: str = "hardening", range: Optional["tuple[float, float]"] = None,
                  grid: Optional[int] = None, ln_tolerance: Optional[float] = None,
                  tolerance: Optional[float] = None, max_iterations: Optional[int] = None,
                  imaging_fwhm: Optional[float] = None, imaging_pixel_size: Any = None,
                  client: Any = None, threads_per_task: Optional[int] = None,
                  progress: bool = False, device: str = "cpu") -> FitResults:
    """:func:`contactscope.fit_hardening` with every model evaluation (one load ramp) a Dask task.

    The same search as the library's: a log-spaced grid of ``grid`` values over ``range``
    (k in Pa/m, default 1e14–1e17; p_Y in Pa, default 1e7–1e10) evaluated in parallel, then
    Brent's method on ln(parameter) between the best grid point's neighbours down to
    ``ln_tolerance``, then the Gauss–Newton standard error from two more ramps (in parallel).
    Misfit: RMS of ln(A_sim/A_exp) (forces in N, areas in m²). "elastic" and "gt" are one ramp.
    The result equals the serial path (``client="serial"``) exactly; it agrees with the
    library's own fit to the search tolerance (their Brent implementations differ in detail).
    ``threads_per_task``, ``progress`` and ``device`` as for :func:`sweep` (the grid's ramps
    share the cores, each Brent step, a lone task, gets all of its worker's share). Returns a
    :class:`contactscope.FitResults` with one model (no ``measured`` or ``roughness``: the
    tasks see only the ramps).
    """
    grid = 7 if grid is None else grid
    ln_tolerance = 0.01 if ln_tolerance is None else ln_tolerance
    forces = [float(f) for f in forces]
    areas = [float(a) for a in areas]
    if len(forces) != len(areas):
        raise _cs.InputError(f"{len(forces)} forces for {len(areas)} areas")
    pts = sorted(zip(forces, areas))
    fs = [p[0] for p in pts]
    ms = [p[1] for p in pts]
    # Validates the measured points (at least 2, positive) exactly as the library does.
    _cs.misfit(fs, ms, ms)
    if grid < 3:
        raise _cs.InputError(f"a search grid needs at least 3 points; got {grid}")
    has_parameter = family in ("hardening", "hardness")
    if family not in ("hardening", "hardness", "elastic", "gt"):
        raise _cs.InputError(f"model '{family}' is not one of elastic, gt, hardness, hardening")
    lo, hi = range or ((1e7, 1e10) if family == "hardness" else (1e14, 1e17))
    if not (0 < lo < hi < math.inf):
        raise _cs.InputError(f"search range {lo:e}..{hi:e} is not usable")
    h = _f64(heights, 2, "heights")
    _check_device(device)

    with _executor(client, grid if has_parameter else 1, threads_per_task) as ex:
        threads = _Threads(ex, threads_per_task)
        show = _Progress(ex, progress)
        body = ex.scatter(h, broadcast=True, hash=False)

        def submit(parameter: Optional[float], plan: Plan) -> Any:
            return ex.submit(_ramp_task, body, pixel_size, float(modulus), family, parameter,
                             fs, radius, tolerance, max_iterations, imaging_fwhm,
                             imaging_pixel_size, plan, device, **_pure(ex))

        def score(out: Dict[str, Any]) -> float:
            if out["error"] is not None:
                return math.inf
            return _cs.misfit(fs, ms, list(out["areas_m2"]))

        if not has_parameter:
            out = submit(None, threads.plan(1)).result()
            if out["error"] is not None:
                raise _cs.InputError(out["error"])
            return _fit_results(family, None, None, score(out), out["areas_m2"], [], False)

        a, b = math.log(lo), math.log(hi)
        xs = [a + (b - a) * i / (grid - 1) for i in builtins.range(grid)]
        show.note(f"{family} fit: {grid} ramps over the search grid")
        plan = threads.plan(grid)
        show.expect(grid)
        pending = [submit(math.exp(x), plan) for x in xs]
        show(pending)
        grid_out = ex.gather(pending)
        values = [score(o) for o in grid_out]
        if all(math.isinf(v) for v in values):
            first = next((o["error"] for o in grid_out if o["error"]), "no feasible value")
            raise _cs.InputError(first)
        trace = [(math.exp(x), v) for x, v in zip(xs, values) if math.isfinite(v)]
        best = min(builtins.range(len(values)), key=lambda i: values[i])
        at_edge = best in (0, len(values) - 1)
        x0, x1 = xs[max(best - 1, 0)], xs[min(best + 1, len(xs) - 1)]
        alone = threads.plan(1)
        unit, factor = _parameter_column(family)
        show.expect(None)

        def cost(x: float) -> float:
            m = score(submit(math.exp(x), alone).result())
            show.note(f"Brent step: {unit} = {math.exp(x) * factor:.6g}, misfit {m:.6g}")
            if math.isfinite(m):
                trace.append((math.exp(x), m))
                return m
            return INFEASIBLE_MISFIT

        ln_best = brent_minimum(cost, x0, x1, ln_tolerance / 4.0)
        step = 0.05
        plan = threads.plan(3)
        show.note("the best value and the two ramps of its standard error")
        show.expect(3)
        pending = [submit(math.exp(ln_best), plan), submit(math.exp(ln_best - step), plan),
                   submit(math.exp(ln_best + step), plan)]
        show(pending)
        final, minus, plus = ex.gather(pending)
    if final["error"] is not None:
        raise _cs.InputError(final["error"])
    best_areas = list(final["areas_m2"])
    se = None
    if len(fs) >= 2 and minus["error"] is None and plus["error"] is None:
        jac = [(math.log(max(p, 1e-300)) - math.log(max(q, 1e-300))) / (2 * step)
               for q, p in zip(minus["areas_m2"], plus["areas_m2"])]
        jtj = sum(j * j for j in jac)
        if jtj > 0:
            res = [math.log(max(s, 0.01 * e) / e) for s, e in zip(best_areas, ms)]
            s2 = sum(r * r for r in res) / (len(fs) - 1)
            se = math.exp(ln_best) * math.sqrt(s2 / jtj)
    return _fit_results(family, math.exp(ln_best), se, score(final), final["areas_m2"], trace,
                        at_edge)


def _fit_results(family: str, parameter: Optional[float], se: Optional[float], misfit: float,
                 areas_m2: Any, trace: List[Any], at_edge: bool) -> FitResults:
    """One fitted model in the shape of :func:`contactscope.fit_hardening`'s result."""
    model: Dict[str, Any] = {"model": family, "misfit_rms_ln_area": misfit,
                             "areas_m2": list(areas_m2), "evaluations": len(trace),
                             "at_range_edge": at_edge, "trace": trace}
    if parameter is not None:
        key = "hardness_pa" if family == "hardness" else "k_pa_per_m"
        model[key] = parameter
        model[key + "_se"] = se
    return FitResults(models=[model], best_model=family, warnings=[])

