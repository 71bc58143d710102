"""The studies' one declared dependency graph (study.toml [about], [needs]) and what is derived from it:
the Makefile's rules, the build order, the report and the docs navigation."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from hhscatter.studies import graph

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ROOT / "studies"


def _study(root: Path, name: str, needs: dict | None = None, paper: str = "Fig. 1"):
    (root / name).mkdir(parents=True)
    lines = ["[about]", f'title = "{name}"', f'paper = "{paper}"', f'summary = "what {name} does"']
    if needs:
        lines += ["[needs]", *(f'{k} = "{v}"' for k, v in needs.items())]
    (root / name / "study.toml").write_text("\n".join([*lines, "[scene]", "n = 1", ""]))


def test_every_study_folder_declares_what_it_is_and_needs():
    infos = graph.studies(STUDIES)
    names = [s.name for s in infos]
    assert set(names) == {p.parent.name for p in STUDIES.glob("*/study.toml")}
    for s in infos:
        assert s.title and s.summary, s.name
        # every study comes after the studies it needs
        assert all(names.index(u) < names.index(s.name) for u in s.upstream), s.name
    by = {s.name: s for s in infos}
    assert by["fig5"].upstream == ("fig1", "fig3") and by["fig6"].upstream == ("fig2", "fig3", "fig4")
    assert by["resc"].beyond_paper and not by["fig1"].beyond_paper
    assert graph.upstream_closure("fig6", STUDIES) == ["fig2", "fig3", "fig4", "fig6"]


def test_graph_refuses_unknown_upstreams_and_cycles(tmp_path):
    _study(tmp_path / "a", "x", {"mu": "nope"})
    with pytest.raises(graph.GraphError, match="needs 'nope', which is not a study folder"):
        graph.studies(tmp_path / "a")
    _study(tmp_path / "b", "x", {"p": "y"})
    _study(tmp_path / "b", "y", {"p": "x"})
    with pytest.raises(graph.GraphError, match="cycle"):
        graph.studies(tmp_path / "b")
    _study(tmp_path / "c", "x", {"p": "z"})
    _study(tmp_path / "c", "z")
    _study(tmp_path / "c", "a", {"q": "x"})
    assert [s.name for s in graph.studies(tmp_path / "c")] == ["z", "x", "a"]


def _repo(tmp_path: Path) -> Path:
    """A copy of the Makefile, the graph module and the study folders' study.toml."""
    work = tmp_path / "repo"
    (work / "hhscatter" / "studies").mkdir(parents=True)
    shutil.copy(ROOT / "Makefile", work / "Makefile")
    (work / "pyproject.toml").touch()
    shutil.copy(ROOT / "hhscatter" / "studies" / "graph.py", work / "hhscatter" / "studies" / "graph.py")
    for toml in STUDIES.glob("*/study.toml"):
        (work / "studies" / toml.parent.name).mkdir(parents=True)
        shutil.copy(toml, work / "studies" / toml.parent.name / "study.toml")
    return work


def _dry_run(work: Path, target: str) -> list[str]:
    """`make -n -B <target> SCALE=tiny` in ``work``: the study stage commands, in order."""
    r = subprocess.run(
        ["make", "-n", "-B", target, "SCALE=tiny", f"PYTHON={sys.executable}"],
        cwd=work,
        capture_output=True,
        text=True,
        check=True,
    )
    return re.findall(r"hhscatter study (\w+) (simulate|analyze|plot) --scale tiny", r.stdout)


def test_make_builds_the_studies_a_study_needs_first(tmp_path):
    steps = _dry_run(_repo(tmp_path), "fig6")
    assert {s for s, _ in steps} == {"fig2", "fig3", "fig4", "fig6"}
    at = {step: i for i, step in enumerate(steps)}
    for up in ("fig2", "fig3", "fig4"):
        assert at[(up, "analyze")] < at[("fig6", "analyze")]
    assert ("fig2", "plot") not in at  # an upstream's numbers are needed, not its figure
    assert at[("fig3", "analyze")] < at[("fig4", "analyze")]  # fig4 reads fig3's μ too


