"""The load-series dock widget: the paper's analysis of a confocal load series in the viewer.

Weber et al., Nat. Commun. 9, 888 (2018): one exact Otsu (1979) threshold over the pooled
histogram of every micrograph of the series, contact = value > threshold, the contact area per
image (contact pixels × pixel area) and the power-law fit A ∝ N^β of area against load. The
numbers come from :func:`contactscope.analyze` on the files — the same Rust path as the command
line's ``analyze`` — and "Export…" writes the command line's folder (``areas.csv``,
``summary.json``, ``area_vs_load.png``/``.svg``) through the command line's own writer, with the
equivalent command recorded in ``summary.json``.

The series: files (TIFF, CZI, ND2, LIF, OME-Zarr), a folder, a manifest CSV (``file``, ``page``,
``force_mN``…) or an image layer a reader or the sample made; forces as the command line's
``--forces`` (``4,10,20,40mN``, ``4mN..400mN:12``); for a vendor file the load axis and channel.
The work runs in a napari worker thread; the viewer stays responsive and a bar shows progress.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
from qtpy.QtCore import QObject, Signal
from qtpy.QtWidgets import (QComboBox, QFileDialog, QFormLayout, QHBoxLayout, QLabel, QLineEdit,
                            QProgressBar, QPushButton, QSpinBox, QTableWidget, QTableWidgetItem,
                            QVBoxLayout, QWidget)

import contactscope as cs

from ._common import ERRORS, META, notify_error, one_line, stem

LOAD_AXES = ["(one image per file)", "t", "z", "series"]
FILES = "files / folder / manifest below"


@dataclass
class SeriesRequest:
    """What to analyse: files (the command line's inputs or one manifest) or an image stack in
    memory, with forces (N), channel and load axis, and the texts that name them as the command
    line's arguments."""

    inputs: List[str] = field(default_factory=list)
    forces_text: str = ""
    forces_n: Optional[List[float]] = None
    channel: Optional[int] = None
    series: Optional[int] = None
    z: Optional[int] = None
    t: Optional[int] = None
    load_axis: Optional[str] = None
    images: Optional[np.ndarray] = None
    pixel_size_m: Optional[Any] = None
    label: str = "series"
    #: The command line's ``--threshold`` as typed ("" for its default, otsu) and as
    #: :func:`contactscope.analyze` takes it.
    threshold_text: str = ""
    method: Optional[Union[str, float]] = None
    #: The command line's ``--pixel-size`` as typed ("" for the files' own).
    pixel_size_text: str = ""

    def read(self) -> Any:
        """The series (files as the command line reads them, or the stack)."""
        if self.images is not None:
            return self.images
        return cs.read_series(self.inputs, forces=self.forces_n, channel=self.channel,
                              series=self.series, z=self.z, t=self.t, load_axis=self.load_axis)

    def command_line(self, out: str) -> List[str]:
        """The command line's ``analyze`` with the same selection, writing to ``out``."""
        if self.images is not None:
            words = ["contactscope-napari", "analyze", self.label]
        elif self.is_manifest():
            words = ["contactscope", "analyze", "--manifest", self.inputs[0]]
        else:
            words = ["contactscope", "analyze", *self.inputs]
        words += self.selection_flags()
        if self.threshold_text:
            words += ["--threshold", self.threshold_text]
        if self.pixel_size_text and self.images is None:
            words += ["--pixel-size", self.pixel_size_text]
        return words + ["--out", out]

    def is_manifest(self) -> bool:
        """Whether the files are one manifest (which gives the forces itself)."""
        return len(self.inputs) == 1 and self.inputs[0].lower().endswith(".csv")

    def selection_flags(self) -> List[str]:
        """The command line's flags of this selection shared by its commands: ``--forces``
        (unless a manifest gives them), ``--series``, ``--channel``, ``--z``, ``--t`` and
        ``--load-axis``."""
        words = []
        if self.forces_text and not self.is_manifest():
            words += ["--forces", self.forces_text]
        for flag, value in (("--series", self.series), ("--channel", self.channel),
                            ("--z", self.z), ("--t", self.t)):
            if value is not None:
                words += [flag, str(value)]
        if self.load_axis is not None:
            words += ["--load-axis", self.load_axis]
        return words

    def micrographs(self, series: Any) -> Tuple[Any, Optional[List[float]], Optional[Any]]:
        """``series`` (from :meth:`read`) as the micrographs, forces and pixel size arguments of
        :func:`contactscope.compare`: a stack with its own, or files that carry theirs."""
        if self.images is not None:
            return series, self.forces_n, self.pixel_size_m
        return series, None, None

    def options(self) -> Dict[str, Any]:
        """The analysis' keyword arguments beyond the series: the threshold rule, and the pixel
        size where one is typed or the stack in memory carries one."""
        return {"method": self.method, "pixel_size": self.pixel_size_m}


def analyze(request: SeriesRequest, progress=None) -> Dict[str, Any]:
    """Read and analyse the series (global Otsu, masks): the micrographs and the outcome."""
    import warnings

    series = request.read()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cs.ContactscopeWarning)
        if request.images is not None:
            result = cs.analyze(series, request.forces_n, masks=True, progress=progress,
                                **request.options())
            images, px = series, request.pixel_size_m
        else:
            result = cs.analyze(series, masks=True, progress=progress, **request.options())
            images = series["images"]
            px = request.pixel_size_m or series["pixel_size_m"]
    return {"result": result, "images": images, "pixel_size_m": px}


