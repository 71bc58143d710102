"""hhscatter.reproduction.noise_records: the noise study's records against hand-counted samples and the closed
forms of Hénon–Heiles (three saddles at E_c = 1/6 with ω_b = 1 and det H_s = −3, unit Hessian at the minimum)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hhscatter.model import HenonHeiles
from hhscatter.reproduction.noise_records import (
    absorbing_radius_record,
    finite_barrier_record,
    no_drag_records,
    no_drag_survival,
    pretty_potential,
    rate_record,
    reactivation_record,
    saddle_turnover_terms,
    survivor_record,
    turnover_record,
    two_saddle_record,
)


def _k_kl(gamma, T):
    """Kramers–Langer of Hénon–Heiles: 3 (λ₊/2π)(1/√3) e^{−(1/6)/T}, λ₊ = −γ/2 + √(γ²/4 + 1)."""
    lam = -gamma / 2 + math.sqrt(gamma**2 / 4 + 1)
    return 3 * lam / (2 * math.pi) / math.sqrt(3) * math.exp(-1 / 6 / T)


def _sample():
    """40 escapes at t = 10, 20, …, 400 and 60 orbits censored at 400."""
    t = np.r_[np.arange(1, 41) * 10.0, np.full(60, 400.0)]
    return t, np.r_[np.ones(40, bool), np.zeros(60, bool)]


def test_rate_record_is_events_over_exposure_beside_kramers_langer():
    """On [0, 400]: 40 escapes over 8200 + 60 · 400 orbit·time; halves [0, 200] (20 escapes over 2100 + 80 · 200)
    and [200, 400] (20 over 2100 + 60 · 200); each error the rate over √20."""
    t, esc = _sample()
    T = 1 / 18
    r = rate_record(t, esc, HenonHeiles(), 1.0, T, (0.0, 400.0), n=100, r_esc=1.5, seed=9, z_max=3.0)
    k, kl = 40 / 32200, _k_kl(1.0, T)
    assert r["rate"] == pytest.approx(k, rel=1e-12) and r["rate_err"] == pytest.approx(k / math.sqrt(40), rel=1e-12)
    assert r["kramers_langer"] == pytest.approx(kl, rel=1e-6)
    assert r["ratio"] == pytest.approx(k / kl, rel=1e-6) and r["ratio_err"] == pytest.approx(k / kl / math.sqrt(40))
    assert r["barrier_over_T"] == pytest.approx(3.0, rel=1e-12)
    k1, k2 = 20 / 18100, 20 / 14100
    assert r["rate_first_half"] == pytest.approx(k1, rel=1e-12) and r["rate_second_half"] == pytest.approx(k2)
    z = (k2 - k1) / math.hypot(k1 / math.sqrt(20), k2 / math.sqrt(20))
    assert r["halves_z"] == pytest.approx(z, rel=1e-12) and r["constant_in_window"] is (abs(z) < 3.0)
    assert (r["n"], r["r_esc"], r["seed"], r["n_events"], r["window"]) == (100, 1.5, 9, 40, [0.0, 400.0])
    assert "rate_upper95" not in r


def test_a_window_without_an_escape_gives_bounds_not_a_rate():
    """No escape in [0, 400] of 100 orbits: the rate's bound −ln 0.05 / 40000, the ratio's that over k_KL."""
    t = np.full(100, 400.0)
    r = rate_record(t, np.zeros(100, bool), HenonHeiles(), 1.0, 1 / 18, (0.0, 400.0), n=100, r_esc=1.5, seed=1,
                    z_max=3.0)  # fmt: skip
    assert math.isnan(r["rate"]) and math.isnan(r["ratio"]) and math.isnan(r["ratio_err"])
    assert r["rate_upper95"] == pytest.approx(-math.log(0.05) / 40000, rel=1e-12)
    assert r["ratio_upper95"] == pytest.approx(-math.log(0.05) / 40000 / _k_kl(1.0, 1 / 18), rel=1e-6)
    assert not r["constant_in_window"]


@pytest.mark.parametrize("gamma, holds", [(0.1, True), (0.3, True), (0.31, False)])
def test_turnover_record_reads_the_theory_where_gamma_over_omega_b_is_small(gamma, holds):
    """ω_b = 1: γ/ω_b = γ; the ratios are the rate over each theory's rate with the rate's relative error."""
    T = 1 / 18
    rec = {"gamma": gamma, "temperature": T, "rate": 2e-3, "rate_err": 1e-4}
    t = turnover_record(rec, HenonHeiles(), 0.3)
    assert t["gamma_over_omega_b"] == pytest.approx(gamma, rel=1e-6)
    assert t["theory_assumptions_hold"] is holds
    # energy diffusion: δ k_TST, δ = γ S / T, k_TST = 3 (ω_b/2π)(1/√3) e^{−ΔE/T}
    k_tst = 3 / (2 * math.pi) / math.sqrt(3) * math.exp(-3.0)
    assert t["delta"] == pytest.approx(gamma * t["action"] / T, rel=1e-12)
    assert t["energy_diffusion"] == pytest.approx(t["delta"] * k_tst, rel=1e-6)
    assert t["ratio_ed"] == pytest.approx(2e-3 / (t["delta"] * k_tst), rel=1e-6)
    assert t["ratio_ed_err"] == pytest.approx(0.05 * t["ratio_ed"], rel=1e-12)
    assert t["ratio_mm"] == 2e-3 / t["melnikov_meshkov"] and t["ratio_mm_err"] == 1e-4 / t["melnikov_meshkov"]
    assert t["melnikov_meshkov"] < _k_kl(gamma, T)  # Υ < 1


def test_two_saddle_record_shares_against_equal_saddles():
    """Three equal saddles: each a third of the sum; the lowest term k_KL/3. Escapes in (0, 100]: 50, 30, 20 by
    exits 0, 1, 2; the escape at t = 150 is outside, the censored orbits do not count."""
    t = np.r_[np.linspace(1.0, 100.0, 100), 150.0, np.full(5, 150.0)]
    esc = np.r_[np.ones(101, bool), np.zeros(5, bool)]
    ch = np.r_[np.zeros(50, int), np.ones(30, int), np.full(20, 2), 1, np.full(5, -1)]
    rec = {"gamma": 1.0, "temperature": 1 / 18, "rate": 0.02, "rate_err": 0.002, "window": [0.0, 100.0], "n": 106}
    s = two_saddle_record(rec, ch, t, esc, HenonHeiles())
    assert s["n"] == 106 and s["kramers_langer_lowest"] == pytest.approx(_k_kl(1.0, 1 / 18) / 3, rel=1e-6)
    assert s["ratio_lowest"] == pytest.approx(0.02 / (_k_kl(1.0, 1 / 18) / 3), rel=1e-6)
    assert s["ratio_lowest_err"] == pytest.approx(0.1 * s["ratio_lowest"], rel=1e-12)
    shares = s["exit_shares"]
    assert [x["measured"] for x in shares] == [0.5, 0.3, 0.2]
    assert [x["predicted"] for x in shares] == pytest.approx([1 / 3] * 3, rel=1e-9)
    assert shares[0]["measured_err"] == pytest.approx(0.05, rel=1e-12)  # √(0.5 · 0.5 / 100)
    assert shares[0]["z"] == pytest.approx((0.5 - 1 / 3) / 0.05, rel=1e-6) and shares[0]["verdict"].startswith(
        "differs"
    )


def test_absorbing_radius_record_is_the_ratio_of_the_two_rates():
    """0.009 ± 0.0006 over 0.010 ± 0.0008: 0.9 ± 0.9 √(1/15² + 0.08²), shift −0.1 with the same error."""
    near = {"rate": 0.010, "rate_err": 0.0008, "r_esc": 1.5}
    far = {"barrier_over_T": 5.0, "rate": 0.009, "rate_err": 0.0006, "ratio": 1.1, "ratio_err": 0.07,
           "r_esc": 3.0, "n_events": 400, "window": [23.0, 1000.0], "constant_in_window": False, "seed": 3}  # fmt: skip
    a = absorbing_radius_record(near, far)
    err = 0.9 * math.hypot(1 / 15, 0.08)
    assert a["rate_ratio"]["value"] == pytest.approx(0.9, rel=1e-12) and a["rate_ratio"]["err"] == pytest.approx(err)
    assert a["shift"]["value"] == pytest.approx(-0.1, rel=1e-9) and a["shift"]["err"] == a["rate_ratio"]["err"]
    assert a["z"] == pytest.approx(-0.1 / err, rel=1e-9)
    assert a["ratio_kramers_langer"] == {"value": 1.1, "err": 0.07}
    assert (a["r_esc_default"], a["r_esc"], a["constant_in_window"], a["seed"]) == (1.5, 3.0, False, 3)


def test_survivor_record_keeps_the_survivors_energies_and_the_ensemble_mean():
    """Three survivors at 0.1, 0.2, 0.6 of five orbits, threshold 0.25: mean 0.3, two thirds below; ⟨E⟩ of the
    whole ensemble 0.25 + 0.02² · 50 = 0.27. One survivor: no distribution."""
    alive = np.array([True, True, False, True, False])
    e = np.array([0.1, 0.2, 5.0, 0.6, 5.0])
    s = survivor_record(0.25, 0.02, 50.0, alive, e, 0.25)
    assert (s["n"], s["n_alive"]) == (5, 3) and s["ensemble_mean_energy"] == pytest.approx(0.27, rel=1e-12)
    assert s["mean_energy"] == pytest.approx(0.3, rel=1e-12) and s["energy_q50"] == pytest.approx(0.2)
    assert s["below_ec"] == pytest.approx(2 / 3, rel=1e-12)
    one = survivor_record(0.25, 0.02, 50.0, alive & (e < 0.15), e, 0.25)
    assert one["n_alive"] == 1 and "mean_energy" not in one


def test_no_drag_records_give_kappa_its_ratio_to_kappa0_and_the_energy_gain():
    """Every orbit escaped inside [0, 1000]: κ = n / Σt; σ = 0.01 with lifetimes a third of σ = 0's: κ/κ0 = 3 ±
    3 √(2/50); ⟨E⟩ gains 0.01² · 1000 = 0.1 by the window's end."""
    t = np.linspace(2.0, 100.0, 50)
    one = np.ones(50, bool)
    rows = no_drag_records(0.3, [0.0, 0.01], [(t, one), (t / 3, one)], (0.0, 1000.0), 3.0)
    assert rows[0]["kappa"] == pytest.approx(50 / t.sum(), rel=1e-12) and rows[0]["kappa_over_kappa0"] == 1.0
    assert rows[1]["kappa_over_kappa0"] == pytest.approx(3.0, rel=1e-12)
    assert rows[1]["kappa_over_kappa0_err"] == pytest.approx(3 * math.sqrt(2 / 50), rel=1e-12)
    assert rows[1]["energy_gain_at_window_end"] == pytest.approx(0.1, rel=1e-12)
    assert [r["sigma"] for r in rows] == [0.0, 0.01] and rows[1]["n_events"] == 50
    no_ref = no_drag_records(0.3, [0.01], [(t, one)], (0.0, 1000.0), 3.0)
    assert "kappa_over_kappa0" not in no_ref[0] and "energy_gain_at_window_end" not in no_ref[0]


