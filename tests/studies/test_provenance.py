"""A study's numbers JSON records what it was made from and its own hash; the plot stage, a downstream analyze
and the report refuse numbers that were edited or are stale (naming the file), and `make report` tracks what the
report reads at every scale."""

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from hhscatter.errors import StudyError
from hhscatter.publish.report import build_report
from hhscatter.publish.report import main as report_main
from hhscatter.studies import run_stage
from hhscatter.studies.provenance import ProvenanceError, config_sha256, content_sha256, sealed, verify_numbers

ROOT = Path(__file__).resolve().parents[2]


def _doc(**extra):
    config = {"scene": {"energy": 0.3}, "study": {"fit_window": [0.0, 200.0]}}
    return sealed(
        {
            "study": "x",
            "mu": {"value": 0.9287, "err": 0.001},
            "config": config,
            "made_from": {"config_sha256": config_sha256(config), "upstream": {}, "raw_runs": {}},
            **extra,
        }
    ), config


def test_a_sealed_document_verifies_and_any_change_of_a_value_is_seen(tmp_path):
    doc, config = _doc()
    verify_numbers(tmp_path / "x.json", doc, config=config, scale="quick", upstream={})
    assert content_sha256(json.loads(json.dumps(doc, indent=4))) == doc["sha256"]  # re-indenting is not a change
    edited = {**doc, "mu": {"value": 0.91, "err": 0.001}}
    with pytest.raises(ProvenanceError, match=r"x.json was edited after it was written"):
        verify_numbers(tmp_path / "x.json", edited, config=config, scale="quick", upstream={})
    with pytest.raises(ProvenanceError, match=r"x.json is stale: the study's configuration at scale quick"):
        verify_numbers(
            tmp_path / "x.json",
            doc,
            config={**config, "study": {"fit_window": [0.0, 100.0]}},
            scale="quick",
            upstream={},
        )
    bare = {k: v for k, v in doc.items() if k not in ("sha256", "made_from")}
    with pytest.raises(ProvenanceError, match="carries no record of what it was made from"):
        verify_numbers(tmp_path / "x.json", bare, config=config, scale="quick", upstream={})


def test_numbers_made_from_another_upstream_json_are_stale(tmp_path):
    up, _ = _doc()
    config = {"scene": {}}
    down = sealed(
        {
            "config": config,
            "made_from": {
                "config_sha256": config_sha256(config),
                "upstream": {"up": content_sha256(up)},
                "raw_runs": {},
            },
        }
    )
    verify_numbers(
        tmp_path / "down.json", down, config=config, scale="quick", upstream={"up": (tmp_path / "up.json", up)}
    )
    newer = sealed({**up, "mu": {"value": 0.93, "err": 0.001}})  # up analyzed again since
    with pytest.raises(ProvenanceError, match=r"down.json is stale: it was made from another up.json"):
        verify_numbers(
            tmp_path / "down.json", down, config=config, scale="quick", upstream={"up": (tmp_path / "up.json", newer)}
        )


@pytest.fixture
def fig3_copy(tiny_studies, tmp_path):
    """fig3 at scale tiny as `make` leaves it (its raw runs, derived tables and numbers), in a root of its own."""
    root = tmp_path / "studies"
    shutil.copytree(tiny_studies / "fig3", root / "fig3")
    shutil.copy(tiny_studies / "conventions.toml", root / "conventions.toml")  # a studies folder is self-contained
    return root


def test_plot_and_report_refuse_a_hand_edited_numbers_json(fig3_copy, tmp_path, capsys):
    run_stage("fig3", "plot", "tiny", root=fig3_copy)  # as analyze wrote it: drawn
    path = fig3_copy / "fig3" / "out" / "tiny" / "fig3.json"
    doc = json.loads(path.read_text())
    doc["mu"]["value"] = 0.9100
    path.write_text(json.dumps(doc, indent=2))
    with pytest.raises(ProvenanceError, match=rf"{path} was edited after it was written"):
        run_stage("fig3", "plot", "tiny", root=fig3_copy)
    with pytest.raises(ProvenanceError, match=rf"{path} was edited after it was written"):
        build_report("tiny", out=tmp_path / "rep", root=fig3_copy)
    assert not (tmp_path / "rep").exists()  # nothing written


def test_plot_and_report_refuse_numbers_made_from_another_study_toml(fig3_copy, tmp_path):
    toml = fig3_copy / "fig3" / "study.toml"
    toml.write_text(toml.read_text().replace("[scale.tiny.study]\n", "[scale.tiny.study]\nfit_window = [0.0, 150.0]\n"))
    path = fig3_copy / "fig3" / "out" / "tiny" / "fig3.json"
    with pytest.raises(ProvenanceError, match=rf"{path} is stale: the study's configuration at scale tiny"):
        run_stage("fig3", "plot", "tiny", root=fig3_copy)
    with pytest.raises(ProvenanceError, match=rf"{path} is stale"):
        build_report("tiny", out=tmp_path / "rep", root=fig3_copy)


def test_the_report_refuses_an_unknown_scale(capsys):
    with pytest.raises(StudyError, match=r"scale must be one of \[[^]]*'paper'[^]]*\].*got 'nonexistent'"):
        build_report("nonexistent")
    assert report_main(["--scale", "nonexistent"]) == 2
    assert "report: error: scale must be one of" in capsys.readouterr().err


