"""The compare dock widget: simulated contact maps against the micrographs, as layers.

Weber et al., Nat. Commun. 9, 888 (2018), Fig. 2: each simulated contact map (a folder written
by ``contactscope simulate``) is imaged as the microscope would — blurred with a Gaussian PSF of
the measured FWHM, integrated over the micrograph's pixels, registered once for the series —
and compared with the micrograph at the same load (Dice, Jaccard). Everything is computed by
:func:`contactscope.compare` (the command line's ``compare``, same defaults and scores); the
widget only shows what it returns: the micrographs and the imaged simulations as image layers
(side by side in napari's grid), the contact of each as edge layers (experiment green,
simulation magenta) and the Dice per load in a table. Several simulation folders (one per
model, separated by ``;``) are compared one after the other with the same micrographs and shown
side by side, as the paper's Fig. 2 shows its models.
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
from qtpy.QtWidgets import (QCheckBox, QComboBox, QDoubleSpinBox, QFileDialog, QFormLayout,
                            QHBoxLayout, QLabel, QLineEdit, QProgressBar, QPushButton,
                            QTableWidget, QTableWidgetItem, QVBoxLayout, QWidget)

import contactscope as cs

from ._common import ERRORS, META, notify_error, one_line
from .series_widget import (LOAD_AXES, SeriesRequest, _coloured, _green, choose_micrographs,
                            files_request, selection_boxes, selection_row)

#: The experiment's layers; each simulation adds "<name>: imaged" and "<name>: contact edges".
LAYERS = ("compared micrographs", "experiment contact edges")


def model_name(simulation: str) -> str:
    """A simulation folder's name, as its layers and table rows call it."""
    return os.path.basename(os.path.normpath(simulation))


def compare(request: SeriesRequest, simulation: Any, psf_fwhm_m: float,
            dihedral: bool = False) -> Dict[str, Any]:
    """Read the micrographs once and compare them with each simulation folder (one, or a list:
    one per model) by the command line's ``compare``, with the registered pairs. Returns
    ``results`` (name, result) per folder, ``result`` (the first) and ``pixel_size_m``."""
    import warnings

    folders = [simulation] if isinstance(simulation, (str, os.PathLike)) else list(simulation)
    names = [model_name(os.fspath(f)) for f in folders]
    if len(set(names)) != len(names):
        raise cs.InputError(f"two simulation folders have the same name ({', '.join(names)}): "
                            "the layers are named after them")
    series = request.read()
    results = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cs.ContactscopeWarning)
        for name, folder in zip(names, folders):
            results.append((name, cs.compare(*request.micrographs(series), folder,
                                             psf_fwhm=psf_fwhm_m, dihedral=dihedral,
                                             images=True)))
    px = request.pixel_size_m if request.images is not None else series["pixel_size_m"]
    return {"results": results, "result": results[0][1], "pixel_size_m": px}


def command_line(request: SeriesRequest, simulation: str, psf_fwhm_m: float, dihedral: bool,
                 out: str) -> List[str]:
    """The command line's ``compare`` with the same micrographs, selection and options."""
    if request.images is not None:
        words = ["contactscope-napari", "compare", "--micrographs", request.label]
    else:
        words = ["contactscope", "compare", "--micrographs", *request.inputs]
    words += request.selection_flags()
    words += ["--simulation", simulation, "--psf-fwhm", f"{psf_fwhm_m * 1e9:g}nm"]
    if dihedral:
        words.append("--dihedral")
    return words + ["--out", out]


#: What one comparison runs on: the series, the simulation folders, the PSF's FWHM (m) and
#: whether the dihedral registration is on.
Arguments = Tuple[SeriesRequest, List[str], float, bool]


def export(request: SeriesRequest, simulation: Any, psf_fwhm_m: float, dihedral: bool,
           parent: str) -> List[str]:
    """The command line's ``compare`` folder for each simulation folder, written by its own
    writer as ``<parent>/compare-<folder name>`` (each all files or none); the folders."""
    import warnings

    folders = [simulation] if isinstance(simulation, (str, os.PathLike)) else list(simulation)
    series = request.read()
    written = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", cs.ContactscopeWarning)
        for folder in folders:
            out = os.path.join(parent, f"compare-{model_name(os.fspath(folder))}")
            words = command_line(request, os.fspath(folder), psf_fwhm_m, dihedral, out)
            cs.compare(*request.micrographs(series), folder, psf_fwhm=psf_fwhm_m,
                       dihedral=dihedral, out=out, command_line=words)
            written.append(out)
    return written


def table_rows(result: Dict[str, Any], name: str = "") -> List[List[str]]:
    """Per matched load: model, force (mN), simulated force (mN), Dice, Jaccard, shift (µm),
    areas (µm²)."""
    rows = []
    for r in result["loads"]:
        rows.append([name, f"{r['force_n'] * 1e3:g}", f"{r['simulated_force_n'] * 1e3:g}",
                     f"{r['dice']:.3f}", f"{r['jaccard']:.3f}",
                     f"{r['shift_x_m'] * 1e6:.2f}, {r['shift_y_m'] * 1e6:.2f}",
                     f"{r['experiment_area_m2'] * 1e12:.1f}",
                     f"{r['simulated_area_m2'] * 1e12:.1f}"])
    return rows