def export(request: SeriesRequest, out: str, progress=None) -> Dict[str, Any]:
    """Write the command line's ``analyze`` folder for the series (its own writer)."""
    import warnings

    series = request.read()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cs.ContactscopeWarning)
        kwargs = dict(out=out, command_line=request.command_line(out), progress=progress,
                      **request.options())
        if request.images is not None:
            return cs.analyze(series, request.forces_n, **kwargs)
        return cs.analyze(series, **kwargs)


class _Progress(QObject):
    """Progress from the threads the Rust analysis runs on, delivered in the GUI thread."""

    changed = Signal(str, int, int)


def _um2(value: Optional[float]) -> str:
    """An area in m² shown in µm² ("-" where there is none: no contact light)."""
    return "-" if value is None or not np.isfinite(value) else f"{value * 1e12:.2f}"


def _px(value: Optional[float]) -> str:
    """An area in pixels ("-" where there is none)."""
    return "-" if value is None or not np.isfinite(value) else f"{value:.1f}"


def table_rows(result: Dict[str, Any]) -> List[List[str]]:
    """The area-vs-load table as shown: image, force (mN), contact pixels' area (µm² or px), the
    corrected area, its 95 % interval on the true area, patches, p (MPa)."""
    rows = []
    for r in result["rows"]:
        f = r.get("force_n")
        area = r.get("area_m2")
        p = r.get("mean_pressure_pa")
        if area is not None:
            shown = f"{area * 1e12:.2f}"
            corrected = _um2(r.get("area_corrected_m2"))
            interval = f"{_um2(r.get('area_m2_lo'))}…{_um2(r.get('area_m2_hi'))}"
        else:
            shown = f"{r.get('area_px', 0)} px"
            corrected = _px(r.get("area_corrected_px"))
            interval = f"{_px(r.get('area_px_lo'))}…{_px(r.get('area_px_hi'))} px"
        rows.append([f"{os.path.basename(str(r['image']))} p{r['page']}",
                     "-" if f is None else f"{f * 1e3:g}", shown, corrected, interval,
                     str(r["patches"]),
                     "-" if p is None else f"{p * 1e-6:.1f}"])
    return rows