def test_no_drag_survival_is_the_fraction_still_inside():
    """Escapes at 1, 2, 3, 4 and one orbit censored at 10: P = 1, 4/5, 2/5, 1/5 at t = 0, 1.5, 3.5, 6."""
    t = np.array([1.0, 2.0, 3.0, 4.0, 10.0])
    f = no_drag_survival(0.25, 0.005, t, t < 5, np.array([0.0, 1.5, 3.5, 6.0]))
    assert f["P"].tolist() == pytest.approx([1.0, 0.8, 0.4, 0.2], rel=1e-12)
    assert set(f["energy"]) == {0.25} and set(f["sigma"]) == {0.005}


def test_reactivation_record_refuses_a_tail_before_the_orbits_settle():
    """Orbits settling up to t = 10 (99 % by ≈ 9.9): a tail from t = 5 is refused."""
    tau = np.linspace(0.01, 10.0, 1000)
    bath = (tau + 20.0, np.ones(1000, bool))
    with pytest.raises(ValueError, match="99"):
        reactivation_record((tau, np.zeros(1000, bool), np.ones(1000, bool)), bath, bath, t_max=100.0,
                            tail_start=5.0, window_start=0.0, about={})  # fmt: skip


def test_finite_barrier_record_fits_the_first_correction():
    """Ratios 0.9 + 0.6 T/ΔE at ΔE/T = 3, 4, 6: intercept 0.9, slope 0.6; with the intercept held at 1 the slope
    of (ratio − 1) against T/ΔE by weighted least squares through the origin."""
    rows = [{"barrier_over_T": b, "ratio": 0.9 + 0.6 / b, "ratio_err": 0.02} for b in (3.0, 4.0, 6.0)]
    f = finite_barrier_record(rows, HenonHeiles())
    assert f["intercept"]["value"] == pytest.approx(0.9, rel=1e-9)
    assert f["slope"]["value"] == pytest.approx(0.6, rel=1e-9)
    x = np.array([1 / 3, 1 / 4, 1 / 6])
    y = 0.9 + 0.6 * x - 1
    assert f["slope_intercept_one"]["value"] == pytest.approx(float((x * y).sum() / (x * x).sum()), rel=1e-9)
    assert f["T_over_barrier_range"] == pytest.approx([1 / 6, 1 / 3]) and f["dof"] == 1