def test_a_new_study_folder_gets_make_rules_without_editing_the_makefile(tmp_path):
    work = _repo(tmp_path)
    assert _dry_run(work, "help") == []
    _study(work / "studies", "figx", {"c": "fig1"})
    steps = _dry_run(work, "figx")
    assert ("fig1", "analyze") in steps and steps[-1] == ("figx", "plot")
    help_text = subprocess.run(
        ["make", "help", f"PYTHON={sys.executable}"], cwd=work, capture_output=True, text=True, check=True
    ).stdout
    assert "figx" in help_text and "what figx does (needs fig1)" in help_text


def test_report_and_docs_nav_list_the_study_folders():
    from hhscatter.publish.report import collect

    assert [s.key for s in collect("tiny", STUDIES)] == [s.name for s in graph.studies(STUDIES)]
    spec_path = ROOT / "docs" / "_hooks" / "studies.py"
    from tests.docs.test_docs import _load

    hook = _load(spec_path, "hh_docs_hook_graph")
    nav = hook.study_pages(ROOT)
    assert [next(iter(d.values())) for d in nav] == [f"studies/{s.name}.md" for s in graph.studies(STUDIES)]
    assert [next(iter(d)) for d in nav] == [s.title for s in graph.studies(STUDIES)]


def _study_code(name: str) -> list[Path]:
    """The Python files of one study: the modules of its folder (the package hhscatter_study_<name>)."""
    return sorted((STUDIES / name).glob("*.py"))


def _imported_modules(path: Path, package: str) -> set[str]:
    """Absolute names of every module a file imports (relative imports resolved against ``package``)."""
    import ast

    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join([*parts, *([base] if base else [])])
            out.add(base)
            out |= {f"{base}.{a.name}" for a in node.names}
    return out


def test_no_study_imports_another_or_reads_its_raw_runs():
    from hhscatter.studies import _upstream

    names = [s.name for s in graph.studies(STUDIES)]
    for name in names:
        others = [o for o in names if o != name]
        files = _study_code(name)
        assert files, f"studies/{name} has no modules"
        for path in files:
            mods = _imported_modules(path, f"hhscatter_study_{name}")
            bad = {
                m
                for m in mods
                for o in others
                if re.search(rf"(^|\.)(studies|plotting)\.{o}(\.|$)", m)
                or m.endswith(f"studies.{o}")
                or re.match(rf"(hhscatter_study_)?{o}(\.|$)", m)
            }
            assert not bad, f"{path.relative_to(ROOT)} imports another study: {sorted(bad)}"
            text = path.read_text()
            # other studies are reached through their published outputs only (_upstream.numbers / table)
            assert "load_study(" not in text, path
    assert not hasattr(_upstream, "raw_dir")


def test_a_study_is_one_folder():
    """Everything a study is lives in studies/<name>/: parameters, stages, figure code and docs page."""
    from hhscatter.studies import stage_module

    for s in graph.studies(STUDIES):
        folder = STUDIES / s.name
        assert {"study.toml", "study.py", "figure.py", "page.md"} <= {p.name for p in folder.iterdir()}, s.name
        mod = stage_module(s.name)
        assert Path(mod.__file__) == folder / "study.py"
        assert all(callable(getattr(mod, st)) for st in ("simulate", "analyze", "plot"))
        assert not (ROOT / "hhscatter" / "studies" / f"{s.name}.py").exists()
        assert not (ROOT / "hhscatter" / "plotting" / f"{s.name}.py").exists()
        assert not (ROOT / "docs" / "studies" / f"{s.name}.md").exists()


