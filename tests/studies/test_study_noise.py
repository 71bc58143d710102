"""The noise study's rate records: each has its own initial conditions and noise streams, and its window opens after
the start has relaxed."""

from __future__ import annotations

import numpy as np
import pytest

from hhscatter.reproduction.noise_records import pretty_potential, turnover_record
from hhscatter.scene.ics import region_ics
from hhscatter.studies import load_study, stage_module


@pytest.fixture(scope="module")
def runs():
    study = load_study("noise", "quick")
    return study, stage_module("noise")._runs(study)


def test_rate_records_share_no_orbits(runs):
    _, scenes = runs
    rated = {k: sc for k, sc in scenes.items() if k.startswith(("kramers_", "turnover_", "saddles_"))}
    assert len({sc.seed for sc in rated.values()}) == len(rated)
    # the turnover point γ = 1 is the Kramers point ΔE/T = 3 in all but its seed: other initial states
    kramers, turnover = scenes["kramers_b3"], scenes["turnover_g1"]
    assert (kramers.gamma, kramers.noise, kramers.energy) == (turnover.gamma, turnover.noise, turnover.energy)
    a, b = region_ics(kramers, 0, 50), region_ics(turnover, 0, 50)
    assert not np.isin(a, b).any()


def test_rate_windows_open_after_relaxation(runs):
    study, _ = runs
    p, mod = study.params, stage_module("noise")
    assert mod._window_start(p, 0.03) == pytest.approx(p.t_relax + p.relax_widths / 0.03)
    assert mod._window_start(p, 0.03) > 3 / 0.03 and mod._window_start(p, 1.0) > p.t_relax


def test_turnover_records_carry_the_theory_and_its_range(runs):
    """Hénon–Heiles: S = 6/5 along x = 0, δ = γS/T; k_TST = 3 (1/2π)(1/√3) e^{−ΔE/T}; energy diffusion δ k_TST;
    the theory's range is γ/ω_b ≤ 0.3 (ω_b = 1)."""
    study, scenes = runs
    for key, holds in (("turnover_g0.03", True), ("turnover_g0.3", True), ("turnover_g1", False)):
        sc = scenes[key]
        T = sc.noise.temperature
        row = {"gamma": sc.gamma, "temperature": T, "rate": 0.02, "rate_err": 0.001}
        th = turnover_record(row, sc.model, study.params.theory_gamma_max)
        tst = 3 / (2 * np.pi) / np.sqrt(3) * np.exp(-(1 / 6) / T)
        delta = sc.gamma * 1.2 / T
        assert th["action"] == pytest.approx(1.2, rel=1e-9) and th["delta"] == pytest.approx(delta, rel=1e-9)
        assert th["ratio_ed"] == pytest.approx(0.02 / (delta * tst), rel=1e-6)
        assert th["ratio_ed_err"] / th["ratio_ed"] == pytest.approx(0.05, rel=1e-9)
        assert th["ratio_mm"] == pytest.approx(0.02 / th["melnikov_meshkov"], rel=1e-12)
        assert th["theory_assumptions_hold"] == holds  # γ = 0.3 is the range's edge, γ/ω_b ≤ 0.3 (ω_b = 1)


def test_the_absorbing_radius_records_differ_from_their_kramers_record_in_radius_and_seed_only(runs):
    study, scenes = runs
    p = study.params
    for b in p.resc_barriers:
        base, far = scenes[f"kramers_b{b:g}"], scenes[f"kramers_b{b:g}_r{p.resc_radius:g}"]
        assert far.r_esc == p.resc_radius > base.r_esc == 1.5
        assert far.seed != base.seed
        assert base.replace(r_esc=far.r_esc, seed=far.seed, name=far.name) == far


def test_the_survivor_runs_are_the_no_drag_orbits_run_to_each_time(runs):
    """Same seed, initial conditions and kick interval as the no-drag run; one run per time and σ > 0."""
    from hhscatter.integrate.noise import kick_interval

    study, scenes = runs
    p = study.params
    times = [t for t in p.nodrag_times if t < p.nodrag_t_max]
    for E in p.nodrag_energies:
        for s in p.nodrag_sigmas:
            key = f"nodrag_E{E:.2f}_s{s:g}"
            extra = sorted(k for k in scenes if k.startswith(key + "_t"))
            if s == 0:
                assert extra == []
                continue
            assert extra == sorted(f"{key}_t{t:g}" for t in times)
            for t in times:
                sc = scenes[f"{key}_t{t:g}"]
                assert sc.replace(t_max=p.nodrag_t_max, name=scenes[key].name) == scenes[key] and sc.t_max == t
                assert kick_interval(sc) == kick_interval(scenes[key])


