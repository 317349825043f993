"""cs.batch and contactscope.distributed.batch against the command line's `contactscope batch`:
the same tables byte for byte, DataFrames equal to the Parquet files, and the Parquet read by
pyarrow, pandas and DuckDB with the numbers of the CSV."""

import os
import pathlib
import shutil
import subprocess

import numpy as np
import pytest

import contactscope as cs
from contactscope import distributed as dd

pd = pytest.importorskip("pandas")

TABLES = ["images.csv", "series.csv", "images.parquet", "series.parquet"]


def write_series(folder: pathlib.Path, seed: int, manifest: bool = True) -> None:
    """A seeded series of four loads (144² px of 200 nm, 1–8 mN) as one TIFF, with a manifest."""
    folder.mkdir(parents=True)
    s = cs.synth_series(144, 144, 200e-9, [1e-3, 2e-3, 4e-3, 8e-3], seed=seed)
    cs.write_tiff(folder / "series.tif", s.images, 200e-9)
    if manifest:
        (folder / "manifest.csv").write_text(
            "file,page,force_mN\n" + "".join(f"series.tif,{i},{f}\n"
                                             for i, f in enumerate([1, 2, 4, 8])))


@pytest.fixture(scope="module")
def archive(tmp_path_factory):
    """Three series (two manifest folders, one TIFF with forces in the samplesheet), a missing
    one, and metadata: `sheet.csv` in the archive's folder."""
    d = tmp_path_factory.mktemp("archive")
    write_series(d / "s1", 1)
    write_series(d / "s2", 2)
    write_series(d / "loose", 3, manifest=False)
    (d / "sheet.csv").write_text(
        "id,input,forces_mN,sample,temperature_C\n"
        "s1,s1,,glass,21.5\n"
        "s2,s2,,steel,22\n"
        "s3,loose/series.tif,\"1,2,4,8\",steel,23\n"
        "gone,nowhere,,glass,24\n")
    return d


def run_cli(binary, *args, cwd):
    done = subprocess.run([str(binary), *map(str, args)], cwd=cwd, capture_output=True,
                          text=True, timeout=300)
    return done


@pytest.fixture(scope="module")
def cli_batch(archive, cli):
    """The command line's batch over the samplesheet: exit 3 (one series is missing)."""
    from conftest import _binary

    done = run_cli(_binary(), "batch", "--samplesheet", archive / "sheet.csv", "--out",
                   archive / "cli", "-q", cwd=archive)
    assert done.returncode == 3, done.stderr
    return archive / "cli"


def same_tables(a: pathlib.Path, b: pathlib.Path) -> None:
    for name in TABLES:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_batch_in_python_writes_the_command_lines_tables(archive, cli_batch):
    seen = []
    result = cs.batch(archive / "sheet.csv", archive / "py",
                      progress=lambda i, done, total: seen.append((i, done, total)))
    same_tables(cli_batch, archive / "py")
    images, series = result
    assert list(series["series_id"]) == ["s1", "s2", "s3", "gone"]
    assert list(series["status"]) == ["ok", "ok", "ok", "failed"]
    assert "nowhere" in series["error"][3]
    assert result.outcome["failed"] == 1 and result.outcome["analysed"] == 4
    # Series run side by side: every one reported once, with how many are done of four.
    assert sorted(i for i, _, _ in seen) == ["gone", "s1", "s2", "s3"]
    assert sorted(done for _, done, _ in seen) == [1, 2, 3, 4]
    assert {total for _, _, total in seen} == {4}
    assert len(images) == 12
    # The folders are the command line's analyze folders (but for the program's name).
    for sid in ["s1", "s2", "s3"]:
        for name in ["areas.csv", "area_vs_load.svg"]:
            assert ((archive / "py/series" / sid / name).read_bytes()
                    == (cli_batch / "series" / sid / name).read_bytes()), (sid, name)
    # A second call re-uses every series and returns the same tables.
    again = cs.batch(archive / "sheet.csv", archive / "py")
    assert again.outcome["analysed"] == 0 and again.outcome["reused"] == 4
    pd.testing.assert_frame_equal(again.images, images)
    pd.testing.assert_frame_equal(again.series, series)


def test_the_dataframes_are_the_parquet_tables(archive, cli_batch):
    pa = pytest.importorskip("pyarrow.parquet")
    duckdb = pytest.importorskip("duckdb")
    result = cs.batch(archive / "sheet.csv", archive / "py-frames")
    for name, frame in [("images", result.images), ("series", result.series)]:
        path = archive / "py-frames" / f"{name}.parquet"
        by_pandas = pd.read_parquet(path)
        pd.testing.assert_frame_equal(frame, by_pandas)
        by_arrow = pa.read_table(path).to_pandas()
        pd.testing.assert_frame_equal(frame, by_arrow)
        by_duckdb = duckdb.sql(f"SELECT * FROM '{path}'").df()
        assert list(by_duckdb.columns) == list(frame.columns)
        csv = pd.read_csv(archive / "py-frames" / f"{name}.csv", keep_default_na=False,
                          na_values=[""], dtype=str)
        for column in frame.columns:
            kind = frame[column].dtype
            if kind.kind in "fi":
                want = pd.to_numeric(csv[column])
                np.testing.assert_array_equal(frame[column].to_numpy(np.float64),
                                              want.to_numpy(np.float64), err_msg=column)
                np.testing.assert_array_equal(
                    pd.to_numeric(by_duckdb[column]).to_numpy(np.float64),
                    want.to_numpy(np.float64), err_msg=column)
            else:
                got = [None if v is None or v is pd.NA or (isinstance(v, float) and np.isnan(v))
                       else str(v).lower() if isinstance(v, (bool, np.bool_)) else str(v)
                       for v in frame[column]]
                want = [None if isinstance(v, float) else v for v in csv[column]]
                assert got == want, column
    images = result.images
    assert images["contact_pixels"].dtype == np.int64
    assert images["area_um2"].dtype == np.float64
    assert images["edge_contact"].dtype == bool
    assert result.series["temperature_C"].dtype == np.float64
    assert pd.api.types.is_string_dtype(result.series["sample"])
    # DuckDB on the archive: mean area at 8 mN per sample, from the Parquet alone.
    per_sample = duckdb.sql(
        f"SELECT sample, avg(area_um2) AS a FROM '{archive / 'py-frames' / 'images.parquet'}' "
        "WHERE force_mN = 8 GROUP BY sample ORDER BY sample").fetchall()
    assert [s for s, _ in per_sample] == ["glass", "steel"]
    glass = images[(images["sample"] == "glass") & (images["force_mN"] == 8)]["area_um2"]
    assert per_sample[0][1] == pytest.approx(glass.mean(), rel=1e-12)


