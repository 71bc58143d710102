"""Strict configuration (hhscatter.scene.schema): every bad table, key or value type of a study.toml or scene file
exits with status 2 and one exact message before any work, and the checks change no scene's result_hash."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from old_code import code_at

from hhscatter.cli import main

ROOT = Path(__file__).resolve().parents[2]
BASE = "f701897"  # the code before the strict configuration (and the study rooms)


def _files(root: Path) -> list[str]:
    """The files below root (Python's bytecode caches of the study code aside)."""
    return sorted(str(p.relative_to(root)) for p in root.rglob("*") if "__pycache__" not in p.parts)


def _study_root(tmp_path: Path, name: str, edit) -> Path:
    """A studies root with a copy of the study's folder, its study.toml changed by ``edit(text) -> text``."""
    from study_copy import copy_study_folder

    root = tmp_path / "studies"
    copy_study_folder(name, root, edit)
    return root


def _run_study(root: Path, name: str, capsys, monkeypatch, tmp_path) -> tuple[int, str]:
    monkeypatch.setenv("HHSCATTER_STUDIES", str(root))
    monkeypatch.chdir(tmp_path)
    before = _files(tmp_path)
    rc = main(["study", name, "simulate", "--scale", "tiny", "--workers", "1"])
    err = capsys.readouterr().err
    assert _files(tmp_path) == before, "a refused configuration left files behind"
    assert "Traceback" not in err
    return rc, err.strip()


BAD_STUDY_FILES = [
    # (study, edit of its study.toml, exact message after "hhscatter: error: studies/<study>/study.toml: ")
    (
        "fig1",
        lambda t: t + '\n[sections]\nfirst_only = "no"\n',
        "[sections] first_only must be true or false, got 'no'",
    ),
    ("fig3", lambda t: t.replace("seed = 2026 ", "seed = true ", 1), "[scene] seed must be an integer, got true"),
    ("fig3", lambda t: t.replace("energy = 0.3 ", 'energy = "0.3" ', 1), "[scene] energy must be a number, got '0.3'"),
    (
        "fig6",
        lambda t: t.replace("[snapshots]", "[snapshot]", 1),
        "unknown table [snapshot] (did you mean 'snapshots'?); allowed tables: [about], [follow], [needs], [noise], [scale], [scene], [sections], "
        "[snapshots], [study], [system]",
    ),
    (
        "fig3",
        lambda t: t.replace("n_boot = 100 ", "n_bot = 100 ", 1),
        "[study] needs 'n_boot'\nstudies/fig3/study.toml: [study] unknown key 'n_bot' (did you mean 'n_boot'?); allowed keys: alt_window, "
        "authors_selection, authors_window, boot_seed, fit_window, hist_bins, hist_times, later_windows, n_boot, "
        "n_boot_orbits, paper_mu, paper_mu_half_unit, plot_t_max, ribbon_t, sliding_window, snapshot_grid",
    ),
    (
        "fig3",
        lambda t: t.replace("[scale.tiny.scene]\nn = 1200", "[scale.tiny.scene]\nn = 1200\nchunk = 600", 1),
        "[scale.tiny.scene] unknown key 'chunk' (did you mean 'chunk_size'?); allowed keys: batch_size, chunk_size, continue_settled, energy, "
        "gamma, ics, lam, momentum, n, name, omega, r_esc, r_far, radius, region, seed, t_max, tangent, tol",
    ),
    (
        "fig6",
        lambda t: t.replace('by = "rate"', 'by = "speed"', 1),
        "[study] mixtures[2].by must be one of 'energy', 'rate', got 'speed'",
    ),
    (
        "resc",
        lambda t: t.replace("n_follow = 300", 'n_follow = "300"', 1),
        "[scale.tiny.study] n_follow must be an integer, got '300'",
    ),
    (
        "fig5",
        lambda t: t.replace("summary = ", "summry = ", 1),
        "[about] unknown key 'summry' (did you mean 'summary'?); allowed keys: paper, setup, summary, title",
    ),
    ("fig4", lambda t: t.replace("\nmu_gamma = 0.01", "\n", 1), "[study] needs 'mu_gamma'"),
    (
        "fig5",
        lambda t: t.replace('sensitivity_momentum = "random"', 'sensitivity_momentum = "radial"', 1),
        "[study] sensitivity_momentum must be one of 'random', got 'radial'",
    ),
    (
        "fig5",
        lambda t: t.replace("seed = 505", 'seed = 505\nmomentum = "radial"', 1),
        "[scene] momentum must be one of 'tangential', 'random', got 'radial'",
    ),
]


@pytest.mark.parametrize("name, edit, message", BAD_STUDY_FILES)
def test_bad_study_file_exits_2_with_its_exact_message(name, edit, message, tmp_path, capsys, monkeypatch):
    root = _study_root(tmp_path, name, edit)
    rc, err = _run_study(root, name, capsys, monkeypatch, tmp_path)
    assert rc == 2
    assert err == f"hhscatter: error: studies/{name}/study.toml: {message}"


def test_every_problem_of_a_file_is_named_once(tmp_path, capsys, monkeypatch):
    root = _study_root(
        tmp_path,
        "fig3",
        lambda t: t.replace("seed = 2026 ", "seed = true ", 1).replace("tol = 1e-15", "tol = 1e-15\nt_mx = 3", 1),
    )
    rc, err = _run_study(root, "fig3", capsys, monkeypatch, tmp_path)
    assert rc == 2
    lines = err.splitlines()
    assert len(lines) == 2
    assert lines[0] == "hhscatter: error: studies/fig3/study.toml: [scene] seed must be an integer, got true"
    assert lines[1].startswith(
        "studies/fig3/study.toml: [scene] unknown key 't_mx' (did you mean 't_max'?); allowed keys: batch_size"
    )


BAD_SCENE_FILES = [
    (
        '[scene]\nenergy = 0.3\nn = 40\n[sections]\nfirst_only = "no"\n',
        "[sections] first_only must be true or false, got 'no'",
    ),
    ("[scene]\nenergy = 0.3\nn = 40\nseed = true\n", "[scene] seed must be an integer, got true"),
    ('[scene]\nenergy = "0.3"\nn = 40\n', "[scene] energy must be a number or a list of numbers, got '0.3'"),
    (
        "[scene]\nenergy = 0.3\nn = 40\n[snapshot]\nstart = 0\n",
        "unknown table [snapshot] (did you mean 'snapshots'?); allowed tables: [follow], [noise], [scale], [scene], [sections], [snapshots], [system]",
    ),
    (
        "[scene]\nenergy = 0.3\nn = 40\n[snapshots]\nstart = 0\nstop = 10\n",
        "[snapshots] needs 'times' or all of start, stop and step",
    ),
    (
        "[scene]\nenergy = [0.3, 0.35]\nn = 40\ngamma = [0, true]\n",
        "[scene] gamma must be a number or a list of numbers, got [0, true]",
    ),
    ("[scene]\nenergy = 0.3\nn = 40\n[scale.paper]\nn = 1e7\n", "[scale.paper] n must be an integer, got 10000000.0"),
]


@pytest.mark.parametrize("text, message", BAD_SCENE_FILES)
def test_bad_scene_file_exits_2_with_its_exact_message(text, message, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "scene.toml").write_text(text)
    before = _files(tmp_path)
    rc = main(["simulate", "scene.toml", "--out", "run", "--workers", "1"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and err == f"hhscatter: error: scene.toml: {message}"
    assert _files(tmp_path) == before  # no run folder, no scene.json


def test_text_for_a_number_is_refused_by_the_scene_itself():
    """A scene built in code gets the same answer (energy = "0.3" used to pass float() and crash in the engine)."""
    from hhscatter.scene.scene import Scene, SceneError, SectionWindow

    with pytest.raises(SceneError, match="energy must be a number, got '0.3'"):
        Scene(energy="0.3", n=10)
    with pytest.raises(SceneError, match="gamma must be a number, got True"):
        Scene(energy=0.3, n=10, gamma=True)
    with pytest.raises(SceneError, match="first_only must be true or false"):
        SectionWindow(first_only="no")


def test_a_refused_study_file_in_a_subprocess_prints_no_traceback(tmp_path):
    root = _study_root(tmp_path, "fig3", lambda t: t.replace("energy = 0.3 ", 'energy = "0.3" ', 1))
    env = {**os.environ, "HHSCATTER_STUDIES": str(root)}
    r = subprocess.run(
        [sys.executable, "-m", "hhscatter", "study", "fig3", "simulate", "--scale", "tiny"],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
    )
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert r.stderr.strip() == "hhscatter: error: studies/fig3/study.toml: [scene] energy must be a number, got '0.3'"
    assert _files(root) == sorted(
        ["conventions.toml", "fig3", *(f"fig3/{p.name}" for p in (ROOT / "studies" / "fig3").iterdir() if p.is_file())]
    )


def test_every_study_declares_its_study_table():
    from hhscatter.studies import load_study, study_names
    from hhscatter.studies.params import StudyParams

    for name in study_names():
        s = load_study(name, "tiny")
        assert s.params_model is not None and issubclass(s.params_model, StudyParams), name
        with pytest.raises(Exception, match="does not declare"):
            s.param("no_such_key")


# -- the checks change no scene: result_hash at every scale, against the code of main before them --------------
_HASHES = textwrap.dedent('''
    """Print {study/scale/key: result_hash} of the scenes each study's simulate stage makes (runs not executed)."""
    import json, sys
    import hhscatter.studies as st

    class Stop(Exception):
        pass

    out = {}
    names = [p.parent.name for p in sorted(st.studies_root().glob("*/study.toml"))]
    only = sys.argv[1].split(",") if len(sys.argv) > 1 and sys.argv[1] else names  # studies in both trees
    patch = json.loads(sys.argv[2]) if len(sys.argv) > 2 else {}  # {study: {scene key: value}} laid over [scene]
    for name in [n for n in names if n in only]:
        for scale in ("quick", "tiny", "paper"):
            study = st.load_study(name, scale)
            study.config.setdefault("scene", {}).update(patch.get(name, {}))
            base = dict(study.config.get("scene", {}))
            extra = {} if "energy" in base else {"energy": 0.3}
            out[f"{name}/{scale}/<base>"] = study.scene("base", **extra).result_hash()

            def run(key, scene, workers=None, progress=True, _n=name, _s=scale):
                out[f"{_n}/{_s}/{key}"] = scene.result_hash()
                return study.out / "no-such-run"  # stages that read a run's results stop here

            study.run = run
            try:
                st.stage_module(name).simulate(study, workers=1, progress=False)
            except Exception:
                pass
    json.dump(out, sys.stdout, sort_keys=True)
''')


def _scene_hashes(code_root: Path, cwd: Path, only=None, patch=None) -> dict:
    script = cwd / "hashes.py"
    script.write_text(_HASHES)
    env = {**os.environ, "PYTHONPATH": str(code_root)}
    env["HHSCATTER_STUDIES"] = str(code_root / "studies")  # the study files of that code
    args = [",".join(only or []), *([json.dumps(patch)] if patch else [])]
    r = subprocess.run([sys.executable, str(script), *args], cwd=cwd, env=env, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-3000:]
    return json.loads(r.stdout)


# the studies whose scenes the shared convention "paper" (studies/conventions.toml) changed: they ran with the
# tool's default r_esc = 1.5 before it; every other study (fig1-fig4 set 1.03 themselves, resc, basins) is unchanged
CONVENTION_CHANGED = {"fig5": {"r_esc": 1.03}, "fig6": {"r_esc": 1.03}}


def test_scene_hashes_of_every_study_and_scale_are_those_of_main_before_the_checks(tmp_path):
    old = code_at(BASE, tmp_path / "old", ("hhscatter", "studies"))
    before = _scene_hashes(old, old)
    # the studies that existed then (a study added since, e.g. basins, has no earlier hash to keep)
    then = sorted({k.split("/")[0] for k in before})
    after = _scene_hashes(ROOT, tmp_path, only=then)
    # every old scene is still made; the only new ones are the runs added since, by name
    added = {
        f"fig5/{scale}/{key}"
        for scale in ("quick", "tiny", "paper")
        for key in ("5a_authors", "5b_authors", "5a_authors_random", "5b_authors_random")
    }
    assert set(before) <= set(after) and set(after) - set(before) == added
    after = {k: after[k] for k in before}
    # changed on purpose for the paper scale: fig1's pilot keeps its quick-scale size (it fixes t_rec).
    # (fig2's runs after its pilots, e.g. the square-IC runs and the paper-scale N per energy, need a pilot's
    # result and are not reached here: their scenes are tested in test_study_fig1_fig2.)
    by_design = {k for k in before if k.startswith("fig1/paper/pilot_E")}
    assert by_design and all(after[k] != before[k] for k in by_design)
    before = {k: v for k, v in before.items() if k not in by_design}
    after = {k: v for k, v in after.items() if k not in by_design}
    assert len(before) >= 7 * 3 * 2  # every study, every scale: its base scene and at least one run
    moved = {k.split("/")[0] for k in CONVENTION_CHANGED}
    assert {"fig1", "fig2", "fig3", "fig4", "resc"} <= set(then) and moved <= set(then)
    # every other study keeps every scene
    assert {k: v for k, v in after.items() if k.split("/")[0] not in moved} == {
        k: v for k, v in before.items() if k.split("/")[0] not in moved
    }
    # fig5 and fig6: every scene changed, and by r_esc only (the old code with r_esc = 1.03 gives the new hashes)
    changed = {k for k in before if k.split("/")[0] in moved}
    assert changed and all(after[k] != before[k] for k in changed)
    patched = _scene_hashes(old, old, only=sorted(moved), patch=CONVENTION_CHANGED)
    assert patched == {k: after[k] for k in changed}


def test_the_engine_options_are_accepted_in_files(tmp_path):
    """sections.stop, [follow] radii and continue_settled pass the strict checks (and build their scenes)."""
    from hhscatter.scene.schema import load_scene

    (tmp_path / "a.toml").write_text(
        "[scene]\nenergy = 0.3\ngamma = 0.01\nn = 10\ncontinue_settled = true\n"
        "[snapshots]\nstart = 0\nstop = 10\nstep = 5\n"
        "[sections]\nt_from = 2.0\nfirst_only = true\nstop = true\n"
    )
    s = load_scene(tmp_path / "a.toml")
    assert s.continue_settled and s.sections.stop and s.snapshots == (0.0, 5.0, 10.0)
    (tmp_path / "b.toml").write_text('[scene]\nenergy = 0.3\nn = 10\nregion = "square"\n[follow]\nradii = [1.0, 2.0]\n')
    assert load_scene(tmp_path / "b.toml").follow.radii == (1.0, 2.0)


def test_study_code_receives_typed_params():
    """study.params.<key> has the declared Python type, whatever TOML wrote (1 for a Number is 1.0)."""
    from hhscatter.studies import load_study

    s = load_study("fig1", "tiny")
    assert all(type(e) is float for e in s.params.energies)
    assert type(s.params.pilot_n) is int and type(s.params.pilot_t_max) is float
    assert s.params.pilot_t_max == s.param("pilot_t_max")  # the raw value, equal
    with pytest.raises(Exception, match="does not declare"):
        _ = s.params.no_such_key
    s.params_read = set()
    _ = s.params.pilot_n
    assert s.params_read == {"pilot_n"}


def test_typed_params_converts_each_leaf_type():
    from hhscatter.scene.schema import Integer, Integers, NumberLists, NumberOr, Numbers, Text, typed_params
    from hhscatter.studies.params import StudyParams

    class Params(StudyParams):
        a: Integer
        b: Numbers
        c: NumberLists
        d: NumberOr("tau0")
        e: Integers = [1, 2]
        f: Text = "x"

    p = typed_params(Params, {"a": 3, "b": [1, 2.5], "c": [[0, 1]], "d": 2})
    assert (p.a, p.b, p.c, p.d, p.e, p.f) == (3, [1.0, 2.5], [[0.0, 1.0]], 2.0, [1, 2], "x")
    assert [type(x) for x in p.b] == [float, float] and type(p.d) is float
    assert typed_params(Params, {"a": 1, "b": [], "c": [], "d": "tau0"}).d == "tau0"
