"""The noise study's rate records: each has its own initial conditions and noise streams, and its window opens after
the start has relaxed."""

from __future__ import annotations

import numpy as np
import pytest

from hhscatter.scene.ics import region_ics
from hhscatter.studies import load_study, stage_module


@pytest.fixture(scope="module")
def runs():
    study = load_study("noise", "quick")
    return study, stage_module("noise")._runs(study)


def test_rate_records_share_no_orbits(runs):
    _, scenes = runs
    rated = {k: sc for k, sc in scenes.items() if k.startswith(("kramers_", "turnover_"))}
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
    mod = stage_module("noise")
    for key, holds in (("turnover_g0.03", True), ("turnover_g0.3", True), ("turnover_g1", False)):
        sc = scenes[key]
        T = sc.noise.temperature
        row = {"temperature": T, "rate": 0.02, "rate_err": 0.001}
        th = mod._turnover_theory(study, row, sc)
        tst = 3 / (2 * np.pi) / np.sqrt(3) * np.exp(-(1 / 6) / T)
        delta = sc.gamma * 1.2 / T
        assert th["action"] == pytest.approx(1.2, rel=1e-9) and th["delta"] == pytest.approx(delta, rel=1e-9)
        assert th["ratio_ed"] == pytest.approx(0.02 / (delta * tst), rel=1e-6)
        assert th["ratio_ed_err"] / th["ratio_ed"] == pytest.approx(0.05, rel=1e-9)
        assert th["ratio_mm"] == pytest.approx(0.02 / th["melnikov_meshkov"], rel=1e-12)
        assert th["theory_assumptions_hold"] == holds  # γ = 0.3 is the range's edge, γ/ω_b ≤ 0.3 (ω_b = 1)