class LoadSeriesWidget(QWidget):
    """Dock widget: choose a series and its forces, run the global Otsu analysis, see the
    contact as layers, the table and the log-log plot, export the command line's files."""

    def __init__(self, napari_viewer: Any) -> None:
        super().__init__()
        self.viewer = napari_viewer
        self.outcome: Optional[Dict[str, Any]] = None
        self.request: Optional[SeriesRequest] = None
        self._worker = None

        self.source = QComboBox()
        self.paths = QLineEdit()
        self.paths.setPlaceholderText("files, a folder or a manifest .csv (separate with ;)")
        browse_files, browse_folder = QPushButton("Files…"), QPushButton("Folder…")
        browse_files.clicked.connect(self._browse_files)
        browse_folder.clicked.connect(self._browse_folder)
        self.forces = QLineEdit()
        self.forces.setPlaceholderText("4,10,20,40mN or 4mN..400mN:12")
        self.load_axis = QComboBox()
        self.load_axis.addItems(LOAD_AXES)
        self.selection = selection_boxes()
        self.channel = self.selection["channel"]
        self.threshold = QLineEdit()
        self.threshold.setPlaceholderText("otsu: one threshold for the series (or per-image, "
                                          "or a grey value)")
        self.pixel_size = QLineEdit()
        self.pixel_size.setPlaceholderText("from the files (or 200nm, 200x210nm)")
        self.run_button = QPushButton("Analyze")
        self.run_button.clicked.connect(self.start)
        self.export_button = QPushButton("Export areas.csv, summary.json, plot…")
        self.export_button.clicked.connect(self._export_clicked)
        self.export_button.setEnabled(False)
        self.bar = QProgressBar()
        self.status = QLabel("")
        self.status.setWordWrap(True)
        self.table = QTableWidget(0, 6)
        self.table.setHorizontalHeaderLabels(["image", "force (mN)", "area (µm²)", "patches",
                                              "p (MPa)"])

        from matplotlib.backends.backend_qtagg import FigureCanvasQTAgg
        from matplotlib.figure import Figure

        self.figure = Figure(figsize=(4, 3), tight_layout=True)
        self.canvas = FigureCanvasQTAgg(self.figure)
        self.canvas.setMinimumHeight(220)

        files_row = QHBoxLayout()
        files_row.addWidget(self.paths)
        files_row.addWidget(browse_files)
        files_row.addWidget(browse_folder)
        form = QFormLayout()
        form.addRow("series", self.source)
        form.addRow("files", files_row)
        form.addRow("forces", self.forces)
        form.addRow("load axis", self.load_axis)
        form.addRow("plane", selection_row(self.selection))
        form.addRow("threshold", self.threshold)
        form.addRow("pixel size", self.pixel_size)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.run_button)
        layout.addWidget(self.bar)
        layout.addWidget(self.status)
        layout.addWidget(self.table)
        layout.addWidget(self.canvas)
        layout.addWidget(self.export_button)

        self._progress = _Progress()
        self._progress.changed.connect(self._on_progress)
        self.refresh_sources()
        self.source.currentTextChanged.connect(self.take_layer)
        self.viewer.layers.events.inserted.connect(self.refresh_sources)
        self.viewer.layers.events.removed.connect(self.refresh_sources)

    # The series -----------------------------------------------------------------------------

    def refresh_sources(self, *_: Any) -> None:
        """The choice of series: the files below, or an image layer."""
        current = self.source.currentText()
        self.source.blockSignals(True)
        self.source.clear()
        self.source.addItem(FILES)
        for layer in self.viewer.layers:
            if layer.__class__.__name__ == "Image" and not layer.name.startswith("contact"):
                self.source.addItem(layer.name)
        index = self.source.findText(current)
        self.source.setCurrentIndex(max(index, 0))
        self.source.blockSignals(False)

    def take_layer(self, name: str) -> None:
        """Fill the selection from a layer a reader made: its channel and series, the load
        axis "t" where the file has a T axis, and for a file with Z planes too, z plane 0 in
        the widget's own z box, said in the status line. The viewer's sliders never choose a
        plane: where they stand is no part of an analysis, which must give the same numbers
        each time it is run."""
        if not name or name == FILES or name not in self.viewer.layers:
            return
        layer = self.viewer.layers[name]
        meta = layer.metadata.get(META, {})
        axes = list(meta.get("axes") or [])
        # The file's channel and series, where it has more than one (as the CLI asks for).
        for key, count in (("channel", "channels"), ("series", "series_count")):
            if meta.get(key) is not None and (meta.get(count) or 1) > 1:
                self.selection[key].setValue(int(meta[key]))
        if "T" in axes:
            self.load_axis.setCurrentText("t")
        if "Z" in axes and "T" in axes:
            nz = int(layer.data.shape[axes.index("Z")])
            if self.selection["z"].value() < 0 or self.selection["z"].value() >= nz:
                self.selection["z"].setValue(0)
            self.status.setText(
                f"z plane {self.selection['z'].value()} of {nz} (0..{nz - 1}), chosen in the z "
                "box: the viewer's slider does not choose the plane analysed")

    def _browse_files(self) -> None:
        if choose_micrographs(self, self.paths):
            self.source.setCurrentIndex(0)

    def _browse_folder(self) -> None:
        name = QFileDialog.getExistingDirectory(self, "A folder of micrographs")
        if name:
            self.paths.setText(name)
            self.source.setCurrentIndex(0)

    def current_request(self) -> SeriesRequest:
        """The series and options the fields describe (raises InputError with a one-line
        message)."""
        request = self._series_request()
        threshold = self.threshold.text().strip()
        if threshold and threshold != "otsu":
            request.threshold_text = threshold
            request.method = threshold if threshold == "per-image" else _grey_value(threshold)
        text = self.pixel_size.text().strip()
        if text:
            request.pixel_size_text = text
            request.pixel_size_m = cs.parse_pixel_size(text)
        return request

    def _series_request(self) -> SeriesRequest:
        """The series the fields describe."""
        text = self.forces.text().strip()
        forces = cs.parse_forces(text) if text else None
        axis = self.load_axis.currentText()
        load_axis = None if axis == LOAD_AXES[0] else axis
        chosen = selected(self.selection)
        channel = chosen.pop("channel")
        name = self.source.currentText()
        if name and name != FILES:
            layer = self.viewer.layers[name]
            meta = layer.metadata.get(META, {})
            if forces is None and meta.get("forces_n") and None not in meta["forces_n"]:
                forces = list(meta["forces_n"])
                text = ",".join(f"{f * 1e3:g}" for f in forces) + "mN"
            inputs = meta.get("inputs") or ([meta["path"]] if meta.get("path") else None)
            if inputs:
                if channel is None and (meta.get("channels") or 1) > 1:
                    channel = int(meta["channel"])
                if chosen["series"] is None and (meta.get("series_count") or 1) > 1:
                    chosen["series"] = int(meta["series"])
                return SeriesRequest(inputs=list(inputs), forces_text=text, forces_n=forces,
                                     channel=channel, load_axis=load_axis, label=name,
                                     series=chosen["series"], z=chosen["z"], t=chosen["t"])
            data = np.asarray(layer.data)
            if data.ndim != 3:
                raise cs.InputError(f"layer '{name}' has {data.ndim} dimensions; a load series "
                                    "is a stack of 2-D images")
            px = meta.get("pixel_size_m")
            return SeriesRequest(images=data, forces_text=text, forces_n=forces, label=name,
                                 pixel_size_m=None if px is None else tuple(px))
        return files_request(self.paths.text(), self.forces.text(), self.load_axis.currentText(),
                             self.selection, "choose micrographs: files, a folder, a manifest "
                             "or a layer")

    # Running ---------------------------------------------------------------------------------

    def _on_progress(self, name: str, done: int, total: int) -> None:
        self.bar.setMaximum(max(total, 1))
        self.bar.setValue(done)
        self.bar.setFormat(f"{name} %v/%m")

    def _report(self, name: str, done: int, total: int) -> None:
        self._progress.changed.emit(name, done, total)

    def start(self) -> Any:
        """Run the analysis in a worker thread (the viewer stays responsive); the worker."""
        from napari.qt.threading import create_worker

        try:
            request = self.current_request()
        except ERRORS as e:
            self._fail(e)
            return None
        self.run_button.setEnabled(False)
        self.status.setText("reading and thresholding…")
        # Errors go to _fail (one line), never re-raised from the thread as a traceback.
        connect = {"returned": lambda outcome: self.show_outcome(request, outcome),
                   "errored": self._fail, "finished": lambda: self.run_button.setEnabled(True)}
        worker = create_worker(analyze, request, progress=self._report, _start_thread=False,
                               _connect=connect)
        self._worker = worker
        worker.start()
        return worker

    def run_now(self) -> Dict[str, Any]:
        """The same analysis in this thread (scripts and tests): the outcome, shown."""
        request = self.current_request()
        outcome = analyze(request, progress=self._report)
        self.show_outcome(request, outcome)
        return outcome

    def _fail(self, error: BaseException) -> None:
        message = one_line(error)
        self.status.setText(f"error: {message}")
        notify_error(f"contactscope: {message}")

    # Results ---------------------------------------------------------------------------------

    def show_outcome(self, request: SeriesRequest, outcome: Dict[str, Any]) -> None:
        """The outcome as layers, the table and the plot."""
        self.request, self.outcome = request, outcome
        result = outcome["result"]
        px = outcome["pixel_size_m"]
        scale = [1.0, 1.0, 1.0] if px is None else [1.0, px[1] * 1e6, px[0] * 1e6]
        images = np.asarray(outcome["images"])
        masks = np.asarray(result["masks"]).astype(np.uint8)
        common = {"scale": scale, "axis_labels": ["image", "y", "x"],
                  "units": ["pixel"] + (["pixel"] * 2 if px is None else ["µm", "µm"])}
        for name in ("contact micrographs", "contact mask", "contact edges"):
            if name in self.viewer.layers:
                self.viewer.layers.remove(name)
        source = self.source.currentText()
        layer = self.viewer.layers[source] if source in self.viewer.layers else None
        embedded = None if layer is None else _embed(layer, request, masks)
        if embedded is not None:
            # Drawn in the file's layer's own axes: the masks sit on the plane analysed.
            masks, common = embedded
        elif layer is None or np.shape(layer.data) != images.shape:
            self.viewer.add_image(images, name="contact micrographs", **common,
                                  metadata={META: {"inputs": request.inputs}})
        mask_layer = self.viewer.add_labels(masks, name="contact mask", opacity=0.25, **common)
        _coloured(mask_layer, "cyan")
        edges = self.viewer.add_labels(masks, name="contact edges", opacity=1.0, **common)
        edges.contour = 1
        _green(edges)
        for layer in (mask_layer, edges):
            layer.metadata[META] = {"threshold": result["threshold"]}
        self._fill_table(result)
        self._plot(result)
        t = result["threshold"]
        fit = (result.get("fits") or {}).get("power_law")
        beta = "" if not fit else f"; power law A ∝ N^β, β = {fit['exponent']:.3f}"
        self.status.setText(f"threshold {t.get('value')} ({t.get('method')}), contact is "
                            f"value > t, {len(result['rows'])} images{beta}")
        for w in result.get("warnings") or []:
            try:
                from napari.utils.notifications import show_warning
                show_warning(f"contactscope: {w}")
            except ImportError:  # pragma: no cover
                pass
        self.export_button.setEnabled(True)

    def _fill_table(self, result: Dict[str, Any]) -> None:
        rows = table_rows(result)
        self.table.setRowCount(len(rows))
        unit = "µm²" if result.get("area_unit") == "um2" or any(
            r.get("area_m2") is not None for r in result["rows"]) else "px"
        self.table.setHorizontalHeaderLabels(["image", "force (mN)", f"area ({unit})",
                                              "corrected", "95 % interval (true area)",
                                              "patches", "p (MPa)"])
        for i, row in enumerate(rows):
            for j, text in enumerate(row):
                self.table.setItem(i, j, QTableWidgetItem(text))
        self.table.resizeColumnsToContents()

    def _plot(self, result: Dict[str, Any]) -> None:
        self.figure.clear()
        ax = self.figure.add_subplot(111)
        pts = [(r["force_n"] * 1e3, r["area_m2"] * 1e12) for r in result["rows"]
               if r.get("force_n") and r.get("area_m2")]
        corrected = [(r["force_n"] * 1e3, r["area_corrected_m2"] * 1e12,
                      r["area_m2_lo"] * 1e12, r["area_m2_hi"] * 1e12) for r in result["rows"]
                     if r.get("force_n") and r.get("area_m2")
                     and np.isfinite(r.get("area_corrected_m2") or np.nan)]
        if pts:
            f, a = np.array(pts).T
            ax.plot(f, a, "o", mfc="none", color="tab:gray", label="contact pixels (Otsu)")
            if corrected:
                fc, c, lo, hi = np.array(corrected).T
                ax.errorbar(fc, c, yerr=[c - lo, hi - c], fmt="o", color="tab:blue",
                            capsize=3, label="corrected, 95 % interval on the true area")
            ax.set_xscale("log")
            ax.set_yscale("log")
            fit = (result.get("fits") or {}).get("power_law")
            if fit and len(f) > 1:
                # SI: area_m2 = prefactor · force_n^exponent; drawn in mN and µm².
                grid = np.geomspace(f.min(), f.max(), 40)
                area_um2 = 1e12 * fit["prefactor_m2_per_n_pow_exponent"] \
                    * (grid * 1e-3) ** fit["exponent"]
                ci = fit.get("exponent_ci95")
                span = "" if ci is None else f" ({ci[0]:.3f}…{ci[1]:.3f})"
                ax.loglog(grid, area_um2, "-", color="tab:orange",
                          label=f"A ∝ N^β, β = {fit['exponent']:.3f}{span}")
            ax.legend(loc="best", fontsize=8)
        else:
            ax.text(0.5, 0.5, "no forces or no contact: nothing on log axes",
                    ha="center", va="center", transform=ax.transAxes)
        ax.set_xlabel("normal force N (mN)")
        ax.set_ylabel("contact area A (µm²)")
        self.canvas.draw_idle()

    # Export ----------------------------------------------------------------------------------

    def _export_clicked(self) -> None:
        out = QFileDialog.getExistingDirectory(self, "Folder for areas.csv and summary.json")
        if out:
            self.start_export(out)

    def start_export(self, out: str) -> Any:
        """Write the command line's folder in a worker thread; the worker."""
        from napari.qt.threading import create_worker

        if self.request is None:
            return None
        request = self.request
        connect = {"returned": lambda r: self.status.setText(
                       f"wrote {len(r['written'])} files to {out}"),
                   "errored": self._fail}
        worker = create_worker(export, request, out, progress=self._report, _start_thread=False,
                               _connect=connect)
        worker.start()
        return worker

    def export_now(self, out: str) -> Dict[str, Any]:
        """The export in this thread (scripts and tests): the outcome with ``written``."""
        if self.request is None:
            raise cs.InputError("analyze a series before exporting it")
        return export(self.request, out, progress=self._report)