class CompareWidget(QWidget):
    """Dock widget: a simulation folder, the micrograph series and the PSF FWHM in; the imaged
    simulation next to each micrograph and the Dice per load out."""

    def __init__(self, napari_viewer: Any) -> None:
        super().__init__()
        self.viewer = napari_viewer
        self.outcome: Optional[Dict[str, Any]] = None
        self._compared: Optional[Arguments] = None  # the arguments of the comparison shown
        self._worker = None

        self.simulation = QLineEdit()
        self.simulation.setPlaceholderText(
            "folders written by contactscope simulate (one per model, separated by ;)")
        browse_sim = QPushButton("Folder…")
        browse_sim.clicked.connect(self._browse_simulation)
        self.paths = QLineEdit()
        self.paths.setPlaceholderText("micrographs: files, a folder or a manifest .csv")
        browse = QPushButton("Files…")
        browse.clicked.connect(self._browse_files)
        self.forces = QLineEdit()
        self.forces.setPlaceholderText("4,10,20,40mN (not with a manifest)")
        self.load_axis = QComboBox()
        self.load_axis.addItems(LOAD_AXES)
        self.selection = selection_boxes()
        self.channel = self.selection["channel"]
        self.fwhm = QDoubleSpinBox()
        self.fwhm.setRange(50.0, 5000.0)
        self.fwhm.setDecimals(1)
        self.fwhm.setValue(450.0)
        self.fwhm.setSuffix(" nm")
        self.dihedral = QCheckBox("also try mirror images and 90° rotations")
        self.grid = QCheckBox("side by side (napari grid)")
        self.grid.setChecked(True)
        self.run_button = QPushButton("Compare")
        self.run_button.clicked.connect(self.start)
        self.export_button = QPushButton("Export compare.csv, compare.json, panels…")
        self.export_button.clicked.connect(self._export_clicked)
        self.export_button.setEnabled(False)
        self.bar = QProgressBar()
        self.bar.setRange(0, 1)
        self.status = QLabel("")
        self.status.setWordWrap(True)
        self._layers: List[Any] = []
        self.table = QTableWidget(0, 8)
        self.table.setHorizontalHeaderLabels(["model", "force (mN)", "simulated (mN)", "Dice", "Jaccard",
                                              "shift x, y (µm)", "A exp (µm²)", "A sim (µm²)"])

        sim_row = QHBoxLayout()
        sim_row.addWidget(self.simulation)
        sim_row.addWidget(browse_sim)
        files_row = QHBoxLayout()
        files_row.addWidget(self.paths)
        files_row.addWidget(browse)
        form = QFormLayout()
        form.addRow("simulation", sim_row)
        form.addRow("micrographs", files_row)
        form.addRow("forces", self.forces)
        form.addRow("load axis", self.load_axis)
        form.addRow("plane", selection_row(self.selection))
        form.addRow("PSF FWHM", self.fwhm)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.dihedral)
        layout.addWidget(self.grid)
        layout.addWidget(self.run_button)
        layout.addWidget(self.bar)
        layout.addWidget(self.status)
        layout.addWidget(self.table)
        layout.addWidget(self.export_button)

    def _browse_simulation(self) -> None:
        name = QFileDialog.getExistingDirectory(self, "A simulate output folder (one model)")
        if name:  # each folder chosen is added: one per model
            known = [s.strip() for s in self.simulation.text().split(";") if s.strip()]
            self.simulation.setText(";".join(known + [name]))

    def _browse_files(self) -> None:
        choose_micrographs(self, self.paths)

    def current_request(self) -> SeriesRequest:
        """The micrograph series the fields describe."""
        request = files_request(self.paths.text(), self.forces.text(),
                                self.load_axis.currentText(), self.selection,
                                "choose the micrographs: files, a folder or a manifest")
        if not self.simulations():
            raise cs.InputError("choose the simulation: a folder written by contactscope "
                                "simulate (or several, one per model)")
        return request

    def simulations(self) -> List[str]:
        """The simulation folders typed or chosen, in order."""
        return [s.strip() for s in self.simulation.text().split(";") if s.strip()]

    def _arguments(self) -> Arguments:
        request = self.current_request()
        return (request, self.simulations(), self.fwhm_m(), self.dihedral.isChecked())

    def fwhm_m(self) -> float:
        """The PSF FWHM in m, read from its text as the command line reads ``--psf-fwhm 450nm``
        (450 × 1e-9 in floating point is one unit in the last place off, which moves every
        score in its last digits)."""
        return cs.parse_pixel_size(f"{self.fwhm.value()!r}nm")[0]

    def start(self) -> Any:
        """Run the comparison in a worker thread; the worker."""
        from napari.qt.threading import create_worker

        try:
            args = self._arguments()
        except ERRORS as e:
            self._fail(e)
            return None
        self.run_button.setEnabled(False)
        self.bar.setRange(0, 0)  # busy: the comparison reports no steps
        self.status.setText("imaging the simulated maps, registering, scoring…")
        # Errors go to _fail (one line), never re-raised from the thread as a traceback.
        worker = create_worker(compare, *args, _start_thread=False, _connect={
            "returned": lambda outcome: self._shown(args, outcome), "errored": self._fail,
            "finished": self._done})
        self._worker = worker
        worker.start()
        return worker

    def run_now(self) -> Dict[str, Any]:
        """The same comparison in this thread (scripts and tests): the outcome, shown."""
        args = self._arguments()
        outcome = compare(*args)
        self._shown(args, outcome)
        return outcome

    def _shown(self, args: Arguments, outcome: Dict[str, Any]) -> None:
        self.show_outcome(outcome)
        self._compared = args
        self.export_button.setEnabled(True)

    def export_now(self, parent: str) -> List[str]:
        """Write the command line's ``compare`` folder of each model compared last, as
        ``<parent>/compare-<folder name>``, in this thread (scripts and tests); the folders."""
        if self._compared is None:
            raise cs.InputError("compare before exporting")
        return export(*self._compared, parent)

    def _export_clicked(self) -> None:
        from napari.qt.threading import create_worker

        parent = QFileDialog.getExistingDirectory(
            self, "Where to write compare-<model> folders (the command line's compare --out)")
        if not parent or self._compared is None:
            return
        self.export_button.setEnabled(False)
        self.status.setText("writing the compare folders…")
        worker = create_worker(export, *self._compared, parent, _start_thread=False, _connect={
            "returned": lambda folders: self.status.setText(
                "written: " + ", ".join(os.path.basename(f) for f in folders)),
            "errored": self._fail,
            "finished": lambda: self.export_button.setEnabled(True)})
        self._worker = worker
        worker.start()

    def _done(self) -> None:
        self.run_button.setEnabled(True)
        self.bar.setRange(0, 1)
        self.bar.setValue(1)

    def _fail(self, error: BaseException) -> None:
        message = one_line(error)
        self.status.setText(f"error: {message}")
        notify_error(f"contactscope: {message}")

    def show_outcome(self, outcome: Dict[str, Any]) -> None:
        """The registered pairs as layers (the micrographs, then each model's imaged map) and
        the scores in the table."""
        self.outcome = outcome
        results = outcome["results"]
        first = results[0][1]
        px = outcome["pixel_size_m"]
        scale = [1.0, 1.0, 1.0] if px is None else [1.0, px[1] * 1e6, px[0] * 1e6]
        common = {"scale": scale, "axis_labels": ["load", "y", "x"],
                  "units": ["pixel"] + (["pixel"] * 2 if px is None else ["µm", "µm"])}
        for layer in self._layers:
            if layer in self.viewer.layers:
                self.viewer.layers.remove(layer)
        micrographs = np.asarray(first["micrographs"])
        finite = micrographs[np.isfinite(micrographs)]
        limits = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
        if limits[0] == limits[1]:
            limits = (limits[0], limits[0] + 1.0)

        def meta(name: str, result: Dict[str, Any]) -> Dict[str, Any]:
            return {META: {"model": name, "simulation": result["simulation"],
                           "forces_n": [r["force_n"] for r in result["loads"]],
                           "dice": [r["dice"] for r in result["loads"]]}}

        added = [self.viewer.add_image(micrographs, name=LAYERS[0], contrast_limits=limits,
                                       metadata=meta("experiment", first), **common),
                 self.viewer.add_labels(
                     np.asarray(first["experiment_contact"]).astype(np.uint8), name=LAYERS[1],
                     **common)]
        _green(added[1])
        for name, result in results:
            added.append(self.viewer.add_image(np.asarray(result["simulated_images"]),
                                               name=f"{name}: imaged", contrast_limits=limits,
                                               metadata=meta(name, result), **common))
            edges = self.viewer.add_labels(
                np.asarray(result["simulated_contact"]).astype(np.uint8),
                name=f"{name}: contact edges", **common)
            _coloured(edges, "magenta")
            added.append(edges)
        for layer in added[1::2]:
            layer.contour = 1
        self._layers = added
        if self.grid.isChecked():
            # napari ≥ 0.9 keeps the grid on the canvas (viewer.grid before).
            canvas = getattr(self.viewer, "canvas", None)
            grid = getattr(canvas, "grid", None) or self.viewer.grid
            grid.stride = 2
            grid.enabled = True
        rows = [row for name, result in results for row in table_rows(result, name)]
        self.table.setRowCount(len(rows))
        for i, row in enumerate(rows):
            for j, text in enumerate(row):
                self.table.setItem(i, j, QTableWidgetItem(text))
        self.table.resizeColumnsToContents()
        scores = "; ".join(f"{name}: mean Dice {r['dice_mean']:.3f} over {r['loads_matched']} "
                           "loads" for name, r in results)
        self.status.setText(f"{scores} (PSF FWHM {first['psf_fwhm_m'] * 1e9:.0f} nm)")
