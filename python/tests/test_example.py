"""The paper-workflow example runs end to end (analysis, Dask fit, comparison, plot)."""

import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

pytest.importorskip("dask.distributed")
pytest.importorskip("matplotlib")
pytest.importorskip("pandas")


def test_paper_workflow_example(tmp_path):
    script = ROOT / "examples" / "paper_workflow.py"
    out = tmp_path / "out"
    done = subprocess.run([sys.executable, str(script), "--out", str(out)], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300, env=dict(os.environ))
    assert done.returncode == 0, done.stderr
    # The cluster shuts down cleanly: no tracebacks or scheduler errors at exit.
    for noise in ("Traceback", "CommClosedError", "- ERROR -"):
        assert noise not in done.stderr, done.stderr[-2000:]
    png = out / "paper_workflow.png"
    assert png.stat().st_size > 10_000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    summary = json.loads((out / "summary.json").read_text())
    # The fit found an interior k with a small misfit, and the maps were scored.
    assert 0.1 < summary["k_MPa_per_nm"] < 100
    assert summary["misfit"] < 0.2
    assert len(summary["dice"]) == 5 and all(0 < d <= 1 for d in summary["dice"])
    # The areas grow sublinearly with the load, as the paper's.
    assert 0.6 < summary["power_law_exponent"] < 1.0
    assert "k =" in done.stdout
    # The map is large enough: the simulated contact never reaches its border.
    assert not any(summary["edge_contact"])
