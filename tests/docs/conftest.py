"""The built site and the paper-scale reproduction report, once per test session: ``mkdocs build --strict`` into a
temporary folder (the browser tests and the site checks read it), and ``build_report("paper")`` from the committed
results into another."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def built_site(tmp_path_factory):
    pytest.importorskip("mkdocs", reason="no mkdocs: pip install -e '.[docs]'")
    out = tmp_path_factory.mktemp("site")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    mkdocs = [sys.executable, "-m", "mkdocs", "build", "--strict", "--quiet", "--site-dir", str(out)]
    proc = subprocess.run(mkdocs, cwd=ROOT, env=env, capture_output=True, text=True, timeout=900, check=False)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return out


@pytest.fixture(scope="session")
def paper_report_html(tmp_path_factory) -> str:
    """The HTML of the paper-scale reproduction report, built from the committed results."""
    from hhscatter.publish.report import build_report

    out = tmp_path_factory.mktemp("report")
    return build_report("paper", out=out, root=ROOT / "studies")["html"].read_text()
