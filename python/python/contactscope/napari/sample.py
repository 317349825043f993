"""Sample data: the demo's synthetic experiment, generated on the fly (nothing shipped).

:func:`contactscope.synth_series` with its defaults — a rough sphere's contact imaged as a
confocal load series, 256 × 256 pixels of 200 nm, 8 loads from 4 to 100 mN, seed 2018, 12-bit
values in uint16 — as in Weber et al., Nat. Commun. 9, 888 (2018), Fig. 1. The true contact
masks come as a Labels layer; the forces travel in the layers' metadata, so the load-series
widget can analyse the layer without typing them.
"""

from __future__ import annotations

from typing import Any, Dict, List, Tuple

import numpy as np

import contactscope as cs

from ._common import META


def synthetic_series() -> List[Tuple[Any, Dict[str, Any], str]]:
    """The synthetic load series (image layer) and its true contact (labels layer)."""
    s = cs.synth_series()
    px_m = 200e-9  # synth_series' default pixel size
    forces = [float(f) for f in s["forces_n"]]
    scale = [1.0, px_m * 1e6, px_m * 1e6]
    meta = {META: {"path": None, "format": "synthetic", "forces_n": forces,
                   "pixel_size_m": (px_m, px_m), "axes": ["load", "y", "x"],
                   "true_area_m2": [float(a) for a in s["true_area_m2"]]}}
    common = {"scale": scale, "axis_labels": ["load", "y", "x"],
              "units": ["pixel", "µm", "µm"]}
    return [
        (s["images"], {"name": "synthetic series (4–100 mN)", "metadata": meta, **common},
         "image"),
        (np.asarray(s["truth"]).astype(np.uint8),
         {"name": "true contact", "opacity": 0.35, "visible": False, "metadata": meta, **common},
         "labels"),
    ]
