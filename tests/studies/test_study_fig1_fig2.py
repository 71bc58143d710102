"""Tests of the studies fig1 / fig2 and of the analysis functions they added.

Synthetic tests compare with closed forms (the survival law a sample was
drawn from); the end-to-end tests run both studies at scale 'tiny' in a
temporary studies root and check the outputs against physics that the code
does not impose (κ from two independent estimators, energy conservation on
the section, the sign and size of κ).
"""

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.survival.escape_rate import (
    choose_t_max,
    cmeasure_sample_from_sections,
    escaping_tail,
    fit_exponential,
)
from hhscatter.analysis.survival.fits import lifetimes_to_arrays

REPO = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------------------
# choose_t_max
# ---------------------------------------------------------------------------
def test_choose_t_max_follows_the_rule_on_an_exponential_pilot():
    kappa = 0.05
    rng = np.random.default_rng(5)
    t = rng.exponential(1 / kappa, 4000)
    obs = np.ones(t.size, bool)
    ch = choose_t_max(t, obs, 100_000, min_survivors=100, margin_efolds=3, t_min=10, t_cap=10_000, step=10)
    assert ch.reason == "rule"
    # closed forms for P = e^{-κt}: median ln2/κ, P = 1/10 at ln10/κ
    assert ch.t_half == pytest.approx(math.log(2) / kappa, rel=0.06)
    assert ch.t_tenth == pytest.approx(math.log(10) / kappa, rel=0.06)
    assert ch.kappa_pilot == pytest.approx(kappa, rel=0.08)
    # main run keeps 100 survivors until ln(1000)/κ; t_max adds 3 e-folds
    want = math.log(1000) / kappa + 3 / kappa
    assert ch.t_max == pytest.approx(want, rel=0.08)
    assert ch.t_max % 10 == 0


def test_choose_t_max_caps_and_flags_slow_decay():
    rng = np.random.default_rng(6)
    # a pilot that never decays to 1/10: 80 % of the orbits are trapped (censored at 500)
    t = np.where(rng.random(2000) < 0.2, rng.exponential(20.0, 2000), 500.0)
    obs = t < 500.0
    ch = choose_t_max(t, obs, 10_000, t_cap=5000)
    assert (ch.reason, ch.t_max) == ("slow", 5000.0)
    # a slow but measurable decay whose rule exceeds the cap
    t2 = rng.exponential(2000.0, 3000)
    ch2 = choose_t_max(t2, np.ones(t2.size, bool), 10**7, t_cap=5000)
    assert (ch2.reason, ch2.t_max) == ("cap", 5000.0)
    # a fast decay is clipped from below
    t3 = rng.exponential(0.5, 3000)
    assert choose_t_max(t3, np.ones(t3.size, bool), 1000, t_min=100).t_max == 100.0
    with pytest.raises(ValueError, match="n_main"):
        choose_t_max(t3, np.ones(t3.size, bool), 0)


# ---------------------------------------------------------------------------
# escaping_tail
# ---------------------------------------------------------------------------
class ExpThenPowerLaw:
    """P(t) = e^{−κt} for t ≤ τ*, e^{−κτ*} (τ*/t)^z after (continuous at τ*, hazard κ → z/t)."""

    def __init__(self, kappa=0.06, tau_star=100.0, z=3.0):
        self.kappa, self.tau_star, self.z = kappa, tau_star, z
        self.P_star = math.exp(-kappa * tau_star)

    def sample(self, rng, n):
        u = rng.random(n)
        early = -np.log(u) / self.kappa
        late = self.tau_star * (self.P_star / u) ** (1.0 / self.z)
        return np.where(u >= self.P_star, early, late)


