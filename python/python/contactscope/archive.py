"""A lab's archive in one call: :func:`batch` runs the command line's ``contactscope batch`` in
this process — a samplesheet (a CSV file or a pandas DataFrame) or a folder walk becomes one
output folder with the per-series folders ``analyze`` writes, the tables ``images`` and
``series`` (Parquet and CSV), ``batch.json`` and the QC page ``index.html``; re-runs redo only
the series whose inputs or options changed. The tables come back as DataFrames.

The same batch on a Dask cluster, one series per task: :func:`contactscope.distributed.batch`.
"""

from __future__ import annotations

import os
import sys
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _contactscope as _cs

__all__ = ["batch", "BatchResult"]

#: Per-series options whose numbers are in SI units, with the unit their text takes.
_SI_UNITS = {
    "pixel_size": "m",
    "topography_pixel_size": "m",
    "radius": "m",
    "height_unit": "m",
    "modulus": "Pa",
}


def _number(x: Any) -> str:
    return repr(float(x))


def option_text(name: str, value: Any) -> str:
    """A per-series option's value as the samplesheet writes it: text as it is (``"200nm"``),
    numbers in SI units (``pixel_size=2e-7``, ``forces=[4e-3, 1e-2]``, ``modulus=3.7e9``,
    ``k_range=(1e14, 1e17)`` in Pa/m, ``hardness_range`` in Pa), ``axes`` as a dict, ``models``
    as a list."""
    if isinstance(value, str):
        return value
    if name == "forces":
        return ",".join(_number(f) for f in value) + "N"
    if name in ("pixel_size", "topography_pixel_size") and isinstance(value, (tuple, list)):
        x, y = value
        return f"{_number(x)}x{_number(y)}m"
    if name in _SI_UNITS:
        return _number(value) + _SI_UNITS[name]
    if name == "k_range":
        lo, hi = value
        return f"{_number(lo)}Pa/m..{_number(hi)}Pa/m"
    if name == "hardness_range":
        lo, hi = value
        return f"{_number(lo)}..{_number(hi)}Pa"
    if name in ("axis", "axes") and isinstance(value, Mapping):
        return ";".join(f"{k}={int(v)}" for k, v in value.items())
    if name == "models" and not isinstance(value, str):
        return ",".join(str(m) for m in value)
    if isinstance(value, (bool, np.bool_)):
        raise _cs.InputError(f"batch: {name}={value!r} is not a value of this option")
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return _number(value)
    return os.fspath(value)


def _options(options: Mapping[str, Any]) -> Dict[str, str]:
    out = {}
    for name, value in options.items():
        if value is None:
            continue
        key = "axis" if name == "axes" else name
        out[key] = option_text(name, value)
    return out


def _frame(columns: List[Tuple[str, str, list]]):
    """The table's columns as a DataFrame with the dtypes pandas gives its Parquet file
    (``pandas.read_parquet`` with pyarrow): float64; int64, or float64 with NaN where a column
    has nulls; bool, or object with None; text as pandas' string dtype where pandas infers it
    (pandas 3), else object with None."""
    import pandas as pd

    if int(pd.__version__.split(".")[0]) >= 3:
        strings = True
    else:
        try:
            strings = bool(pd.get_option("future.infer_string"))
        except (KeyError, pd.errors.OptionError):  # pandas < 2.1
            strings = False
    data = {}
    for name, kind, values in columns:
        nulls = any(v is None for v in values)
        if kind == "float" or (kind == "int" and nulls):
            data[name] = np.array([np.nan if v is None else v for v in values], dtype=np.float64)
        elif kind == "int":
            data[name] = np.array(values, dtype=np.int64)
        elif kind == "bool" and not nulls:
            data[name] = np.array(values, dtype=bool)
        elif kind == "text" and strings:
            data[name] = pd.array(values, dtype=pd.StringDtype(na_value=np.nan))
        else:
            data[name] = np.array(values, dtype=object)
    return pd.DataFrame(data, columns=[c[0] for c in columns])


class BatchResult:
    """What a batch did: ``images`` and ``series`` (the tables as pandas DataFrames, as
    written to ``images.parquet`` and ``series.parquet``) and ``outcome`` (counts, failures,
    warnings, the files written). Unpacks as ``images, series = cs.batch(...)``."""

    def __init__(self, outcome: Mapping[str, Any]) -> None:
        outcome = dict(outcome)
        self.images = _frame(outcome.pop("images_table"))
        self.series = _frame(outcome.pop("series_table"))
        self.outcome = outcome

    def __iter__(self) -> Iterator[Any]:
        return iter((self.images, self.series))

    def __repr__(self) -> str:
        o = self.outcome
        return (f"BatchResult({o['series']} series: {o['ok']} ok, {o['failed']} failed; "
                f"{o['analysed']} analysed, {o['reused']} reused; {o['image_rows']} images)")


