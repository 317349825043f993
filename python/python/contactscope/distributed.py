"""Parameter sweeps and fits whose load ramps run as Dask tasks.

Each task is one load ramp (a model at one parameter value on one surface) and returns the
ramp's contact areas (m²), not maps: Dask's per-task overhead (a few ms) stays small against
the ramp. Height maps are scattered to the workers once (``client.scatter(..., broadcast=True)``)
and every task refers to them. Surfaces given by seed are generated once each, on a worker, as
tasks of their own.

Every task first sets contactscope's thread count on its worker (``threads_per_task``, default
the worker's share: 1 for ``LocalCluster(n_workers=2, threads_per_worker=1)``), so that the
workers' parallel loops do not oversubscribe the cores, and, once per worker process, glibc's
malloc thresholds that Dask's worker environment lowers (:func:`_tune_malloc`: a 512² ramp
took 1.60–1.77 s in a one-thread worker without them, 1.41–1.42 s with them).

``client=None`` starts a loopback-only ``LocalCluster(n_workers=2, threads_per_worker=1,
host="127.0.0.1", dashboard_address="127.0.0.1:0")`` for the call and closes it afterwards;
``client="serial"`` runs the same tasks in this process, one after the other (the reference the
Dask results equal exactly).

SI units: heights and lengths in m, forces in N, E* in Pa, hardness in Pa, k in Pa/m.
"""

from __future__ import annotations

import builtins
import contextlib
import ctypes
import itertools
import math
import os
import sys
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence

import numpy as np

from . import FitResults, Results, _cs, _f64

__all__ = ["local_client", "sweep", "fit_hardening", "brent_minimum"]

#: A misfit standing for an infeasible parameter in the Brent search (misfits are RMS log
#: ratios, of order 1), as in the library's own fit.
INFEASIBLE_MISFIT = 1e6


def _threads(n: int) -> None:
    _tune_malloc()
    if _cs.get_num_threads() != n:
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
               imaging_pixel_size: Any, threads: int) -> Dict[str, Any]:
    """One load ramp on a worker: areas (m²) and whether contact reached the map's border.
    An infeasible parameter (e.g. a hardness too low for the load) gives ``error``."""
    _threads(threads)
    try:
        r = _cs.ramp(heights, pixel_size, modulus, family, parameter, loads, radius, tolerance,
                     max_iterations, imaging_fwhm, imaging_pixel_size)
    except ValueError as e:
        return {"areas_m2": None, "edge_contact": False, "error": str(e)}
    return {"areas_m2": np.asarray(r["areas_m2"]), "edge_contact": r["edge_contact"],
            "error": None}


def _surface_task(spec: Dict[str, Any], seed: int, threads: int) -> np.ndarray:
    _threads(threads)
    return _cs.surface(spec["nx"], spec["ny"], spec["pixel_size"], spec.get("hurst"),
                       spec.get("rms_height"), spec.get("rms_slope"), spec.get("rolloff"),
                       spec.get("cutoff"), int(seed))["heights"]


@contextlib.contextmanager
def local_client(n_workers: int = 2, threads_per_worker: int = 1) -> Iterator[Any]:
    """A ``dask.distributed`` client on a new loopback-only ``LocalCluster`` (every listener,
    the dashboard included, on 127.0.0.1), closed on exit."""
    from dask.distributed import Client, LocalCluster

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
    """The same tasks in this process, in order: the reference for the Dask path."""

    def scatter(self, value: Any, **_: Any) -> Any:
        return value

    def submit(self, fn: Callable, *args: Any, **_: Any) -> Any:
        # Results of earlier tasks stand for their values, as Dask futures do.
        return _Done(fn(*(a.value if isinstance(a, _Done) else a for a in args)))

    def gather(self, futures: Sequence[Any]) -> List[Any]:
        return [f.result() for f in futures]


class _Done:
    def __init__(self, value: Any) -> None:
        self.value = value

    def result(self) -> Any:
        return self.value


@contextlib.contextmanager
def _executor(client: Any) -> Iterator[Any]:
    if client is None:
        with local_client() as c:
            yield c
    elif isinstance(client, str) and client == "serial":
        yield _Serial()
    else:
        yield client


def _pure(client: Any) -> Dict[str, Any]:
    # Dask would merge identical submissions (same arguments): that is right for these pure
    # tasks, and the serial executor ignores it.
    return {} if isinstance(client, _Serial) else {"pure": True}