def _embed(layer: Any, request: SeriesRequest, masks: np.ndarray) -> Optional[Any]:
    """Masks (loads, rows, columns) of a series read along a file's T or Z axis, placed in the
    axes of the file's layer (T, Z, …, y, x): the load axis full, every other axis one plane
    at the index analysed. ``None`` where the layer is not such a file's layer."""
    axes = list(layer.metadata.get(META, {}).get("axes") or [])
    load = {"t": "T", "z": "Z"}.get(request.load_axis or "")
    if load not in axes or len(axes) != layer.ndim or layer.ndim < 3 or \
            tuple(layer.data.shape[-2:]) != masks.shape[-2:] or \
            layer.data.shape[axes.index(load)] != masks.shape[0]:
        return None
    index = {"T": request.t, "Z": request.z}
    translate = list(np.asarray(layer.translate, dtype=float))
    others = [a for a in axes[:-2] if a != load]
    data = masks
    for a in others:
        data = data[np.newaxis]
        i = axes.index(a)
        translate[i] += (index.get(a) or 0) * float(layer.scale[i])
    # data's axes: (others reversed…, load, y, x); transposed to the layer's order.
    current = list(reversed(others)) + [load]
    data = np.transpose(data, [current.index(a) for a in axes[:-2]] +
                        [data.ndim - 2, data.ndim - 1])
    return data, {"scale": list(layer.scale), "translate": translate,
                  "axis_labels": list(layer.axis_labels), "units": list(layer.units)}


