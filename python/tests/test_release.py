"""What a release promises, from the installed package: one version everywhere (the package's
metadata, ``__version__``, the command line's ``--version``, the JSON files it writes) and the
licence audit's reading of SPDX expressions (scripts/licence-audit)."""

import importlib.machinery
import importlib.metadata
import importlib.util
import json
import re

import pytest

import contactscope as cs

from conftest import ROOT


def test_version_is_the_distributions_and_the_command_lines(cli):
    assert cs.__version__ == importlib.metadata.version("contactscope")
    assert re.fullmatch(r"\d+\.\d+\.\d+", cs.__version__)
    line = cli("--version").strip()
    expected = f"contactscope {cs.__version__}"
    if cs.__source_revision__ is not None:
        assert re.fullmatch(r"[0-9a-f]{40}( \(modified\))?", cs.__source_revision__)
        expected += f" (source {cs.__source_revision__})"
    assert line == expected


def test_summary_json_names_version_and_source_revision(tmp_path):
    series = cs.synth_series(width=128, height=128, forces=[4e-3, 10e-3, 25e-3], seed=7)
    cs.analyze(series["images"], forces=series["forces_n"], pixel_size=2e-7, out=tmp_path / "a")
    summary = json.loads((tmp_path / "a" / "summary.json").read_text())
    assert list(summary)[:3] == ["contactscope_version", "source_revision", "command_line"]
    assert summary["contactscope_version"] == cs.__version__
    assert summary["source_revision"] == cs.__source_revision__


def _audit():
    path = ROOT / "scripts" / "licence-audit"
    if not path.exists():
        pytest.skip("scripts/licence-audit is not beside these tests")
    loader = importlib.machinery.SourceFileLoader("licence_audit", str(path))
    spec = importlib.util.spec_from_loader("licence_audit", loader)
    module = importlib.util.module_from_spec(spec)
    loader.exec_module(module)
    return module


@pytest.mark.parametrize("expression, ok", [
    ("MIT OR Apache-2.0", True),
    ("MIT/Apache-2.0", True),
    ("Apache-2.0 WITH LLVM-exception OR Apache-2.0 OR MIT", True),
    ("(MIT OR Apache-2.0) AND Unicode-3.0", True),
    ("(MIT OR GPL-3.0) AND Zlib", True),
    ("GPL-3.0", False),
    ("MIT AND GPL-3.0", False),
    ("MPL-2.0", False),
    ("LGPL-3.0 OR GPL-2.0", False),
    ("GPL-2.0 WITH Classpath-exception-2.0", False),
    ("Apache-2.0 WITH Classpath-exception-2.0", False),
])
def test_licence_audit_reads_spdx(expression, ok):
    assert _audit().spdx_ok(expression) is ok


@pytest.mark.parametrize("expression", ["", "MIT OR", "(MIT", "MIT Apache-2.0"])
def test_licence_audit_refuses_what_it_cannot_read(expression):
    with pytest.raises(ValueError):
        _audit().spdx_ok(expression)
