"""The Systems page shows the built-ins' numbers as the systems derive them today (tools/system_gallery.py)."""

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_systems_page_table_is_the_systems_own_and_its_figures_exist():
    spec = importlib.util.spec_from_file_location("system_gallery", ROOT / "tools" / "system_gallery.py")
    gallery = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(gallery)
    page = (ROOT / "docs" / "concepts" / "systems.md").read_text()
    assert gallery.markdown_table() in page, "rerun: .venv/bin/python tools/system_gallery.py"
    for s in gallery.gallery():
        assert (ROOT / "docs" / "concepts" / "systems" / f"{s['name']}.png").stat().st_size > 10_000