def test_escaping_tail_recovers_z_and_tau_star_despite_trapped_orbits():
    law = ExpThenPowerLaw(kappa=0.06, tau_star=100.0, z=3.0)
    rng = np.random.default_rng(17)
    n, t_max = 600_000, 5000.0
    t = law.sample(rng, n)
    trapped = rng.random(n) < 2e-4  # KAM-trapped: never leave, censored at t_max
    t = np.where(trapped, t_max, np.minimum(t, t_max))
    obs = (~trapped) & (t < t_max)
    grid = np.linspace(0.0, 3000.0, 30001)
    P_true = np.where(grid <= 100.0, np.exp(-0.06 * grid), law.P_star * (100.0 / np.maximum(grid, 100.0)) ** 3)
    exp_fit = fit_exponential(grid, P_true, (10.0, 90.0))  # the exact exponential regime
    res = escaping_tail(t, obs, 10.0, exp_fit, grid, min_survivors=30)
    assert res.n_trapped == int(trapped.sum()) + int(np.count_nonzero(~trapped & (t >= t_max)))
    assert res.tail is not None
    assert abs(res.tail.z - 3.0) < max(3 * res.tail.z_err, 0.25)
    assert res.tau_star == pytest.approx(100.0, rel=0.15)
    assert res.tail.window[0] == pytest.approx(100.0, rel=0.2)


def test_escaping_tail_finds_no_tail_in_a_pure_exponential():
    rng = np.random.default_rng(3)
    t = rng.exponential(1 / 0.1, 300_000)
    obs = np.ones(t.size, bool)
    res = escaping_tail(t, obs, 0.0, None)
    assert res.tail is None and math.isnan(res.tau_star)
    with pytest.raises(ValueError, match="escaping"):
        escaping_tail(t[:5], obs[:5], 0.0)


