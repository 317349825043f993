"""The batch's QC page in a real browser: Debian's Chromium, driven headless by Playwright
(`scripts/test-browser` installs both; elsewhere the test is skipped, unless
CONTACTSCOPE_REQUIRE_BROWSER=1). The page loads with no console error or warning, every image it
shows is there and decodes, its flags match the series table, and its filter, "flagged only" and
sorting work. CONTACTSCOPE_DOCS_IMAGES=<folder> also writes the screenshot of docs/batch.md."""

import os
import pathlib
import shutil

import numpy as np
import pytest

import contactscope as cs

pd = pytest.importorskip("pandas")

CHROMIUM = os.environ.get("CONTACTSCOPE_CHROMIUM") or shutil.which("chromium")


def _browser_or_skip():
    missing = None
    try:
        from playwright.sync_api import sync_playwright  # noqa: F401
    except ImportError:
        missing = "playwright (pip install playwright)"
    if missing is None and not (CHROMIUM and os.path.exists(CHROMIUM)):
        missing = "Chromium (Debian's package chromium)"
    if missing:
        if os.environ.get("CONTACTSCOPE_REQUIRE_BROWSER") == "1":
            pytest.fail(f"the QC page's browser test needs {missing}: scripts/test-browser")
        pytest.skip(f"no {missing}: run scripts/test-browser")


FORCES = [1e-3, 2e-3, 4e-3, 8e-3]


def _series(folder: pathlib.Path, seed: int, scale: float = 1.0, crop: int = 0) -> None:
    """A seeded series with a manifest; `scale` multiplies the grey levels (another threshold),
    `crop` cuts that many pixels off the top and left (contact at the border)."""
    folder.mkdir(parents=True)
    s = cs.synth_series(208, 208, 200e-9, FORCES, seed=seed)
    images = np.clip(s.images.astype(np.float64) * scale, 0, 4095).astype(np.uint16)
    cs.write_tiff(folder / "series.tif", images[:, crop:, crop:], 200e-9)
    (folder / "manifest.csv").write_text(
        "file,page,force_mN\n" + "".join(f"series.tif,{i},{f * 1e3:g}\n"
                                         for i, f in enumerate(FORCES)))


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """A batch of seven series with a failure and one of each flag, and its QC page."""
    d = tmp_path_factory.mktemp("qc")
    lubricants = ["dry", "dry", "glycerol", "glycerol", "water", "water"]
    for i in range(6):
        _series(d / f"r{i}", seed=10 + i, scale=1.6 if i == 4 else 1.0,
                crop=80 if i == 5 else 0)
    rows = [f"r{i},r{i},{'250' if i == 1 else ''},{lub},{20 + i}\n"
            for i, lub in enumerate(lubricants)]
    (d / "sheet.csv").write_text("id,input,pixel_size_nm,lubricant,temperature_C\n"
                                 + "".join(rows) + "missing,nowhere,,water,30\n")
    result = cs.batch(d / "sheet.csv", d / "out", color_by="lubricant")
    return d / "out", result


def test_the_page_loads_clean_with_every_image(page):
    _browser_or_skip()
    from playwright.sync_api import sync_playwright

    out, result = page
    flags = {i: "" if pd.isna(f) else f
             for i, f in zip(result.series["series_id"], result.series["flags"])}
    # A given 250 nm against the file's 200 nm: flagged, and its areas (×1.56) stand out.
    assert flags["r1"] == "archive_outlier,pixel_size_vs_metadata"
    assert "threshold_outlier" in flags["r4"]
    assert "edge_contact" in flags["r5"]
    assert flags["missing"] == "failed"
    assert flags["r0"] == flags["r2"] == ""
    messages, errors = [], []
    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=CHROMIUM,
            args=["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                  "--disable-background-networking", "--disable-component-update",
                  "--disable-sync"])
        try:
            tab = browser.new_page(viewport={"width": 1400, "height": 1100})
            tab.on("console", lambda m: messages.append(f"{m.type}: {m.text}"))
            tab.on("pageerror", lambda e: errors.append(str(e)))
            tab.on("requestfailed", lambda r: errors.append(f"failed to load {r.url}"))
            tab.goto((out / "index.html").as_uri())
            tab.wait_for_load_state("load")
            assert not errors, errors
            assert not [m for m in messages if m.startswith(("error", "warning"))], messages
            images = tab.evaluate(
                "Array.from(document.images).map(i => [i.getAttribute('src'), i.complete,"
                " i.naturalWidth, i.naturalHeight])")
            # The combined plot and one thumbnail per analysed series.
            assert len(images) == 1 + 6, images
            for src, complete, w, h in images:
                assert complete and w > 0 and h > 0, src
                assert (out / src).is_file(), src
            links = tab.evaluate("Array.from(document.links).map(a => a.getAttribute('href'))")
            for href in links:
                assert (out / href).exists(), href
            rows = tab.locator("#series tbody tr")
            assert rows.count() == 7
            assert tab.locator("#series tbody tr.failed").count() == 1
            codes = tab.evaluate("Array.from(document.querySelectorAll('#series tbody tr'))"
                                 ".map(r => [r.id.slice(2), r.dataset.flags])")
            assert {i: f for i, f in codes} == flags
            visible = "Array.from(document.querySelectorAll('#series tbody tr'))" \
                      ".filter(r => r.style.display !== 'none').map(r => r.id.slice(2))"
            tab.check("#flagged")
            assert sorted(tab.evaluate(visible)) == ["missing", "r1", "r4", "r5"]
            tab.uncheck("#flagged")
            tab.fill("#filter", "glycerol")
            assert tab.evaluate(visible) == ["r2", "r3"]
            tab.fill("#filter", "")
            # Sorting by the exponent β, twice: one order and its reverse.
            header = tab.locator("#series thead th", has_text="β")
            header.click()
            first = tab.evaluate("Array.from(document.querySelectorAll('#series tbody tr'))"
                                 ".map(r => r.id.slice(2))")
            header.click()
            second = tab.evaluate("Array.from(document.querySelectorAll('#series tbody tr'))"
                                  ".map(r => r.id.slice(2))")
            assert first != second and sorted(first) == sorted(second)
            betas = result.series.set_index("series_id")["power_law_exponent"]
            ordered = [i for i in first if not np.isnan(betas[i])]
            assert [betas[i] for i in ordered] == sorted(betas[i] for i in ordered)
            docs = os.environ.get("CONTACTSCOPE_DOCS_IMAGES")
            if docs:
                tab.reload()
                tab.wait_for_load_state("load")
                path = os.path.join(docs, "batch-qc.png")
                tab.screenshot(path=path, full_page=True)
                try:  # 256 colours keep the screenshot small and legible
                    from PIL import Image

                    Image.open(path).convert("RGB").quantize(256).save(path, optimize=True)
                except ImportError:
                    pass
        finally:
            browser.close()