def selection_boxes() -> Dict[str, QSpinBox]:
    """Spin boxes for the plane of a vendor file (the command line's --series, --channel, --z,
    --t); "—" (the lowest value) leaves one unset (index 0 where the file has the axis)."""
    boxes = {}
    for name in ("series", "channel", "z", "t"):
        box = QSpinBox()
        box.setRange(-1, 9999)
        box.setValue(-1)
        box.setSpecialValueText("—")
        box.setToolTip(f"--{name} of the command line (— : not given)")
        boxes[name] = box
    return boxes


def selection_row(boxes: Dict[str, QSpinBox]) -> QHBoxLayout:
    row = QHBoxLayout()
    for name, box in boxes.items():
        row.addWidget(QLabel({"channel": "ch"}.get(name, name)))
        row.addWidget(box, 1)
    return row


def selected(boxes: Dict[str, QSpinBox]) -> Dict[str, Optional[int]]:
    """The selection the boxes give (``None`` where unset)."""
    return {name: (None if box.value() < 0 else box.value()) for name, box in boxes.items()}


def files_request(paths: str, forces: str, load_axis: str, selection: Dict[str, Any],
                  missing: str) -> SeriesRequest:
    """The series of files (``;``-separated), forces, load axis and plane typed in a widget;
    ``missing``: the message when no file is given."""
    inputs = [p.strip() for p in paths.split(";") if p.strip()]
    if not inputs:
        raise cs.InputError(missing)
    forces = forces.strip()
    plane = selected(selection)
    return SeriesRequest(inputs=inputs, forces_text=forces,
                         forces_n=cs.parse_forces(forces) if forces else None,
                         load_axis=None if load_axis == LOAD_AXES[0] else load_axis,
                         label=stem(inputs[0]), channel=plane["channel"],
                         series=plane["series"], z=plane["z"], t=plane["t"])