# ---------------------------------------------------------------------------
# c-measure sampling: KAM-trapped orbits dropped
# ---------------------------------------------------------------------------
def test_cmeasure_sample_drops_censored_orbits():
    sections = pd.DataFrame({"traj_id": [1, 1, 1, 2, 2, 2, 3], "t": [10.0, 16.0, 23.0, 11.0, 14.0, 17.0, 12.0]})
    lifetimes = pd.DataFrame(
        {"traj_id": [1, 2, 3], "outcome": ["escaped", "censored", "escaped"], "t_end": [25.0, 5000.0, 13.0]}
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        T_all, ne_all, nu_all = cmeasure_sample_from_sections(sections, lifetimes, 10.0, 20.0, t_record_end=40.0)
    T, ne, nu = cmeasure_sample_from_sections(sections, lifetimes, 10.0, 20.0, t_record_end=40.0, drop_censored=True)
    np.testing.assert_allclose(np.sort(T), [6.0, 7.0])
    assert (ne, nu) == (1, 0)
    # without dropping, orbit 2's crossings at 11 and 14 return (3, 3) and its last one (17) is undetermined
    np.testing.assert_allclose(np.sort(T_all), [3.0, 3.0, 6.0, 7.0])
    assert (ne_all, nu_all) == (1, 1)


def test_lifetimes_to_arrays_accepts_rounding_in_e0_but_not_two_ensembles():
    base = pd.DataFrame(
        {
            "t_end": [1.0, 2.0, 3.0],
            "outcome": ["escaped", "censored", "escaped"],
            "e0": 0.3 + np.array([0.0, 5.5e-17, -5.5e-17]),
            "gamma": 0.0,
        }
    )
    _, obs = lifetimes_to_arrays(base)
    np.testing.assert_array_equal(obs, [True, False, True])
    with pytest.raises(ValueError, match="e0"):
        lifetimes_to_arrays(base.assign(e0=[0.3, 0.3, 0.31]))


def test_contour_levels_closed_form():
    from hhscatter.studies import stage_module

    lv = stage_module("fig1").contour_levels(20)
    assert lv.size == 20 and 0 < lv.min() and lv.max() < 0.5 and np.isclose(lv, 1 / 6).sum() == 1


# ---------------------------------------------------------------------------
# end to end at scale 'tiny'
# ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def tiny_root(tiny_studies):
    return tiny_studies  # every study built at scale tiny in graph order (conftest.py)


def _finite_numbers(obj):
    if isinstance(obj, dict):
        for v in obj.values():
            yield from _finite_numbers(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _finite_numbers(v)
    elif isinstance(obj, float):
        yield obj


def test_fig1_tiny_end_to_end(tiny_root):
    from hhscatter.data.read import read_sections
    from hhscatter.studies import load_study

    study = load_study("fig1", "tiny", root=tiny_root)
    assert study.figure_path.stat().st_size > 20_000
    doc = json.loads(study.numbers_path.read_text())
    assert set(doc["energies"]) == {"E0.30", "E0.35"}
    for key, info in doc["energies"].items():
        E = info["energy"]
        k = info["kappa_used"]["value"]
        assert 0.5 * 1.41 * (E - 1 / 6) < k < 2 * 1.41 * (E - 1 / 6)  # the right order of magnitude
        assert info["t_rec"] == math.ceil(info["tau0_used"] + study.params.rec_efolds / k)
        assert 0 < info["n_points"] <= info["n_survivors_at_t_rec"] < info["n_orbits"]
        # the raw sections table is the c-measure sample: one crossing per orbit, after t_rec, on the section
        sec = read_sections(study.raw(key))
        assert len(sec) == info["n_points"] and not sec["traj_id"].duplicated().any()
        assert (sec["t"] >= info["t_rec"]).all()
        r2 = sec["x"] ** 2 + sec["y"] ** 2
        assert np.abs(sec["x"] * sec["px"] + sec["y"] * sec["py"]).max() < 1e-9 * max(1.0, r2.max())
        assert (sec["x"] * sec["py"] - sec["y"] * sec["px"] > 0).all()
        assert np.abs(sec["energy"] - E).max() < 1e-12
        assert (r2 < 1.03**2).all()
    assert doc["cmeasure_sample"]["raw_keys"] == {"E0.30": "raw/E0.30", "E0.35": "raw/E0.35"}
    assert all(math.isfinite(v) for v in _finite_numbers(doc["energies"]))
    pts = pd.read_parquet(study.out / "derived" / "cmeasure_points.parquet")
    assert len(pts) == sum(v["n_points"] for v in doc["energies"].values())


def test_fig2_tiny_end_to_end(tiny_root):
    from hhscatter.studies import load_study

    study = load_study("fig2", "tiny", root=tiny_root)
    assert study.figure_path.stat().st_size > 30_000
    doc = json.loads(study.numbers_path.read_text())
    grid = study.params.grid_energies
    ke = pd.read_parquet(study.out / "derived" / "kappa_energy.parquet")
    assert len(ke) == len(grid)
    assert (ke["kappa"] > 0).all() and (ke["kappa_err"] > 0).all()
    # κ grows with E (Fig. 2b) and is of the size of the paper's law within a factor 2
    assert np.corrcoef(ke["energy"], ke["kappa"])[0, 1] > 0.9
    lin = 1.41 * (ke["energy"] - 1 / 6)
    assert ((ke["kappa"] > 0.5 * lin * (ke["energy"] > 0.27) + 0.0) & (ke["kappa"] < 2.5 * lin)).all()
    # the 4 window estimates scatter around their mean
    ks = ke[[f"kappa_w{i}" for i in range(1, 5)]].to_numpy()
    np.testing.assert_allclose(ks.mean(axis=1), ke["kappa"], rtol=1e-12)
    fit = doc["kappa_fit"]
    for name in ("a", "b", "c", "E_b"):
        assert math.isfinite(fit[name]["value"]) and fit[name]["err"] > 0
    assert 1 / 6 < fit["E_b"]["value"] < max(grid)
    assert 0.7 < fit["c"]["value"] < 2.5
    assert {r["quantity"].split(" ")[0] for r in doc["paper_comparison"]} >= {"a", "b", "c", "E_b"}
    # P(t) at the Fig. 2a energies
    assert set(doc["Pt"]) == {"pt_E0.23", "pt_E0.27"}
    for info in doc["Pt"].values():
        assert info["kappa"]["value"] > 0 and info["tau0"] < info["t_stop"]
    # κ from the c-measure: an independent estimator of the same rate
    cm = pd.read_parquet(study.out / "derived" / "kappa_cmeasure.parquet")
    main = cm[cm["shift_efolds"] == 0.0]
    assert len(main) == len(study.params.cm_energies)
    assert (main["n_undetermined"] == 0).all()
    assert ((main["mu_exit"] > 0) & (main["mu_exit"] < 1)).all()
    assert (np.abs(main["z_vs_same_run"]) < 4).all()
    for v in doc["cmeasure"].values():
        assert v["kappa_cm"]["value"] > 0 and v["kappa_cm"]["err"] > 0


def test_fig2_conventions_use_the_authors_square_ics_and_recompute_deterministically(tiny_root):
    """κ(E) under 4 conventions: the square runs are the disk runs with region = 'square' (same n, seed, t_max),
    the P-level windows sit at the P levels of the run's own Kaplan–Meier curve, the law rows use only stable
    energies, and the analysis gives the same numbers twice."""
    from hhscatter.analysis.survival.fits import lifetimes_to_arrays, survival_curve
    from hhscatter.data.read import read_lifetimes
    from hhscatter.studies import load_study, run_stage

    study = load_study("fig2", "tiny", root=tiny_root)
    doc = json.loads(study.numbers_path.read_text())
    conv = doc["kappa_conventions"]
    table = pd.read_parquet(study.out / "derived" / "kappa_conventions.parquet")
    for e in study.params.square_energies:
        disk = json.loads((study.raw(f"grid_E{e:.3f}") / "scene.json").read_text())["scene"]
        sq = json.loads((study.raw(f"sq_grid_E{e:.3f}") / "scene.json").read_text())["scene"]
        assert sq["region"] == "square" and disk["region"] == "disk"
        assert {k: v for k, v in sq.items() if k not in ("region", "name")} == {
            k: v for k, v in disk.items() if k not in ("region", "name")
        }
        # P-level window: starts where the square run's own KM curve first falls to 0.5
        t_end, obs = lifetimes_to_arrays(read_lifetimes(study.raw(f"sq_grid_E{e:.3f}")))
        row = table[(table["energy"] == e) & (table["convention"] == "square_plevel")].iloc[0]
        if np.isfinite(row["t_lo"]):
            km = survival_curve(t_end, obs, np.array([row["t_lo"] - 0.2, row["t_lo"] + 0.2]))
            assert km.P[0] > 0.5 >= km.P[1]
        assert row["n_escaped_at_start"] == int(((t_end == 0) & obs).sum()) > 0  # square corners beyond r_esc
    assert set(table["convention"]) == set(conv["conventions"])
    for info in conv["fits"].values():
        assert set(info["energies"]) <= set(conv["stable_energies"])
    undefined = table[~table["defined"]]
    assert (undefined["reason"].str.len() > 0).all()
    rows = {r["quantity"]: r for r in doc["paper_comparison"]}
    assert rows["κ(E) points ill-defined by the plateau of censored orbits"]["ours"] == len(undefined)
    run_stage("fig2", "analyze", "tiny", root=tiny_root)
    assert json.loads(study.numbers_path.read_text())["kappa_conventions"] == conv


def test_power_law_exponent_mle_recovers_pareto_exponent():
    from hhscatter.analysis.survival.escape_rate import power_law_exponent_mle

    rng = np.random.default_rng(21)
    z, a, t_max = 1.5, 100.0, 5000.0
    t = a * rng.random(200_000) ** (-1.0 / z)  # Pareto: P(T > t) = (a/t)^z, t ≥ a
    obs = t < t_max
    t = np.minimum(t, t_max)
    res = power_law_exponent_mle(t, obs, a, t_max)
    assert abs(res.kappa - z) < 3 * res.kappa_err and res.kappa_err < 0.01
    # left truncation: starting later on the same law gives the same exponent
    res2 = power_law_exponent_mle(t, obs, 300.0, t_max)
    assert abs(res2.kappa - z) < 3 * res2.kappa_err
    with pytest.raises(ValueError, match="t_start"):
        power_law_exponent_mle(t, obs, 0.0, t_max)


def test_fig2_paper_n_per_energy_is_declared_per_grid_energy():
    """The paper scale's κ(E) runs: N per energy from grid_n_by_energy (same order as grid_energies); a list of
    the wrong length is refused by name."""
    from hhscatter.studies import load_study, stage_module

    grid_n = stage_module("fig2").grid_n

    paper = load_study("fig2", "paper")
    grid, per = paper.params.grid_energies, paper.params.grid_n_by_energy
    assert [grid_n(paper, e) for e in grid] == per and grid_n(paper, 0.18) == 750000 and grid_n(paper, 0.4) == 250000
    assert all(n >= 100000 for n in per)
    assert grid_n(load_study("fig2", "quick"), 0.18) == 30000  # no list: grid_n everywhere
    paper.config["study"]["grid_n_by_energy"] = per[:-1]
    with pytest.raises(ValueError, match="grid_n_by_energy"):
        grid_n(paper, 0.2)