def test_pretty_potential():
    assert pretty_potential("x**2/2 - 3*x*y**2 + y**10") == "x²/2 − 3xy² + y¹⁰"


@pytest.mark.parametrize("gamma", [0.01, 0.3, 3.0])
def test_saddle_turnover_terms_of_the_two_saddle_system_are_its_closed_forms(gamma):
    """V = (x² + y²)/2 − x³/3 − 5y³/18: saddle (1, 0) at ΔE = 1/6 with S = 6/5 along y = 0 (Hénon–Heiles' line
    orbit), saddle (0, 6/5) at ΔE = 0.24 with S = (6/5)³ (y = 6u/5 maps V(0, y) onto 36/25 (u²/2 − u³/3)); both
    saddles have ω_b = 1 and Hessian diag(−1, 1), the well the identity: k_KL,s = (λ₊/2π) e^{−ΔE_s/T},
    k_TST,s = e^{−ΔE_s/T}/2π, λ₊ = −γ/2 + √(γ²/4 + 1)."""
    from hhscatter.analysis.noise import depopulation_factor
    from hhscatter.model import make_system

    T = 1 / 18
    m = make_system(potential="(x**2 + y**2)/2 - x**3/3 - 5*y**3/18")
    terms = sorted(saddle_turnover_terms(m, gamma, T), key=lambda s: s["barrier"])
    lam = -gamma / 2 + math.sqrt(gamma**2 / 4 + 1)
    for s, barrier, action in zip(terms, (1 / 6, 0.24), (1.2, 1.2**3)):
        delta = gamma * action / T
        k_kl = lam / (2 * math.pi) * math.exp(-barrier / T)
        assert s["barrier"] == pytest.approx(barrier, rel=1e-9) and s["omega_b"] == pytest.approx(1.0, rel=1e-6)
        assert s["action"] == pytest.approx(action, rel=1e-9) and s["delta"] == pytest.approx(delta, rel=1e-9)
        assert s["kramers_langer"] == pytest.approx(k_kl, rel=1e-6)
        assert s["melnikov_meshkov"] == pytest.approx(float(depopulation_factor(delta)) * k_kl, rel=1e-6)
        assert s["energy_diffusion"] == pytest.approx(delta * math.exp(-barrier / T) / (2 * math.pi), rel=1e-6)
    rec = turnover_record({"gamma": gamma, "temperature": T, "rate": 1e-3, "rate_err": 1e-4}, m, 0.3)
    assert rec["melnikov_meshkov"] == pytest.approx(sum(s["melnikov_meshkov"] for s in terms), rel=1e-12)
    assert rec["energy_diffusion"] == pytest.approx(sum(s["energy_diffusion"] for s in terms), rel=1e-12)