def choose_micrographs(parent: Any, field: Any) -> bool:
    """A file dialog for micrographs or a manifest; the names chosen go into ``field``
    (``;``-separated). Whether any were chosen."""
    names, _ = QFileDialog.getOpenFileNames(
        parent, "Micrographs or a manifest", "",
        "Micrographs (*.tif *.tiff *.czi *.nd2 *.lif *.zarr);;Manifest (*.csv);;All files (*)")
    if names:
        field.setText(";".join(names))
    return bool(names)


def _grey_value(text: str) -> float:
    """A fixed threshold as typed: a number in the images' grey values."""
    try:
        value = float(text)
    except ValueError:
        raise cs.InputError(f"threshold '{text}': give otsu, per-image or a grey value "
                            "(contact is value > it)") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise cs.InputError(f"threshold '{text}' is not a finite grey value")
    return value


def _coloured(layer: Any, colour: str) -> None:
    """Label 1 in ``colour``, the rest transparent."""
    try:
        from napari.utils.colormaps import DirectLabelColormap

        layer.colormap = DirectLabelColormap(color_dict={None: "transparent", 0: "transparent",
                                                         1: colour})
    except (ImportError, TypeError, ValueError):  # pragma: no cover - older napari
        pass


def _green(layer: Any) -> None:
    """Label 1 drawn in green (the command line's overlay colour), the rest transparent."""
    _coloured(layer, "lime")
