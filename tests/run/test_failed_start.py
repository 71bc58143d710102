"""A run that fails before its first chunk leaves nothing behind; --resume needs a run to continue."""

from __future__ import annotations

import pytest

import hhscatter
from hhscatter.errors import OutputError
from hhscatter.run import runner

SCENE = hhscatter.Scene(energy=0.3, n=40, t_max=5.0, chunk_size=20)


def _crash(*args, **kwargs):
    raise RuntimeError("the backend could not start")


@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt])
def test_a_failed_start_leaves_nothing_and_the_same_run_starts_again(tmp_path, monkeypatch, exc):
    out = tmp_path / "run"

    def fail(*args, **kwargs):
        raise exc("stopped at the start")

    monkeypatch.setattr(runner, "_simulate", fail)
    with pytest.raises(exc):
        hhscatter.simulate(SCENE, out, workers=1, progress=False)
    assert not out.exists()
    monkeypatch.undo()
    assert hhscatter.simulate(SCENE, out, workers=1, progress=False).n == 40  # not refused as "not empty"


def test_a_failed_start_in_an_existing_folder_keeps_the_folder_and_empties_it(tmp_path, monkeypatch):
    out = tmp_path / "run"
    out.mkdir()
    monkeypatch.setattr(runner, "_simulate", _crash)
    with pytest.raises(RuntimeError):
        hhscatter.simulate(SCENE, out, workers=1, progress=False)
    assert out.is_dir() and list(out.iterdir()) == []


def test_a_run_that_wrote_a_chunk_is_kept_for_resume(tmp_path, monkeypatch):
    out = tmp_path / "run"
    real = runner.run_one_chunk
    calls = []

    def second_chunk_fails(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise RuntimeError("lost the machine")
        return real(*args, **kwargs)

    monkeypatch.setattr(runner, "run_one_chunk", second_chunk_fails)
    with pytest.raises(RuntimeError):
        hhscatter.simulate(SCENE, out, workers=1, progress=False)
    assert (out / "scene.json").exists() and list((out / "lifetimes").glob("part-*"))
    monkeypatch.undo()
    summary = hhscatter.simulate(SCENE, out, workers=1, progress=False, resume=True)
    assert summary.chunks_skipped == 1


def test_resume_into_a_folder_without_a_run_is_refused_and_touches_nothing(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("my notes")
    with pytest.raises(OutputError, match=r"holds no hhscatter run \(no scene.json: its manifest\).*notes.txt"):
        hhscatter.simulate(SCENE, out, workers=1, progress=False, resume=True)
    assert sorted(p.name for p in out.iterdir()) == ["notes.txt"]
    assert (out / "notes.txt").read_text() == "my notes"
