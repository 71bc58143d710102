"""The engine's revision: a change of the engine's code is recorded, and another revision's run is not resumed."""

import ast

import pytest

import hhscatter._version as version
import hhscatter.run.output as output
import hhscatter.run.worker as worker
import hhscatter.scene.scene as scene_mod
from hhscatter.data.read import read_meta
from hhscatter.errors import OutputError, RunIntegrityError
from hhscatter.run.runner import simulate
from hhscatter.scene.scene import Scene


def test_the_engine_s_code_is_the_one_its_revision_records():
    """A change of the engine's modules (docstrings and comments aside) fails here until it is recorded in
    hhscatter/_version.py: ENGINE_REVISION + 1 if a table can change, else only ENGINE_SOURCES_SHA256."""
    now = version.engine_sources_sha256()
    assert now == version.ENGINE_SOURCES_SHA256, (
        f"the engine's code changed (sha256 {now}): if a table can change, raise ENGINE_REVISION in "
        "hhscatter/_version.py; then record ENGINE_SOURCES_SHA256 = this hash"
    )


def test_the_code_hash_sees_code_not_docstrings_or_comments():
    a = 'def f(x):\n    """Doc."""\n    return x + 1  # one\n'
    b = 'def f(x):\n    """Another text."""\n    # a comment\n    return x + 1\n'
    c = 'def f(x):\n    """Doc."""\n    return x + 2\n'
    code = [version._code(ast.parse(s)) for s in (a, b, c)]
    assert code[0] == code[1] != code[2]


def test_revision_1_keeps_the_hashes_and_a_new_revision_changes_them(monkeypatch):
    sc = Scene(energy=0.3, n=10, seed=1)
    before = sc.result_hash()
    monkeypatch.setattr(scene_mod, "ENGINE_REVISION", 1)
    assert sc.result_hash() == before
    monkeypatch.setattr(scene_mod, "ENGINE_REVISION", 2)
    assert sc.result_hash() != before


def test_a_run_of_another_engine_revision_is_not_resumed_and_the_refusal_names_it(tmp_path, monkeypatch):
    sc = Scene(energy=0.3, n=200, seed=3, chunk_size=100)
    out = tmp_path / "r"
    simulate(sc, out, workers=1, progress=False)
    assert read_meta(out / "lifetimes" / "part-000000.parquet")["engine_revision"] == version.ENGINE_REVISION
    for mod in (scene_mod, worker, output):
        monkeypatch.setattr(mod, "ENGINE_REVISION", version.ENGINE_REVISION + 1)
    with pytest.raises(OutputError, match=rf"made by engine revision {version.ENGINE_REVISION} \(this engine: "):
        simulate(sc, out, workers=1, resume=True, progress=False)
    # without its manifest, the parts themselves say which engine made them
    (out / "scene.json").unlink()
    with pytest.raises(RunIntegrityError, match=rf"by engine revision {version.ENGINE_REVISION} \(this engine: "):
        simulate(sc, out, workers=1, resume=True, progress=False)
