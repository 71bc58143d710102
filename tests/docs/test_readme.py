"""The README tells the truth: its results block is what the committed JSON renders, its code runs as printed,
and the rest of its prose types no number it does not declare."""

from __future__ import annotations

import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

from hhscatter.publish import numbers as nb

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"


def _tool():
    spec = importlib.util.spec_from_file_location("readme_results", ROOT / "tools" / "readme_results.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _blocks(lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```", README.read_text(), flags=re.M | re.S)


def test_the_results_block_is_what_the_committed_json_renders():
    tool = _tool()
    assert tool.current(README.read_text(), tool.render()), "README.md is stale: run python tools/readme_results.py"


def test_the_targets_table_is_what_the_study_folders_render():
    """A row per study folder from its [about] and its cost record: a study folder added, or a cost record re-made,
    leaves the README stale until the tool runs."""
    tool = _tool()
    block = tool.render_targets()
    assert tool.current(README.read_text(), block), "README.md is stale: run python tools/readme_results.py"
    studies = sorted(p.parent.name for p in (ROOT / "studies").glob("*/study.toml"))
    assert sorted(re.findall(r"^\| `make (\w+)` \|", block, flags=re.M)) == sorted([*studies, "studies"])


def test_a_new_study_folder_is_a_new_row(tmp_path):
    """The table is read from the folders: a copy of the tree with one more study gets one more row, with its
    title, summary and CPU minutes, and a total that includes it."""
    import json
    import shutil

    tool = _tool()
    shutil.copytree(ROOT / "studies", tmp_path / "studies", ignore=shutil.ignore_patterns("out"))
    shutil.copytree(ROOT / "docs" / "studies" / "assets", tmp_path / "docs" / "studies" / "assets",
                    ignore=shutil.ignore_patterns("*.png", "paper"))  # fmt: skip
    (tmp_path / "hhscatter").symlink_to(ROOT / "hhscatter")
    new = tmp_path / "studies" / "zeta"
    new.mkdir()
    (new / "study.toml").write_text('[about]\ntitle = "Zeta"\npaper = ""\nsummary = "a check of its own"\n')
    run = {"stage": "simulate", "wall_s": 90.0, "cpu_s": 90.0, "orbits": 1, "rss_self_mb": 1.0, "rss_children_mb": 1.0}
    cost = {"simulate": [run], "analyze": []}
    (tmp_path / "docs" / "studies" / "assets" / "zeta.cost.json").write_text(json.dumps(cost))
    before, after = tool.render_targets(ROOT), tool.render_targets(tmp_path)
    assert "| `make zeta` | beyond the paper: Zeta — a check of its own | 1.5 |" in after

    def total(block):
        return float(re.search(r"^\| `make studies` \|[^\n]*\| ([0-9.]+) \|$", block, flags=re.M).group(1))

    assert abs(total(after) - total(before) - 1.5) <= 0.051  # each total rounded to 0.1


def test_outside_its_generated_block_the_readme_types_no_undeclared_number():
    tool = _tool()
    text = README.read_text()
    for begin, end in ((tool.BEGIN, tool.END), (tool.TARGETS_BEGIN, tool.TARGETS_END)):
        i, j = text.index(begin), text.index(end)
        text = text[:i] + "\n" * text[i:j].count("\n") + text[j:]
    rest = text
    studies = sorted(p.parent.name for p in (ROOT / "studies").glob("*/page.md"))
    allowed = set().union(*(nb.study_conventions(ROOT, s) for s in studies))
    assert nb.stray_numbers(rest, allowed) == []


def test_the_target_table_s_cpu_minutes_are_the_committed_cost_records():
    """Each study row of the README's target table states the CPU minutes of its committed quick-scale cost record
    (hhscatter.studies.cost.summary), to the table's one decimal; the `make studies` row their sum."""
    import json

    from hhscatter.studies.cost import summary

    rows = re.findall(r"^\| `make (\w+)` \|[^\n]*\| ([0-9.]+) \|$", README.read_text(), flags=re.M)
    studies = {p.parent.name for p in (ROOT / "studies").glob("*/study.toml")}
    total = [float(v) for name, v in rows if name == "studies"]
    rows = [(name, float(v)) for name, v in rows if name in studies]
    assert {name for name, _ in rows} == studies  # a row per study folder
    assets = ROOT / "docs" / "studies" / "assets"
    minutes = {name: summary(json.loads((assets / f"{name}.cost.json").read_text()))["cpu_s"] / 60 for name in studies}
    for name, stated in rows:
        assert stated == round(minutes[name], 1), f"make {name}: README says {stated}, the record {minutes[name]:.2f}"
    assert total == [round(sum(minutes.values()), 1)]  # make studies: all of them


def test_the_readme_python_and_sql_run_as_printed(tmp_path):
    """The README's Python and DuckDB snippets, verbatim, on the demo runs' layout (a 400-orbit conservative and a
    300-orbit dissipative scene written where the snippets look: runs/demo/…)."""
    py, sql = _blocks("python"), _blocks("sql")
    assert py and sql
    setup = (
        "import hhscatter\n"
        "from hhscatter.scene.scene import Scene\n"
        "hhscatter.simulate(Scene(energy=0.27, n=400, seed=1), 'runs/demo/conservative', workers=1, progress=False)\n"
        "hhscatter.simulate(Scene(energy=0.3, gamma=0.01, n=300, seed=2), 'runs/demo/dissipative', workers=1,"
        " progress=False)\n"
    )
    statements = [q.strip() for q in re.sub(r"(?m)^--.*$", "", "\n".join(sql)).split(";") if q.strip()]
    env = {**os.environ, "MPLBACKEND": "Agg"}
    made = subprocess.run(
        [sys.executable, "-c", setup], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300, check=False
    )
    assert made.returncode == 0, made.stderr[-3000:]
    code = "\n".join(py) + "\nimport duckdb\n" + "".join(f"print(duckdb.sql({q!r}).fetchall())\n" for q in statements)
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300, check=False
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "escaped" in proc.stdout