def test_a_dataframe_is_a_samplesheet(archive, cli_batch):
    sheet = pd.read_csv(archive / "sheet.csv", dtype=str, keep_default_na=False)
    result = cs.batch(sheet, archive / "py-df", base=archive)
    same_tables(cli_batch, archive / "py-df")
    assert result.outcome["ok"] == 3


def test_options_in_si_units_and_bad_keywords(archive):
    text = cs.archive.option_text
    assert text("pixel_size", 2e-7) == "2e-07m"
    assert text("forces", [1e-3, 2e-3]) == "0.001,0.002N"
    assert text("pixel_size", (2e-7, 2.1e-7)) == "2e-07x2.1e-07m"
    assert text("modulus", 3.7e9) == "3700000000.0Pa"
    assert text("k_range", (1e14, 1e17)) == "100000000000000.0Pa/m..1e+17Pa/m"
    assert text("axes", {"H": 0}) == "H=0"
    assert text("models", ["hardening", "gt"]) == "hardening,gt"
    assert cs.parse_pixel_size(text("pixel_size", 2e-7)) == (2e-7, 2e-7)
    with pytest.raises(cs.InputError, match="not a per-series option"):
        cs.batch(archive / "sheet.csv", archive / "bad", pixelsize="200nm")
    with pytest.raises(cs.InputError, match="pixel_size"):
        cs.batch(archive / "sheet.csv", archive / "bad", pixel_size="200parsecs")
    assert not (archive / "bad").exists()


def test_distributed_batch_equals_the_command_line(archive, cli_batch):
    with dd.local_client(n_workers=2) as client:
        result = dd.batch(archive / "sheet.csv", archive / "dask", client=client)
    same_tables(cli_batch, archive / "dask")
    assert result.outcome["failed"] == 1
    # The serial path, and a re-run with nothing to do.
    serial = dd.batch(archive / "sheet.csv", archive / "serial", client="serial")
    same_tables(cli_batch, archive / "serial")
    again = dd.batch(archive / "sheet.csv", archive / "serial", client="serial")
    assert again.outcome["analysed"] == 0
    pd.testing.assert_frame_equal(again.series, serial.series)


def test_a_walk_from_python(archive, cli):
    walked = archive / "walked"
    shutil.copytree(archive / "s1", walked / "a")
    shutil.copytree(archive / "s2", walked / "b")
    # b's TIFF states no pixel size: the batch's fills it; a keeps its own 200 nm.
    images = cs.read_series(walked / "b")["images"]
    cs.write_tiff(walked / "b" / "series.tif", images)
    result = cs.batch(walked, archive / "walk-out", pixel_size="250nm")
    assert list(result.series["series_id"]) == ["a", "b"]
    assert list(result.series["pixel_size_source"]) == [
        "ImageJ unit + X/YResolution", "batch default for files without one"]
    assert list(result.series["pixel_size_x_um"]) == [0.2, 0.25]
    assert (archive / "walk-out" / "samplesheet.csv").read_text().startswith(
        "id,input,pixel_size_default\na,../walked/a,250nm\n")
    assert os.path.exists(archive / "walk-out" / "index.html")


def test_python_batches_share_the_archive_fixes(tmp_path, monkeypatch):
    """cs.batch and distributed.batch run the same plan and series code as the command line:
    an Excel-made sheet (CRLF, a trailing empty row), a re-run from another working directory
    and of the archive moved as a whole reuse every series; the lock is gone afterwards."""
    lab = tmp_path / "lab"
    write_series(lab / "s1", 1)
    write_series(lab / "s2", 2)
    (lab / "sheet.csv").write_bytes(b"id,input,sample\r\ns1,s1,glass\r\ns2,s2,glass\r\n,,\r\n")
    monkeypatch.chdir(lab)
    first = cs.batch("sheet.csv", "results")
    assert first.outcome["analysed"] == 2
    assert not (lab / "results" / ".contactscope-batch.lock").exists()
    monkeypatch.chdir(tmp_path)
    again = cs.batch(lab / "sheet.csv", lab / "results")
    assert again.outcome["analysed"] == 0 and again.outcome["reused"] == 2
    moved = tmp_path / "moved"
    lab.rename(moved)
    result = dd.batch(moved / "sheet.csv", moved / "results", client="serial")
    assert result.outcome["analysed"] == 0
    pd.testing.assert_frame_equal(result.series, first.series)
