"""Run keys name one run each: a key made from a float is exact, and a key used twice for two scenes is refused."""

from __future__ import annotations

import json

import pytest

import hhscatter
from hhscatter.errors import StudyError
from hhscatter.studies import Study, load_study, stage_module
from hhscatter.studies.keys import RunKeys, number_key


@pytest.mark.parametrize(
    ("value", "fmt", "text"),
    [
        (0.30, ".2f", "0.30"),
        (0.304, ".2f", "0.304"),
        (0.25, ".2f", "0.25"),
        (3.0, "g", "3"),
        (0.1234567, "g", "0.1234567"),
    ],
)
def test_number_key_keeps_the_format_where_exact(value, fmt, text):
    assert number_key(value, fmt) == text
    assert float(number_key(value, fmt)) == value


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), "0.3", True, None])
def test_number_key_refuses_what_is_not_a_finite_number(bad):
    with pytest.raises(StudyError, match="run key"):
        number_key(bad)


def test_run_keys_refuse_one_key_for_two_runs():
    runs = RunKeys()
    runs["E0.30"] = {"energy": 0.30}
    runs["E0.30"] = {"energy": 0.30}
    with pytest.raises(StudyError, match="'E0.30' names two different runs"):
        runs["E0.30"] = {"energy": 0.304}
    assert runs == {"E0.30": {"energy": 0.30}}


def test_noise_study_makes_one_run_per_energy_of_a_close_pair():
    """0.30 and 0.304 both format as 0.30 with .2f: the study must still make (and label) two runs."""
    study = load_study("noise", "tiny")
    study.config["study"]["nodrag_energies"] = [0.30, 0.304]
    runs = stage_module("noise")._runs(study)
    nodrag = {k: sc for k, sc in runs.items() if k.startswith("nodrag_") and "_t" not in k}  # not the survivors' runs
    sigmas = study.params.nodrag_sigmas
    assert len(nodrag) == 2 * len(sigmas)
    survivors = [k for k in runs if k.startswith("nodrag_") and "_t" in k]
    assert len(survivors) == 2 * sum(s > 0 for s in sigmas) * len(study.params.nodrag_times)
    assert sorted({sc.energy for sc in nodrag.values()}) == [0.30, 0.304]
    for key, sc in nodrag.items():  # the key names the scene's own energy
        assert float(key.split("_")[1][1:]) == sc.energy


def test_noise_study_keys_of_the_committed_grid_are_unchanged():
    doc = json.loads((hhscatter_root() / "docs" / "studies" / "assets" / "noise.json").read_text())
    study = load_study("noise", doc["scale"])
    assert list(stage_module("noise")._runs(study)) == list(doc["raw_runs"])


def hhscatter_root():
    from pathlib import Path

    return Path(hhscatter.__file__).resolve().parent.parent


def test_study_run_refuses_a_key_already_used_for_another_scene(tmp_path):
    study = Study(name="keys", scale="quick", config={}, root=tmp_path / "keys")
    a = hhscatter.Scene(energy=0.3, n=20, t_max=5.0, chunk_size=20)
    b = a.replace(energy=0.304)
    out = study.run("E0.30", a, workers=1, progress=False)
    hash_a = json.loads((out / "scene.json").read_text())["scene_hash"]
    assert study.run("E0.30", a, workers=1, progress=False) == out  # the same scene again: kept
    with pytest.raises(StudyError, match="'E0.30' was already used for another scene"):
        study.run("E0.30", b, workers=1, progress=False)
    assert json.loads((out / "scene.json").read_text())["scene_hash"] == hash_a  # the first run is untouched
