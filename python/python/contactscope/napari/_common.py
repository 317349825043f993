"""Shared pieces of the napari plugin: errors as one-line notifications, units, layer metadata.

Nothing here imports Qt at import time except through napari, which the plugin needs anyway.
"""

from __future__ import annotations

import os
from typing import Any, Callable, Dict, Optional

import contactscope as cs

#: Errors a file or a request can raise in contactscope (and the OS underneath it). A bug (a Rust
#: panic) arrives as :class:`contactscope.InternalError` and is reported the same way: one line.
ERRORS = (cs.InputError, cs.FileError, cs.ConvergenceError, cs.InternalError, OSError,
          ValueError)

#: The key of a layer's ``metadata`` where the plugin keeps what it knows about the layer's file.
META = "contactscope"


def one_line(error: BaseException) -> str:
    """The library's message, first line only (never a traceback)."""
    text = str(error).strip() or type(error).__name__
    return text.splitlines()[0]


def notify_error(message: str) -> None:
    """Show ``message`` as napari's error notification (one line, no traceback dialog)."""
    try:
        from napari.utils.notifications import show_error
    except ImportError:  # pragma: no cover - the plugin runs inside napari
        return
    show_error(message)


def guarded(what: str, call: Callable[[], Any]) -> Optional[Any]:
    """``call()``, or ``None`` after a one-line error notification naming ``what`` when it raises
    one of contactscope's errors."""
    try:
        return call()
    except ERRORS as e:
        notify_error(f"contactscope: {what}: {one_line(e)}")
        return None


def um(metres: Optional[float]) -> Optional[float]:
    """Metres as micrometres (``None`` stays ``None``)."""
    return None if metres is None else metres * 1e6


def stem(path: str) -> str:
    """A file's or folder's name without the folder and the extension."""
    name = os.path.basename(os.path.normpath(os.fspath(path)))
    root, ext = os.path.splitext(name)
    return root if ext else name


def layer_meta(**fields: Any) -> Dict[str, Any]:
    """The plugin's entry of a layer's metadata."""
    return {META: dict(fields)}