def test_shell_theory_record_sets_the_rate_beside_each_shell_rate():
    """Ratios to the three shell rates with the rate's relative error; the theory's values kept as they are."""
    from hhscatter.analysis.noise import EnergyDiffusion
    from hhscatter.reproduction.noise_records import shell_theory_record

    ed = EnergyDiffusion(
        0.003, 1 / 18, rate=8e-4, rate_absorbing=1.6e-3, absorbing_limit=1.8e-3, transition_state=1.5e-2,
        delta=0.12, turnover=1.2e-3, phase_volume_barrier=0.61, top=0.83,
    )  # fmt: skip
    r = shell_theory_record({"rate": 8.4e-4, "rate_err": 4.2e-5}, ed)
    assert r["ratio_shell"] == pytest.approx(1.05) and r["ratio_shell_err"] == pytest.approx(0.0525)
    assert r["ratio_shell_absorbing"] == pytest.approx(0.525) and r["ratio_shell_absorbing_err"] == pytest.approx(
        0.02625
    )
    assert r["ratio_shell_turnover"] == pytest.approx(0.7) and r["ratio_shell_turnover_err"] == pytest.approx(0.035)
    assert (r["shell_delta"], r["shell_transition_state"], r["shell_top"]) == (0.12, 1.5e-2, 0.83)


