"""The paper's workflow end to end from Python (Weber et al., Nat. Commun. 9, 888 (2018)):

1. a confocal load series (here the library's seeded synthetic one, written as a TIFF and read
   back as a lab's files would be) is analysed with one global Otsu threshold → area vs load;
2. the linear-hardening coefficient k is fitted to that curve on a rough sphere, every model
   evaluation (one load ramp) a task on a Dask LocalCluster (loopback only);
3. the simulated contact maps at the fitted k are compared with the micrographs (blur with the
   PSF, register, Dice);
4. everything is plotted with matplotlib into one PNG and summarised in JSON.

Run:  python examples/paper_workflow.py [--out DIR]   (about 10–20 s on 2 cores)
"""

import argparse
import json
import pathlib
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import contactscope as cs  # noqa: E402
from contactscope import distributed  # noqa: E402

PIXEL = 200e-9  # micrograph and simulation pixel, m
SIZE = 192  # pixels of the micrographs and of the height map (38.4 µm: the contact stays inside)
FORCES = [2e-3, 3e-3, 4.5e-3, 6.5e-3, 9e-3]  # N
RADIUS = 290e-6  # sphere radius, m
MODULUS = 5e9  # contact modulus E*, Pa
PSF_FWHM = 450e-9  # m


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="paper_workflow_out", help="output folder")
    args = parser.parse_args()
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()

    # 1. The series, as files, analysed as the command line's `analyze` does.
    synth = cs.synth_series(SIZE, SIZE, PIXEL, FORCES, seed=2018)
    cs.write_tiff(out / "series.tif", synth.images, PIXEL)
    series = cs.read_series(out / "series.tif", forces=FORCES)
    analysis = cs.analyze(series)
    table = analysis.to_pandas()
    table["true_area_m2"] = synth.true_area_m2
    table.to_csv(out / "areas.csv", index=False)
    areas = list(table["area_m2"])
    print(f"threshold {analysis.threshold['value']:.0f}; "
          f"β = {analysis.fits['power_law']['exponent']:.3f}")

    # 2. The rough sphere and the fit of k on Dask (each grid point and each Brent step is one
    #    load ramp; the height map is scattered to the workers once).
    heights = cs.surface(SIZE, SIZE, PIXEL, hurst=0.8, rms_height=120e-9, seed=7)
    with distributed.local_client(n_workers=2, threads_per_worker=1) as client:
        fit = distributed.fit_hardening(FORCES, areas, heights, PIXEL, MODULUS, radius=RADIUS,
                                        grid=7, ln_tolerance=0.02, client=client)
    k = fit.parameter
    print(f"k = {k * 1e-15:.2f} MPa/nm (misfit {fit.misfit:.3f}, "
          f"{len(fit.trace)} ramps on Dask)")

    # 3. Simulated maps at the fitted k against the micrographs.
    sim = cs.simulate(heights, PIXEL, MODULUS, FORCES, "hardening", k=k, radius=RADIUS)
    scores = cs.compare(series.images, FORCES, PIXEL, sim.contact.astype(np.float64), FORCES,
                        PIXEL, PSF_FWHM).to_pandas()
    print("Dice per load:", ", ".join(f"{d:.2f}" for d in scores["dice"]))

    # 4. Plots.
    fig, axes = plt.subplots(1, 3, figsize=(13, 4))
    f_mn = np.array(FORCES) * 1e3
    axes[0].loglog(f_mn, np.array(areas) * 1e12, "o", label="measured (global Otsu)")
    axes[0].loglog(f_mn, np.array(synth.true_area_m2) * 1e12, "k+", label="true (synthetic)")
    axes[0].loglog(f_mn, np.asarray(fit.areas_m2) * 1e12, "-",
                   label=f"hardening, k = {k * 1e-15:.2f} MPa/nm")
    axes[0].set_xlabel("normal force (mN)")
    axes[0].set_ylabel("contact area (µm²)")
    axes[0].legend(fontsize=8)
    trace = sorted(fit.trace)
    axes[1].semilogx([t[0] * 1e-15 for t in trace], [t[1] for t in trace], ".-")
    axes[1].set_xlabel("k (MPa/nm)")
    axes[1].set_ylabel("misfit (RMS ln area)")
    axes[2].imshow(series.images[-1], cmap="gray")
    axes[2].contour(sim.contact[-1], levels=[0.5], colors="r", linewidths=0.5)
    axes[2].set_title(f"{f_mn[-1]:.1f} mN: micrograph; simulated contact (red, unregistered)", fontsize=9)
    axes[2].axis("off")
    fig.tight_layout()
    fig.savefig(out / "paper_workflow.png", dpi=110)

    summary = {
        "threshold": analysis.threshold["value"],
        "power_law_exponent": analysis.fits["power_law"]["exponent"],
        "k_MPa_per_nm": k * 1e-15,
        "k_se_MPa_per_nm": None if fit.parameter_se is None else fit.parameter_se * 1e-15,
        "misfit": fit.misfit,
        "dice": list(scores["dice"]),
        "edge_contact": [r["edge_contact"] for r in sim.rows],
        "area_um2": [a * 1e12 for a in areas],
        "seconds": time.perf_counter() - started,
    }
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    print(f"wrote {out / 'paper_workflow.png'} in {summary['seconds']:.1f} s")


if __name__ == "__main__":
    main()
