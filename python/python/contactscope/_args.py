"""Keyword arguments as the library takes them, checked in Python terms: a wrong type is
answered naming the keyword, what it takes and what was given (``modulus= must be a number
in Pa; got str '3.7GPa'``), never with the extension's own extraction text."""

from __future__ import annotations

import numbers
import os
from typing import TYPE_CHECKING, Any, Dict, List, Optional, Sequence, Union

import numpy as np

from ._contactscope import InputError

if TYPE_CHECKING:
    from ._contactscope import SeriesSpec

PathLike = Union[str, "os.PathLike[str]"]

# What a string with a unit should go through, by unit, for the hint.
_PARSERS = {"N": "parse_forces", "m": "parse_pixel_size"}


def _given(value: Any) -> str:
    if isinstance(value, str):
        return f"str {value[:40]!r}"
    try:
        return f"{type(value).__name__} of {len(value)}"
    except TypeError:
        return f"{type(value).__name__} {value!r}"[:60]


def _hint(value: Any, unit: str) -> str:
    parser = _PARSERS.get(unit)
    if isinstance(value, str) and parser:
        return f" ({parser}({value!r}) converts a value with its unit)"
    if isinstance(value, str):
        return f" (SI units: a number in {unit})"
    return ""


def number(value: Any, keyword: str, unit: str) -> float:
    """A real number (not a bool, not a string) as a float."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise TypeError(f"{keyword}= must be a number in {unit}; got {_given(value)}"
                        f"{_hint(value, unit)}")
    return float(value)


def optional_number(value: Any, keyword: str, unit: str) -> Optional[float]:
    """:func:`number`, or ``None``."""
    return None if value is None else number(value, keyword, unit)


def numbers_of(values: Any, keyword: str, unit: str) -> List[float]:
    """A sequence (or 1-D array) of real numbers as floats."""
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise TypeError(f"{keyword}= must be a sequence of numbers in {unit}; got "
                        f"{_given(values)}{_hint(values, unit)}")
    out = []
    for i, v in enumerate(values):
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
            raise TypeError(f"{keyword}= must be a sequence of numbers in {unit}; item {i} is "
                            f"{_given(v)}{_hint(v, unit)}")
        out.append(float(v))
    return out


def optional_numbers(values: Any, keyword: str, unit: str) -> Optional[List[float]]:
    """:func:`numbers_of`, or ``None``."""
    return None if values is None else numbers_of(values, keyword, unit)


def f64(a: Any, ndim: int, what: str) -> np.ndarray:
    """A C-ordered float64 array of ``ndim`` dimensions (a 2-D one becomes one plane of 3-D)."""
    try:
        a = np.asarray(a, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{what} must be a {ndim}-D array of numbers; got {_given(a)}") from None
    if ndim == 3 and a.ndim == 2:
        a = a[np.newaxis]
    if a.ndim != ndim:
        raise InputError(f"{what} must be a {ndim}-D array; got {a.ndim} dimensions")
    return np.ascontiguousarray(a)


def spec(paths_or_manifest: Union[PathLike, Sequence[PathLike]],
         forces: Optional[Sequence[float]] = None, channel: Union[int, str, None] = None,
         series: Optional[int] = None, z: Optional[int] = None, t: Optional[int] = None,
         axes: Optional[Dict[str, int]] = None,
         load_axis: Optional[str] = None) -> SeriesSpec:
    """The files of a series as the command line takes them: files and folders, or one
    manifest (``.csv``), with the selection flags."""
    if isinstance(paths_or_manifest, (str, os.PathLike)):
        paths = [os.fspath(paths_or_manifest)]
    else:
        try:
            paths = [os.fspath(p) for p in paths_or_manifest]
        except TypeError:
            raise TypeError("the files must be a path, a folder, a manifest (.csv) or a list of "
                            f"paths; got {_given(paths_or_manifest)}") from None
    manifest = None
    if len(paths) == 1 and paths[0].lower().endswith(".csv"):
        manifest, paths = paths[0], []
    return {"inputs": paths, "manifest": manifest, "series": series, "channel": channel,
            "z": z, "t": t, "axes": axes, "load_axis": load_axis,
            "forces": optional_numbers(forces, "forces", "N")}


def command_line(given: Optional[Sequence[str]], call: str, out: Any) -> Optional[List[str]]:
    """The ``command_line`` a folder written from Python records: the words given, else the
    interpreter and the call (``[python, "contactscope.analyze(…, out='run')"]``) — never an
    empty list, which would say nothing of how the folder was made."""
    if out is None:
        return None
    if given is not None:
        return [str(w) for w in given]
    import sys
    return [sys.executable, f"contactscope.{call}(…, out={os.fspath(out)!r})"]
