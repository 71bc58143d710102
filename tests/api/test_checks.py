"""The argument checks of the notebook API: wrong tables, runs, numbers and results are refused with a
ConfigError naming the argument; reads name an unknown column or a filter that matched nothing; transition
times pair a dissipative point only with a conservative point of the same system, ICs and escape rule."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd
import pyarrow.dataset as ds
import pytest

import hhscatter
from hhscatter.errors import ConfigError


def _lifetimes(n=400, seed=0, gamma=0.0, energy=0.3):
    t = 5 + np.random.default_rng(seed).exponential(5.0, n)
    return pd.DataFrame({"traj_id": np.arange(n), "energy": energy, "gamma": gamma, "t_end": t, "outcome": "escaped"})


@pytest.fixture(scope="module")
def grid_run(tmp_path_factory):
    run = tmp_path_factory.mktemp("grid") / "run"
    grid = hhscatter.Grid(hhscatter.Scene(energy=0.3, n=60, t_max=20.0), energies=(0.25, 0.3), gammas=(0.0, 0.01))
    hhscatter.simulate(grid, run, overwrite=True, workers=1, progress=False)
    return run


# -- the API's functions given the wrong thing ----------------------------------------------------------------------
@pytest.mark.parametrize(
    "call, words",
    [
        (lambda: hhscatter.survival("run"), ["lifetimes = 'run': not a run directory (no scene.json)"]),
        (lambda: hhscatter.escape_rates(42), ["lifetimes must be a pandas DataFrame", "int 42"]),
        (lambda: hhscatter.survival(_lifetimes().iloc[:0]), ["lifetimes is empty"]),
        (lambda: hhscatter.survival(_lifetimes().drop(columns="outcome")), ["lacks the column(s) ['outcome']"]),
        (lambda: hhscatter.survival(_lifetimes(), t_grid="a"), ["t_grid must be an array of times"]),
        (lambda: hhscatter.survival(_lifetimes(), t_grid=[2.0, 1.0]), ["increasing order"]),
        (lambda: hhscatter.survival(_lifetimes().assign(outcome="gone")), ["outcome holds ['gone']"]),
        (lambda: hhscatter.survival(_lifetimes().assign(t_end=math.nan)), ["t_end must hold finite numbers ≥ 0"]),
        (lambda: hhscatter.escape_rates(_lifetimes(), windows=3), ["no option 'windows'"]),
        (lambda: hhscatter.escape_rates(_lifetimes(), detect_tail="no"), ["detect_tail must be True or False"]),
        (lambda: hhscatter.plot_survival(hhscatter.escape_rates(_lifetimes())), ["curves must be a SurvivalCurves"]),
        (lambda: hhscatter.plot_escape_rates(_lifetimes()), ["lacks the column(s) ['kappa', 'kappa_err']"]),
        (lambda: hhscatter.energy_decay(_lifetimes()), ["snapshots lacks the column(s) ['t']"]),
        (
            lambda: hhscatter.energy_decay(pd.DataFrame({"traj_id": [0], "t": [0.0], "energy": [0.3]}), window=(5, 1)),
            ["window must have t_lo < t_hi"],
        ),
        (lambda: hhscatter.kappa_cmeasure(_lifetimes()), ["run must be the path of a run directory", "DataFrame of"]),
        (lambda: hhscatter.transition_times(_lifetimes(), alpha=0.5), ["alpha must be a number > 1"]),
        (lambda: hhscatter.cmeasure_distances({}, np.zeros((3, 2))), ["points must be a CMeasurePoints"]),
    ],
)
def test_wrong_arguments_are_refused_naming_them(call, words):
    with pytest.raises(ConfigError) as e:
        call()
    for w in words:
        assert w in str(e.value)
    assert "\n" not in str(e.value)  # a sentence, never a table's repr


def test_kappa_cmeasure_and_run_scene_refuse_a_folder_that_is_not_a_run(tmp_path):
    for call in (hhscatter.kappa_cmeasure, hhscatter.api.run_scene, hhscatter.survival):
        for path in (tmp_path, "no\x00such"):
            with pytest.raises(ConfigError, match="not a run directory"):
                call(path)


def test_survival_and_escape_rates_of_a_run_directory_read_only_what_they_need(grid_run):
    """A run directory in place of its table: the same curves and rates as from the whole table."""
    whole = hhscatter.read_lifetimes(grid_run)
    a, b = hhscatter.survival(grid_run).to_frame(), hhscatter.survival(whole).to_frame()
    pd.testing.assert_frame_equal(a, b)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ra, rb = hhscatter.escape_rates(grid_run).to_frame(), hhscatter.escape_rates(whole).to_frame()
    pd.testing.assert_frame_equal(ra, rb)


# -- reads ------------------------------------------------------------------------------------------------------
def test_read_refuses_an_unknown_column_or_filter_field_naming_the_table_columns(grid_run):
    with pytest.raises(ConfigError, match=r"columns \['foo'\] are not in the lifetimes table") as e:
        hhscatter.read_lifetimes(grid_run, columns=["foo"])
    assert "t_end" in str(e.value) and "\n" not in str(e.value)
    with pytest.raises(ConfigError, match="names the field 'foo', which is not a column") as e:
        hhscatter.read_lifetimes(grid_run, filters=ds.field("foo") == 1)
    assert "\n" not in str(e.value)
    with pytest.raises(ConfigError, match="filters must be a pyarrow expression"):
        hhscatter.read_lifetimes(grid_run, filters="energy == 0.3")


def test_read_takes_the_pandas_list_form_of_filters(grid_run):
    listed = hhscatter.read_lifetimes(grid_run, filters=[("energy", "==", 0.3), ("gamma", "==", 0.01)])
    expr = hhscatter.read_lifetimes(grid_run, filters=(ds.field("energy") == 0.3) & (ds.field("gamma") == 0.01))
    assert len(listed) == 60 and listed["t_end"].tolist() == expr["t_end"].tolist()


def test_a_filter_on_a_value_that_is_not_a_grid_point_says_nothing_matched(grid_run):
    with pytest.warns(
        UserWarning, match=r"nothing matched filters .*energy.*0\.31.*energy = 0\.25, 0\.3; gamma = 0, 0\.01"
    ):
        df = hhscatter.read_lifetimes(grid_run, filters=ds.field("energy") == 0.31)
    assert len(df) == 0 and "nothing matched" in df.attrs["hhscatter"]["nothing_matched"]
    with pytest.raises(ConfigError, match="lifetimes is empty"):
        hhscatter.survival(df)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a filter that matches says nothing
        assert len(hhscatter.read_lifetimes(grid_run, filters=ds.field("energy") == 0.3)) == 120


# -- transition times --------------------------------------------------------------------------------------------
def _two_runs(scene_a: dict, scene_b: dict):
    """A frame as read_lifetimes([a, b]) makes it: run a holds γ = 0, run b γ = 0.01, both at E0 = 0.3."""
    a, b = _lifetimes(5000, seed=1).assign(run="a"), _lifetimes(5000, seed=2, gamma=0.01).assign(run="b")
    df = pd.concat([a, b], ignore_index=True)
    df["run"] = pd.Categorical(df["run"], categories=["a", "b"])
    df.attrs["hhscatter"] = {"runs": [{"run": "a", "scene": scene_a}, {"run": "b", "scene": scene_b}], "pooled": None}
    return df


SCENE = {
    "energy": 0.3,
    "seed": 0,
    "region": "disk",
    "radius": 0.5,
    "ics": None,
    "r_esc": 1.5,
    "r_far": None,
    "omega": 1.0,
    "lam": 1.0,
    "noise": None,
    "system": None,
}


@pytest.mark.parametrize(
    "change",
    [
        {"r_esc": 3.0},
        {"noise": {"sigma": 0.01}},
        {"system": {"name": "n_exit", "params": {"n": 4}}},
        {"seed": 7},
        {"ics": "ic30.parquet"},
    ],
)
def test_transition_times_pair_no_runs_of_another_system_ics_or_escape_rule(change):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        row = hhscatter.transition_times(_two_runs({**SCENE, "gamma": 0.0}, {**SCENE, "gamma": 0.01, **change}))
    row = row.to_frame().iloc[0]
    key = next(iter(change))
    assert math.isnan(row.tau0) and math.isnan(row.tau1) and row.partner == ""
    assert "not paired with E0=0.3, γ=0 (a)" in row.note and f"differs in {key} (" in row.note


def test_transition_times_pair_runs_of_the_same_scene_and_say_with_what():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        row = (
            hhscatter.transition_times(
                _two_runs({**SCENE, "gamma": 0.0, "n": 400}, {**SCENE, "gamma": 0.01, "t_max": 900.0})
            )
            .to_frame()
            .iloc[0]
        )
    assert row.partner == "E0=0.3, γ=0 (a)" and math.isfinite(row.tau0) and row.note.startswith("P_γ never")


def test_transition_times_of_a_conservative_run_only_is_refused():
    with pytest.raises(ConfigError, match=r"needs dissipative \(γ > 0\) points.*only γ = 0 \(E0=0\.3, γ=0\)"):
        hhscatter.transition_times(_lifetimes())


# -- kappa_cmeasure streams its run ------------------------------------------------------------------------------
@pytest.mark.parametrize("grid", [False, True])
def test_kappa_cmeasure_streamed_part_by_part_equals_the_whole_tables(tmp_path, grid):
    """kappa_cmeasure(run) reads the sections part by part (several parts here): every number equals the
    in-memory route over the whole tables."""
    scene = hhscatter.Scene(
        energy=0.3, n=400, seed=3, t_max=400.0, chunk_size=90, sections=hhscatter.SectionWindow(t_from=10.0, t_to=80.0)
    )
    what = hhscatter.Grid(scene, energies=(0.25, 0.3), gammas=(0.0,)) if grid else scene
    hhscatter.simulate(what, tmp_path, overwrite=True, workers=1, progress=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        streamed = hhscatter.kappa_cmeasure(tmp_path, n_boot=50).to_frame()
        whole = hhscatter.api.kappa_cmeasure_tables(
            hhscatter.read_lifetimes(tmp_path), hhscatter.read_sections(tmp_path), n_boot=50
        ).to_frame()
    assert len(streamed) == (2 if grid else 1) and (streamed["n_samples"] > 0).all()
    pd.testing.assert_frame_equal(streamed, whole)


def test_load_run_of_a_folder_names_what_it_takes(tmp_path):
    with pytest.raises(ConfigError, match="is a folder: give a scene TOML file"):
        hhscatter.load_run(tmp_path)
    with pytest.raises(ConfigError, match="is a folder"):
        hhscatter.load_scene(tmp_path)


@pytest.mark.parametrize("run", [{"energy": 0.3, "n": 10}, "scene.toml", None])
def test_simulate_refuses_what_is_not_a_scene_or_grid_before_any_work(tmp_path, run):
    out = tmp_path / "out"
    with pytest.raises(ConfigError, match="run must be a Scene or a Grid"):
        hhscatter.simulate(run, out, workers=1, progress=False)
    assert not out.exists()  # nothing written