def _committed_paper_results(tmp_path):
    """A copy of the repository's study folders (study.toml) and committed paper-scale numbers, no raw run."""
    root = tmp_path / "repo" / "studies"
    for toml in (ROOT / "studies").glob("*/study.toml"):
        (root / toml.parent.name).mkdir(parents=True)
        shutil.copy(toml, root / toml.parent.name / "study.toml")
    shutil.copy(ROOT / "studies" / "conventions.toml", root / "conventions.toml")
    assets = tmp_path / "repo" / "docs" / "studies" / "assets" / "paper"
    assets.mkdir(parents=True)
    for f in (ROOT / "docs" / "studies" / "assets" / "paper").glob("*.json"):
        shutil.copy(f, assets / f.name)
    return root, assets


def test_the_paper_report_builds_from_the_committed_results_and_refuses_an_edited_one(tmp_path):
    root, assets = _committed_paper_results(tmp_path)
    res = build_report("paper", out=tmp_path / "rep", root=root)
    assert res["rows"] > 100
    doc = json.loads((assets / "fig3.json").read_text())
    doc["mu"]["value"] = 0.9100
    (assets / "fig3.json").write_text(json.dumps(doc, indent=2))
    with pytest.raises(ProvenanceError, match=rf"{assets / 'fig3.json'} was edited after it was written"):
        build_report("paper", out=tmp_path / "rep2", root=root)


def test_a_committed_result_made_from_another_upstream_copy_is_refused(tmp_path):
    root, assets = _committed_paper_results(tmp_path)
    doc = json.loads((assets / "fig3.json").read_text())
    doc["mu"]["value"] = 0.9100
    (assets / "fig3.json").write_text(json.dumps(sealed(doc), indent=2))  # fig3 made again, its readers not
    with pytest.raises(
        ProvenanceError, match=r"(fig5|fig6|basins|fig4).json is stale: it was made from another fig3.json"
    ):
        build_report("paper", out=tmp_path / "rep", root=root)


def _clean_checkout(tmp_path):
    """The repository as a fresh clone has it: the files git tracks or would track, from the working tree (ignored
    ones, such as a working copy's studies/*/out/, runs or .venv, are left out: make would remake them)."""
    if not (ROOT / ".git").exists():
        return ROOT  # not a git working tree: nothing was made here beyond the sources
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
    ).stdout.split(b"\0")
    dest = tmp_path / "clone"
    for name in filter(None, (f.decode() for f in listed)):
        src = ROOT / name
        if src.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / name)
    return dest


def _make_n(where, *args):
    """What `make report` would run from scratch (-B: as if nothing were made; -n: nothing is run)."""
    return subprocess.run(["make", "-n", "-B", "report", *args], cwd=where, capture_output=True, text=True, timeout=120)


def test_make_report_runs_the_studies_of_a_scale_without_committed_results_and_refuses_an_unknown_one(tmp_path):
    if shutil.which("make") is None:
        pytest.fail("make is not installed")
    where = _clean_checkout(tmp_path)
    tiny = _make_n(where, "SCALE=tiny")  # the report reads studies/*/out/tiny: it makes them
    assert "hhscatter study fig3 plot --scale tiny" in tiny.stdout, tiny.stdout + tiny.stderr
    assert "hhscatter.publish.report --scale tiny" in tiny.stdout
    bad = subprocess.run(
        ["make", "report", "SCALE=nonexistent"], cwd=where, capture_output=True, text=True, timeout=120
    )
    assert bad.returncode == 2 and "SCALE=nonexistent is not a scale of the studies" in bad.stderr
    paper = _make_n(where, "SCALE=paper")
    assert "hhscatter study" not in paper.stdout  # the committed results: no simulation


def test_an_edit_anywhere_in_the_library_an_analysis_runs_remakes_the_study(tmp_path):
    """make's rules list the analysis code of every subpackage (hhscatter/analysis/geometry/… too) and the plotting
    code: with a study's outputs up to date, editing one of them reruns its analysis or its plot, nothing else."""
    if shutil.which("make") is None:
        pytest.fail("make is not installed")
    import os
    import time

    where = _clean_checkout(tmp_path)
    made = [where / ".venv" / ".installed-stamp"] + [
        where / "studies" / "resc" / "out" / "tiny" / f for f in ("raw/done.json", "resc.json", "resc.png")
    ]
    later = time.time() + 60
    for i, f in enumerate(made):  # each output newer than every source and than the one before it
        f.parent.mkdir(parents=True, exist_ok=True)
        f.write_text("{}")
        os.utime(f, (later + i, later + i))
    target = "studies/resc/out/tiny/resc.png"

    def dry(*what_if):
        cmd = ["make", "-n", "SCALE=tiny", *(a for w in what_if for a in ("-W", w)), target]
        return subprocess.run(cmd, cwd=where, capture_output=True, text=True, timeout=120).stdout

    assert "hhscatter study" not in dry()  # up to date
    for edited in ("hhscatter/analysis/geometry/channels.py", "hhscatter/reproduction/escape_criterion.py"):
        out = dry(edited)
        assert "study resc analyze --scale tiny" in out and "simulate" not in out, (edited, out)
    out = dry("hhscatter/publish/figures.py")
    assert "study resc plot --scale tiny" in out and "analyze" not in out, out
