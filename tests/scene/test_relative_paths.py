"""A path in a scene file is relative to the file's folder, and a run's scene.json names one file."""

from __future__ import annotations

import json

import numpy as np

import hhscatter
from hhscatter.cli import main
from hhscatter.scene.schema import scene_dict_from_toml

STATES_FILE = "x,y,px,py\n0.1,0.05,0.6,0.1\n0.0,0.2,0.55,0.0\n"
STATES_CWD = "x,y,px,py\n0.3,0.0,0.0,0.5\n0.0,-0.3,0.5,0.0\n"


def _layout(tmp_path):
    """scenes/scene.toml with ics = "ic.csv" beside it, and a different ic.csv in the working directory."""
    scenes, cwd = tmp_path / "scenes", tmp_path / "work"
    scenes.mkdir()
    cwd.mkdir()
    (scenes / "ic.csv").write_text(STATES_FILE)
    (cwd / "ic.csv").write_text(STATES_CWD)
    (scenes / "scene.toml").write_text('[scene]\nics = "ic.csv"\nn = 2\nt_max = 5.0\n')
    return scenes, cwd


def test_scene_file_ics_is_relative_to_the_file(tmp_path, monkeypatch):
    scenes, cwd = _layout(tmp_path)
    monkeypatch.chdir(cwd)
    assert scene_dict_from_toml(scenes / "scene.toml")["ics"] == str(scenes / "ic.csv")
    assert hhscatter.load_scene(scenes / "scene.toml").ics == str(scenes / "ic.csv")


def test_cli_run_reads_the_table_beside_the_scene_file_and_records_its_absolute_path(tmp_path, monkeypatch, capsys):
    scenes, cwd = _layout(tmp_path)
    monkeypatch.chdir(cwd)
    assert main(["simulate", str(scenes / "scene.toml"), "--out", "run", "--workers", "1", "--no-progress"]) == 0
    doc = json.loads((cwd / "run" / "scene.json").read_text())
    assert doc["scene"]["ics"] == str(scenes / "ic.csv")
    lt = hhscatter.read_lifetimes(cwd / "run").sort_values("traj_id")
    np.testing.assert_array_equal(lt[["x0", "y0"]].to_numpy(), [[0.1, 0.05], [0.0, 0.2]])


def test_python_scene_with_a_relative_ics_names_an_absolute_path(tmp_path, monkeypatch):
    (tmp_path / "ic.csv").write_text(STATES_FILE)
    monkeypatch.chdir(tmp_path)
    assert hhscatter.Scene(energy=None, n=2, ics="ic.csv").ics == str(tmp_path / "ic.csv")


def test_study_toml_ics_is_relative_to_the_study_folder(tmp_path, monkeypatch):
    from hhscatter.studies import Study

    folder, cwd = tmp_path / "mystudy", tmp_path / "work"
    folder.mkdir()
    cwd.mkdir()
    (folder / "ic.csv").write_text(STATES_FILE)
    monkeypatch.chdir(cwd)
    study = Study(name="mystudy", scale="quick", config={"scene": {"ics": "ic.csv", "n": 2}}, root=folder)
    assert study.scene("k").ics == str(folder / "ic.csv")
