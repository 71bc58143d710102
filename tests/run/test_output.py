"""The run directory: --overwrite removes only what the run's manifest lists, --out names a directory, and the
write lock survives the deletion of its file.

Each case used to lose data or let two writers mix their parts; each is now refused before anything is removed
or written.
"""

import json
import os

import pytest

from hhscatter.data.store import LOCK_FILE, LockedError, Store
from hhscatter.errors import ConfigError, OutputError
from hhscatter.run.runner import simulate
from hhscatter.scene.grid import Grid
from hhscatter.scene.scene import Scene

SCENE = Scene(energy=0.3, n=40, seed=2, chunk_size=20, t_max=30.0, gamma=0.01)


def _files(d):
    return sorted(p.relative_to(d).as_posix() for p in d.rglob("*") if p.is_file())


@pytest.fixture
def run(tmp_path):
    out = tmp_path / "run"
    simulate(SCENE, out, workers=1, progress=False)
    return out


def test_overwrite_refuses_a_file_the_run_did_not_write_and_removes_nothing(run):
    (run / "lifetimes" / "thesis.tex").write_text("months of work")
    before = _files(run)
    with pytest.raises(
        OutputError,
        match=r"--overwrite: .*run holds 1 entry its run's manifest does not list \(first: "
        r".*lifetimes/thesis.tex\); hhscatter removes only what it wrote.*Nothing "
        "was removed",
    ):
        simulate(SCENE.replace(seed=3), run, workers=1, progress=False, overwrite=True)
    assert _files(run) == before


def test_overwrite_refuses_a_folder_that_holds_no_run(tmp_path):
    out = tmp_path / "notes"
    out.mkdir()
    (out / "notes.txt").write_text("x")
    with pytest.raises(
        OutputError,
        match=r"--overwrite: .*notes holds no hhscatter run \(no scene.json: its manifest\) "
        r"but 1 entry \(first: notes.txt\)",
    ):
        simulate(SCENE, out, workers=1, progress=False, overwrite=True)
    assert _files(out) == ["notes.txt"]


def test_overwrite_removes_exactly_the_manifests_files(tmp_path):
    out = tmp_path / "grid"
    grid = Grid(SCENE, energies=(0.3, 0.35), gammas=(0.01,))
    simulate(grid, out, workers=1, progress=False)
    (out / "lifetimes" / ".part-000000.parquet.tmp-123").write_text("left by a killed writer")
    simulate(SCENE.replace(n=20), out, workers=1, progress=False, overwrite=True)
    # the grid's point folders are gone with their parts; only the new plain run is there
    assert _files(out) == [LOCK_FILE, "lifetimes/part-000000.parquet", "scene.json"]
    assert json.loads((out / "scene.json").read_text())["manifest"]["points"][0]["n"] == 20


@pytest.mark.parametrize("out", ["", "   "])
def test_out_must_name_a_directory(tmp_path, out, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(
        ConfigError,
        match=r"out must name a directory \(or a URL\), got '\s*'; the working directory "
        "is '.'",
    ):
        simulate(SCENE, out, workers=1, progress=False)
    assert os.listdir(tmp_path) == []


def test_the_lock_survives_the_deletion_of_its_file(run):
    held = Store(run).lock()
    try:
        os.remove(run / LOCK_FILE)  # what a cleanup script (or a user) does while the run writes
        with pytest.raises(LockedError, match="is being written by another process"):
            Store(run).lock()
        with pytest.raises(OutputError, match="is being written by another process.*one writer per run directory"):
            simulate(SCENE, run, workers=1, progress=False, overwrite=True)
        assert Store(run).writer() == "?"  # its pid note is gone, the lock is not
    finally:
        Store.unlock(held)
    assert Store(run).writer() is None


def test_workers_are_bounded(tmp_path):
    with pytest.raises(ConfigError, match=r"workers must be ≤ 1024, got 1000000 \(one process each"):
        simulate(SCENE, tmp_path / "w", workers=10**6, progress=False)
    assert not (tmp_path / "w").exists()