@pytest.fixture(scope="module", params=[60, 200])
def many(request, tmp_path_factory):
    """A batch of 60 or 200 series (six inputs repeated, four lubricants, a date column with
    gaps, a failure with a long path), as an archive of a busy lab looks."""
    n = request.param
    d = tmp_path_factory.mktemp(f"qc{n}")
    for k in range(6):
        _series(d / f"r{k}", seed=30 + k, scale=1.0 + 0.05 * k)
    deep = "/".join(["a-rather-long-folder-name-of-an-instrument-archive"] * 6)
    rows = []
    for i in range(n):
        date = "" if i % 7 == 3 else f"2024-{1 + i % 12:02d}-{1 + (i * 5) % 28:02d}"
        lub = ["dry", "glycerol", "water", "hexadecane"][i % 4]
        inp = f"{deep}/missing.tif" if i == 5 else f"r{i % 6}"
        rows.append(f"s{i:03d},{inp},{lub},{date}\n")
    (d / "sheet.csv").write_text("id,input,lubricant,date\n" + "".join(rows))
    result = cs.batch(d / "sheet.csv", d / "out", color_by="lubricant")
    return d / "out", result, n


def test_many_series_fit_the_window_and_sort_by_kind(many):
    _browser_or_skip()
    from playwright.sync_api import sync_playwright

    out, result, n = many
    order = "Array.from(document.querySelectorAll('#series tbody tr')).map(r => r.id.slice(2))"
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM,
                                    args=["--no-sandbox", "--disable-gpu", "--no-first-run"])
        try:
            for width in (1400, 1920):
                tab = browser.new_page(viewport={"width": width, "height": 1000})
                tab.goto((out / "index.html").as_uri())
                tab.wait_for_load_state("load")
                # The whole table, its numbers, flags and warnings, within the window.
                right = tab.evaluate("document.getElementById('series')"
                                     ".getBoundingClientRect().right")
                assert right <= width, f"{n} series at {width} px: the table ends at {right}"
                for head in ("β", "R²", "flags", "warnings"):
                    box = tab.locator("#series thead th", has_text=head).first.bounding_box()
                    assert box["x"] + box["width"] <= width, (n, width, head, box)
                shots = os.environ.get("CONTACTSCOPE_QC_SHOTS")
                if shots:
                    tab.screenshot(path=os.path.join(shots, f"qc-{n}-{width}.png"))
                tab.close()
            tab = browser.new_page(viewport={"width": 1400, "height": 1000})
            tab.goto((out / "index.html").as_uri())
            dates = dict(zip(result.series["series_id"],
                             result.series["date"].fillna("")))
            betas = result.series.set_index("series_id")["power_law_exponent"]
            header = tab.locator("#series thead th", has_text="date")
            for direction in (1, -1):
                header.click()
                ids = tab.evaluate(order)
                filled = [dates[i] for i in ids if dates[i]]
                assert filled == sorted(filled, reverse=direction < 0), direction
                # Series without a date last, whichever way.
                assert all(not dates[i] for i in ids[len(filled):]), direction
            header = tab.locator("#series thead th", has_text="β")
            for direction in (1, -1):
                header.click()
                ids = tab.evaluate(order)
                known = [betas[i] for i in ids if not np.isnan(betas[i])]
                assert known == sorted(known, reverse=direction < 0), direction
                assert all(np.isnan(betas[i]) for i in ids[len(known):]), direction
        finally:
            browser.close()