def test_turnover_theories_record_is_both_records_on_the_shells_of_its_settings():
    """The shells up to E_b + w T on the given lattice: the same rates as the energy-diffusion theory computing its
    own shells with those settings; Hénon–Heiles' top E_b + w T = 1/6 + 6/18 = 1/2."""
    from hhscatter.analysis.noise import well_energy_diffusion
    from hhscatter.reproduction.noise_records import shell_theory_record, turnover_theories_record

    m, rec = HenonHeiles(), {"gamma": 0.01, "temperature": 1 / 18, "rate": 9e-4, "rate_err": 9e-5}
    got = turnover_theories_record(rec, m, gamma_max=0.3, shell_top_widths=6.0, shell_grid=201, shell_energies=401)
    ed = well_energy_diffusion(m, 0.01, 1 / 18, above=6.0, grid=201, n_energies=401)
    assert got == {**turnover_record(rec, m, 0.3), **shell_theory_record(rec, ed)}
    assert got["shell_top"] == pytest.approx(0.5, abs=1e-12)
    finer = turnover_theories_record(rec, m, gamma_max=0.3, shell_top_widths=6.0, shell_grid=201, shell_energies=801)
    assert finer["shell_energy_diffusion"] != got["shell_energy_diffusion"]  # the settings reach the result


def test_two_saddle_turnover_record_adds_each_saddles_terms_and_separability():
    from hhscatter.model import make_system
    from hhscatter.reproduction.noise_records import two_saddle_turnover_record

    v = "(x**2 + y**2)/2 - x**3/3 - 5*y**3/18"
    m = make_system(potential=v)
    rows = [{"gamma": g, "temperature": 1 / 18, "rate": 1e-3} for g in (0.1, 1.0)]
    r = two_saddle_turnover_record(rows, m, barrier_over_T=3.0, potential=v)
    assert (r["barrier_over_T"], r["potential"], r["separable"]) == (3.0, v, True)
    for row, out in zip(rows, r["records"]):
        assert out == {**row, "saddles": saddle_turnover_terms(m, row["gamma"], 1 / 18)}
    assert two_saddle_turnover_record([], m, barrier_over_T=3.0, potential=v)["separable"] is None
    assert two_saddle_turnover_record(rows[:1], HenonHeiles(), barrier_over_T=3.0, potential="")["separable"] is False


def test_rates_table_has_a_row_per_record_with_its_series_and_window_end():
    from hhscatter.reproduction.noise_records import rates_table

    a = {"gamma": 1.0, "rate": 0.1, "window": [23.0, 150.0]}
    b = {"gamma": 0.1, "rate": 0.02, "window": [50.0, 400.0], "saddles": [{"exit": 0}, {"exit": 1}]}
    t = rates_table({"kramers": [a], "saddles_turnover": [b, dict(b, gamma=0.3)]})
    assert list(t["set"]) == ["kramers", "saddles_turnover", "saddles_turnover"]
    assert list(t["t_max"]) == [150.0, 400.0, 400.0] and list(t["gamma"]) == [1.0, 0.1, 0.3]
    assert "saddles" not in t.columns and "window" not in t.columns
