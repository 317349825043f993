"""contactscope's napari plugin (npe2 manifest ``napari.yaml``, installed with the
``contactscope[napari]`` extra): readers for micrographs (TIFF, CZI, ND2, LIF, OME-Zarr) and height maps,
a load-series dock widget (one global Otsu threshold, contact masks and edges as layers, the
area-vs-load table and power-law fit, export of the command line's ``analyze`` folder), a compare
dock widget (simulated contact maps imaged with the PSF, registered, Dice per load) and the
synthetic load series as sample data.

Importing :mod:`contactscope` never imports napari; the modules of this package import it (and
Qt) only when napari loads them.
"""