def test_survivor_times_outside_the_run_are_refused():
    from types import SimpleNamespace

    mod = stage_module("noise")
    assert mod._survivor_times(SimpleNamespace(nodrag_times=[55.0, 10.0], nodrag_t_max=200.0)) == [10.0, 55.0, 200.0]
    with pytest.raises(ValueError, match=r"nodrag_times: \[250.0\] outside \(0, nodrag_t_max = 200\]"):
        mod._survivor_times(SimpleNamespace(nodrag_times=[10.0, 250.0], nodrag_t_max=200.0))


def test_the_two_saddle_records_run_the_declared_system_at_its_lowest_barrier(runs):
    """V = (x² + y²)/2 − x³/3 − 5y³/18: saddles (1, 0) at ΔE = 1/6 and (0, 6/5) at 36/50 − (5/18)(216/125) = 0.24;
    T = (1/6)/b, γ = gamma_kramers, each record on its own seed."""
    study, scenes = runs
    p = study.params
    keys = [f"saddles_b{b:g}" for b in p.saddles_barriers]
    assert keys and len(
        {scenes[k].seed for k in keys} | {sc.seed for k, sc in scenes.items() if k.startswith("kramers_")}
    ) == len(keys) + sum(k.startswith("kramers_") for k in scenes)
    for b, key in zip(p.saddles_barriers, keys):
        sc = scenes[key]
        exits = np.array(sorted((e.x, e.y, e.energy) for e in sc.model.exits))
        assert np.abs(exits - [(0.0, 1.2, 0.24), (1.0, 0.0, 1 / 6)]).max() < 1e-12
        assert sc.noise.temperature == pytest.approx(1 / 6 / b, rel=1e-12) and sc.gamma == p.gamma_kramers


def test_the_potential_is_printed_with_superscripts_and_minus_signs():
    assert pretty_potential("(x**2 + y**2)/2 - x**3/3 - 5*y**3/18") == "(x² + y²)/2 − x³/3 − 5y³/18"


def test_the_second_turnover_series_is_the_first_at_the_higher_barrier(runs):
    """The same gammas as ``turnover_gammas`` at T = ΔE/turnover_high_barrier (ΔE = 1/6), its own windows and N."""
    study, scenes = runs
    p = study.params
    keys = sorted(k for k in scenes if k.startswith("turnover_b"))
    assert keys == sorted(f"turnover_b{p.turnover_high_barrier:g}_g{g:g}" for g in p.turnover_gammas)
    for g, t_max in zip(p.turnover_gammas, p.turnover_high_t_max):
        sc, low = scenes[f"turnover_b{p.turnover_high_barrier:g}_g{g:g}"], scenes[f"turnover_g{g:g}"]
        assert sc.noise.temperature == pytest.approx(1 / 6 / p.turnover_high_barrier, rel=1e-12)
        assert (sc.gamma, sc.t_max, sc.n, sc.energy) == (g, t_max, p.turnover_high_n, low.energy)
        assert sc.seed != low.seed


def test_the_two_saddle_turnover_runs_the_declared_system_across_gamma(runs):
    study, scenes = runs
    p = study.params
    keys = sorted(k for k in scenes if k.startswith("saddles_turnover_"))
    assert keys == sorted(f"saddles_turnover_g{g:g}" for g in p.saddles_turnover_gammas)
    assert max(p.saddles_turnover_gammas) / min(p.saddles_turnover_gammas) >= 100  # two decades of γ
    for g, t_max in zip(p.saddles_turnover_gammas, p.saddles_turnover_t_max):
        sc = scenes[f"saddles_turnover_g{g:g}"]
        assert sc.model.critical_energy == pytest.approx(1 / 6, rel=1e-12) and len(sc.model.exits) == 2
        assert sc.noise.temperature == pytest.approx(1 / 6 / p.saddles_turnover_barrier, rel=1e-12)
        assert (sc.gamma, sc.t_max, sc.n) == (g, t_max, p.saddles_turnover_n)


@pytest.mark.parametrize("gammas, t_max", [("turnover_gammas", "turnover_high_t_max"), ("saddles_turnover_gammas",
                                                                                       "saddles_turnover_t_max")])  # fmt: skip
def test_a_turnover_series_with_a_window_per_gamma_missing_is_refused(gammas, t_max):
    import copy
    import dataclasses

    study = load_study("noise", "tiny")
    config = copy.deepcopy(study.config)
    config["study"][t_max] = config["study"][t_max][:-1]
    study = dataclasses.replace(study, config=config)
    with pytest.raises(ValueError, match=rf"\[study\] {gammas} and {t_max} must have the same length, got 2 and 1"):
        stage_module("noise")._runs(study)