def test_the_analysis_layer_is_pure():
    """No heyoka, no engine or runner, no file I/O under hhscatter/analysis: arrays or DataFrames in, results out."""
    import ast

    banned_modules = (
        "heyoka",
        "pyarrow",
        "hhscatter.integrate.engine",
        "hhscatter.run.runner",
        "hhscatter.data.read",
        "hhscatter.data.write",
        "hhscatter.data.schema",
        "hhscatter.data.store",
        "hhscatter.studies",
    )
    banned_calls = {
        "open",
        "read_text",
        "write_text",
        "read_bytes",
        "write_bytes",
        "read_parquet",
        "to_parquet",
        "to_csv",
        "read_csv",
        "savefig",
    }
    for path in sorted((ROOT / "hhscatter" / "analysis").glob("*.py")):
        mods = _imported_modules(path, "hhscatter.analysis")
        bad = {m for m in mods for b in banned_modules if m == b or m.startswith(b + ".")}
        assert not bad, f"{path.name} imports {sorted(bad)}"
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call):
                name = getattr(node.func, "attr", getattr(node.func, "id", None))
                assert name not in banned_calls, f"{path.name}:{node.lineno} calls {name}()"


def test_convention_label_says_the_studys_own_setup():
    """A study whose ICs are not its [scene]'s region says so ([about] setup); the others name the region."""
    from hhscatter.studies import load_study

    basins = load_study("basins", "quick").convention_label
    assert "disk" not in basins and basins.startswith("grid over the square") and basins.endswith("r_esc 1.5")
    assert load_study("fig2", "quick").convention_label.endswith("disk r < 0.5, r_esc 1.03")


def test_the_studies_folder_is_that_of_the_repository_the_command_runs_in(tmp_path, monkeypatch, copy_study):
    """From a repository (or below it) its own studies/; elsewhere an error naming the way out; --studies or
    HHSCATTER_STUDIES name one explicitly. Outputs go into the study's own folder."""
    from hhscatter.errors import StudyError
    from hhscatter.studies import load_study, studies_root

    monkeypatch.delenv("HHSCATTER_STUDIES", raising=False)
    monkeypatch.chdir(ROOT)
    assert load_study("fig2").out == ROOT / "studies" / "fig2" / "out" / "quick"  # make's layout
    monkeypatch.chdir(ROOT / "studies" / "fig2")
    assert studies_root() == ROOT / "studies"
    monkeypatch.chdir(tmp_path)
    with pytest.raises(StudyError, match="no studies folder in .* --studies DIR"):
        load_study("fig2")
    own = tmp_path / "mine"
    copy_study("fig2", own)
    assert load_study("fig2", root=own).out == own / "fig2" / "out" / "quick"  # a studies folder of one's own
    monkeypatch.setenv("HHSCATTER_STUDIES", str(own))
    assert studies_root() == own


def test_a_second_clone_using_this_virtualenv_reads_its_own_study_files(tmp_path):
    """This checkout's virtualenv imports this checkout's hhscatter (an editable install); a command run in another
    clone must still read that clone's study.toml and study code, and write into that clone."""
    clone = tmp_path / "clone"
    shutil.copytree(STUDIES / "fig1", clone / "studies" / "fig1", ignore=shutil.ignore_patterns("out", "__pycache__"))
    shutil.copy(STUDIES / "conventions.toml", clone / "studies" / "conventions.toml")
    toml = clone / "studies" / "fig1" / "study.toml"
    text = toml.read_text()
    n = re.search(r"\[scale\.tiny\.scene\]\s*\nn = (\d+)", text)
    assert n, "fig1 has a [scale.tiny.scene] n"
    toml.write_text(text[: n.start(1)] + "123" + text[n.end(1) :])
    (clone / "studies" / "fig1" / "study.py").write_text(
        (STUDIES / "fig1" / "study.py").read_text() + "\nCLONE_MARK = 1\n"
    )
    code = (
        "from hhscatter.studies import load_study, stage_module\n"
        "s = load_study('fig1', 'tiny')\n"
        "print(s.config['scene']['n'], s.out, stage_module('fig1').CLONE_MARK)\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "HHSCATTER_STUDIES"}
    r = subprocess.run(
        [sys.executable, "-c", code], cwd=clone / "studies" / "fig1", env=env, capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout.split() == ["123", str(clone / "studies" / "fig1" / "out" / "tiny"), "1"]