def sweep(loads: Sequence[float], pixel_size: Any, modulus: float, *,
          family: str = "hardening", values: Sequence[Optional[float]] = (None,),
          heights: Any = None, surfaces: Optional[Sequence[Any]] = None,
          surface_spec: Optional[Dict[str, Any]] = None, seeds: Sequence[int] = (),
          radius: Optional[float] = None, tolerance: float = 1e-8,
          max_iterations: int = 5000, imaging_fwhm: Optional[float] = None,
          imaging_pixel_size: Any = None, client: Any = None,
          threads_per_task: int = 1) -> Results:
    """Load ramps over a parameter grid, one Dask task per ramp.

    The grid is every combination of a model parameter in ``values`` (k in Pa/m for
    "hardening", p_Y in Pa for "hardness", ``None`` for "elastic" and "gt") with a surface:
    ``heights`` (one map, m), ``surfaces`` (several maps), and/or ``seeds`` of self-affine
    surfaces described by ``surface_spec`` (keyword arguments of :func:`contactscope.surface`:
    ``nx``, ``ny``, ``pixel_size`` in m, ``hurst``, ``rms_height`` in m, …). Every surface is
    pressed at ``loads`` (N) with a sphere of ``radius`` m on a flat of E* ``modulus`` Pa.

    Returns ``rows`` (per ramp: ``surface``, ``seed``, ``family``, ``parameter``, ``areas_m2``,
    ``edge_contact``, ``error``) in grid order; ``to_pandas()`` gives one row per ramp and load.
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
    with _executor(client) as ex:
        futures = [ex.scatter(m, broadcast=True, hash=False) for m in maps]
        for seed in seeds:
            labels.append({"surface": len(futures), "seed": int(seed)})
            futures.append(ex.submit(_surface_task, dict(surface_spec), int(seed),
                                     threads_per_task, **_pure(ex)))
        tasks = []
        grid = list(itertools.product(range(len(futures)), values))
        for surface, value in grid:
            tasks.append(ex.submit(_ramp_task, futures[surface], pixel_size, float(modulus),
                                   family, None if value is None else float(value), loads,
                                   radius, tolerance, max_iterations, imaging_fwhm,
                                   imaging_pixel_size, threads_per_task, **_pure(ex)))
        outcomes = ex.gather(tasks)
    rows = []
    for (surface, value), out in zip(grid, outcomes):
        rows.append({**labels[surface], "family": family,
                     "parameter": None if value is None else float(value),
                     "loads_n": loads, **out})
    return _SweepResults(rows=rows)


class _SweepResults(Results):
    def to_pandas(self):
        import pandas as pd

        records = []
        for r in self["rows"]:
            areas = r["areas_m2"] if r["areas_m2"] is not None else [math.nan] * len(r["loads_n"])
            for f, a in zip(r["loads_n"], areas):
                records.append({"surface": r["surface"], "seed": r["seed"], "family": r["family"],
                                "parameter": r["parameter"], "force_n": f, "area_m2": a,
                                "edge_contact": r["edge_contact"], "error": r["error"]})
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
                  client: Any = None, threads_per_task: int = 1) -> FitResults:
    """:func:`contactscope.fit_hardening` with every model evaluation (one load ramp) a Dask task.

    The same search as the library's: a log-spaced grid of ``grid`` values over ``range``
    (k in Pa/m, default 1e14–1e17; p_Y in Pa, default 1e7–1e10) evaluated in parallel, then
    Brent's method on ln(parameter) between the best grid point's neighbours down to
    ``ln_tolerance``, then the Gauss–Newton standard error from two more ramps (in parallel).
    Misfit: RMS of ln(A_sim/A_exp) (forces in N, areas in m²). "elastic" and "gt" are one ramp.
    The result equals the serial path (``client="serial"``) exactly; it agrees with the
    library's own fit to the search tolerance (their Brent implementations differ in detail).
    Returns a :class:`contactscope.FitResults` with one model (no ``measured`` or
    ``roughness``: the tasks see only the ramps).
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

    with _executor(client) as ex:
        body = ex.scatter(h, broadcast=True, hash=False)

        def submit(parameter: Optional[float]) -> Any:
            return ex.submit(_ramp_task, body, pixel_size, float(modulus), family, parameter,
                             fs, radius, tolerance, max_iterations, imaging_fwhm,
                             imaging_pixel_size, threads_per_task, **_pure(ex))

        def score(out: Dict[str, Any]) -> float:
            if out["error"] is not None:
                return math.inf
            return _cs.misfit(fs, ms, list(out["areas_m2"]))

        if not has_parameter:
            out = submit(None).result()
            if out["error"] is not None:
                raise _cs.InputError(out["error"])
            return _fit_results(family, None, None, score(out), out["areas_m2"], [], False)

        a, b = math.log(lo), math.log(hi)
        xs = [a + (b - a) * i / (grid - 1) for i in builtins.range(grid)]
        grid_out = ex.gather([submit(math.exp(x)) for x in xs])
        values = [score(o) for o in grid_out]
        if all(math.isinf(v) for v in values):
            first = next((o["error"] for o in grid_out if o["error"]), "no feasible value")
            raise _cs.InputError(first)
        trace = [(math.exp(x), v) for x, v in zip(xs, values) if math.isfinite(v)]
        best = min(builtins.range(len(values)), key=lambda i: values[i])
        at_edge = best in (0, len(values) - 1)
        x0, x1 = xs[max(best - 1, 0)], xs[min(best + 1, len(xs) - 1)]

        def cost(x: float) -> float:
            m = score(submit(math.exp(x)).result())
            if math.isfinite(m):
                trace.append((math.exp(x), m))
                return m
            return INFEASIBLE_MISFIT

        ln_best = brent_minimum(cost, x0, x1, ln_tolerance / 4.0)
        step = 0.05
        final, minus, plus = ex.gather([submit(math.exp(ln_best)),
                                        submit(math.exp(ln_best - step)),
                                        submit(math.exp(ln_best + step))])
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