def _source(samplesheet: Any, base: Any) -> Tuple[str, str, Optional[str]]:
    """(kind, source, base) of a samplesheet argument: a DataFrame as CSV text (relative inputs
    against ``base``, default the working folder), a folder to walk, or a CSV file."""
    if hasattr(samplesheet, "to_csv") and hasattr(samplesheet, "columns"):
        text = samplesheet.to_csv(index=False)
        return "text", text, os.fspath(base) if base is not None else os.getcwd()
    path = os.fspath(samplesheet)
    if os.path.isdir(path):
        return "walk", path, None
    return "file", path, None


def _request(samplesheet: Any, out: Any, base: Any, patterns: Optional[Sequence[str]],
             tiff_folders: bool, rerun: str, color_by: Optional[str], overlays: bool,
             save_masks: bool, memory_mib: int, device: str,
             options: Mapping[str, Any], call: str) -> Dict[str, Any]:
    kind, source, base = _source(samplesheet, base)
    if kind != "walk" and (patterns or tiff_folders):
        raise _cs.InputError("batch: patterns= and tiff_folders= choose series in a folder walk; "
                             "a samplesheet lists them")
    shown = "<DataFrame>" if kind == "text" else repr(source)
    return dict(kind=kind, source=source, out=os.fspath(out), base=base,
                patterns=list(patterns or ()), tiff_folders=bool(tiff_folders),
                options=_options(options), overlays=bool(overlays),
                save_masks=bool(save_masks), memory_mib=int(memory_mib), device=device,
                rerun=rerun, color_by=color_by,
                command_line=[sys.executable, f"{call}({shown}, out={os.fspath(out)!r})"])


def _print_progress(series_id: str, done: int, total: int) -> None:
    print(f"contactscope: series {done} of {total} done ({series_id})", file=sys.stderr,
          flush=True)


def batch(samplesheet: Any, out: Union[str, "os.PathLike[str]"], *, base: Any = None,
          patterns: Optional[Sequence[str]] = None, tiff_folders: bool = False,
          rerun: str = "changed", color_by: Optional[str] = None, overlays: bool = False,
          save_masks: bool = False, memory_mib: int = 128, device: str = "cpu",
          progress: Any = None, **options: Any) -> BatchResult:
    """A lab's archive in one call: the command line's ``contactscope batch`` (the same folder,
    tables and page, the same checks; ``docs/batch.md``).

    ``samplesheet``: a samplesheet CSV file, a pandas DataFrame of the same columns (``id``,
    ``input``, per-series options, metadata; relative inputs against ``base``, default the
    working folder) or an archive folder to walk (every folder holding ``manifest.csv``, every
    file matching ``patterns`` — ``*.czi``, ``*.nd2``, ``*.lif``, ``*.zarr`` (OME-Zarr stores) by default —, with
    ``tiff_folders`` every folder of TIFFs). ``out``: the batch's folder.

    ``**options``: per-series options for every row that leaves them empty, named as the
    samplesheet's columns — text with units (``pixel_size="200nm"``) or numbers in SI units
    (``pixel_size=2e-7``, ``forces=[4e-3, 1e-2]``, ``modulus=3.7e9``, ``radius=290e-6``;
    ``load_axis="t"``, ``channel=0``, ``threshold="otsu"``, ``topography="map.npy"``, …).
    ``rerun``: ``"changed"`` (default: only new or changed series), ``"failed"`` (also failed
    ones) or ``"all"``. ``color_by``: the metadata column of the QC page's combined plot.
    ``overlays``, ``save_masks``, ``memory_mib`` as ``analyze``'s flags; ``device`` where
    fit-hardening solves. ``progress``: ``True`` for a line per series on stderr, or a
    callable ``(series_id, done, total)``.

    Returns a :class:`BatchResult`: ``images, series = cs.batch(...)`` (DataFrames equal to the
    Parquet tables; a failed series is a row of ``series`` with its ``error``); ``.outcome``
    holds the counts and failures. The folder's per-series folders are those
    ``contactscope analyze`` writes, byte for byte.
    """
    try:
        import pandas  # noqa: F401
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("batch() returns DataFrames: pip install pandas") from e
    request = _request(samplesheet, out, base, patterns, tiff_folders, rerun, color_by,
                       overlays, save_masks, memory_mib, device, options, "contactscope.batch")
    report = _print_progress if progress is True else (progress or None)
    return BatchResult(_cs.batch_plan(**request).run(report))
