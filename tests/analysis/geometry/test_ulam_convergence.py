"""Ulam's κ at one energy: every partition, the extrapolation to both limits, residuals and records
(hhscatter.analysis.geometry.ulam_convergence), against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.geometry import ulam_convergence as uc


def _grid(k_inf, a, beta, p, noise=0.0, seed=0):
    """κ on 3 box sides × 3 sample subsets (M'·c² samples per merged box), exactly κ∞ + a·b + β·M^(−p) (+ noise)."""
    rng = np.random.default_rng(seed)
    rows = [{"box": 0.00625 * c, "samples": m * c * c} for c in (1, 2, 4) for m in (4, 16, 64)]
    g = pd.DataFrame(rows)
    g["kappa"] = k_inf + a * g.box + beta * g.samples ** (-p) + noise * rng.standard_normal(len(g))
    return g


def test_kappa_convergence_recovers_the_limit_of_its_model():
    g = _grid(0.1972, 0.2, 0.03, 0.5)
    c = uc.kappa_convergence(g)
    assert c["kappa_inf"] == pytest.approx(0.1972, abs=1e-12)
    assert c["slope_box"] == pytest.approx(0.2, abs=1e-10) and c["coef_samples"] == pytest.approx(0.03, abs=1e-10)
    # the other exponent does not describe these data: its limit differs, and that difference is the model error
    assert c["model_err"] == pytest.approx(abs(c["kappa_inf_alt"] - 0.1972), rel=1e-12) and c["model_err"] > 1e-3
    assert math.isnan(c["stat_err"]) and math.isnan(c["err"])  # no bootstrap grid: no statistical error


def test_kappa_convergence_bootstrap_spread_is_the_statistical_error():
    """Replicates = the exact grid + independent noise σ: the spread of their extrapolations is that of the
    least-squares intercept, σ·√((XᵀX)⁻¹)₀₀ (an independent closed form)."""
    g = _grid(0.1, 0.1, 0.02, 0.5)
    sigma, n_rep = 1e-3, 400
    reps = pd.concat([_grid(0.1, 0.1, 0.02, 0.5, noise=sigma, seed=r).assign(rep=r) for r in range(n_rep)])
    c = uc.kappa_convergence(g, reps)
    X = np.column_stack([np.ones(len(g)), g.box, g.samples**-0.5])
    expect = sigma * math.sqrt(np.linalg.inv(X.T @ X)[0, 0])
    assert c["stat_err"] == pytest.approx(expect, rel=0.1)  # 400 replicates: the std to ≈ 3.5 %
    assert c["err"] == pytest.approx(math.hypot(c["stat_err"], c["model_err"]), rel=1e-12)


def test_kappa_convergence_needs_two_box_sides_and_two_sample_counts():
    g = _grid(0.1, 0.1, 0.02, 0.5)
    with pytest.raises(ValueError, match="box sides"):
        uc.kappa_convergence(g[g.box == g.box.min()])
    rec = uc.convergence_record(0.3, g.head(3), None, 0.11, {"kappa0": (0.1, 0.001)})
    assert rec["kappa_inf"] is None and "need" in rec["note"]


def test_residuals_with_both_errors():
    r = uc.residuals(0.0994, 0.0006, 0.0972, 0.0002)
    assert r["residual"] == pytest.approx(0.0994 / 0.0972 - 1, rel=1e-12)
    assert r["z"] == pytest.approx(0.0022 / math.hypot(0.0006, 0.0002), rel=1e-12)
    assert r["residual_err"] == pytest.approx(0.0994 / 0.0972 * math.hypot(0.0006 / 0.0994, 0.0002 / 0.0972), rel=1e-12)


def test_the_residual_error_of_a_negative_estimate_is_positive():
    """An extrapolated κ∞ below zero (a small grid): r = κ/κ_ref = −0.5, σ_r = |r| √((σ/κ)² + (σ_ref/κ_ref)²)."""
    r = uc.residuals(-0.05, 0.01, 0.1, 0.001)
    assert r["residual"] == pytest.approx(-1.5, rel=1e-12)
    assert r["residual_err"] == pytest.approx(0.5 * math.hypot(0.01 / 0.05, 0.001 / 0.1), rel=1e-12)


def _boxes(leak_every=4, self_every=4, cut_box=None, kept=4, w=None):
    """16 boxes of side 0.5 over [−1, 1]², 16 samples each: rank % leak_every == 0 escapes, rank % self_every == 1
    returns into its own box, the others into the next box (T = 2). ``cut_box`` keeps only its first ``kept``
    ranks (a box cut by the section's boundary); ``w`` the samples' weights (default 1)."""
    cell, rank = np.repeat(np.arange(16), 16), np.tile(np.arange(16), 16)
    nxt = np.where(rank % self_every == 1, cell, (cell + 1) % 16)
    tab = pd.DataFrame(
        {
            "cell": cell,
            "rank": rank,
            "w": 1.0 if w is None else w,
            "censored": False,
            "ret": rank % leak_every > 0,
            "T": 2.0,
            "t_end": 2.0,
            "x1": -0.75 + 0.5 * (nxt % 4),
            "y1": -0.75 + 0.5 * (nxt // 4),
            "e1": 0.3,
        }
    )
    if cut_box is not None:
        tab = tab[(tab.cell != cut_box) | (tab["rank"] < kept)].reset_index(drop=True)
    return tab


def test_energy_results_give_the_closed_form_rate_at_every_partition():
    """A quarter of every box leaves per return of time 2: ρ(M(κ)) = ¾ e^{2κ} = 1 → κ = ln(4/3)/2 on the finest
    boxes, on merged boxes, on every sample subset, on the whole extrapolation grid, hence κ∞ too."""
    exact = math.log(4 / 3) / 2
    res = uc.energy_results(_boxes(), (-1, 1, -1, 1), 0.5, [1, 2], [4, 16], 16, 3, 2, 1, 0.3)
    assert res["kappa"] == pytest.approx(exact, rel=1e-9)
    assert [r["vary"] for r in res["rows"]] == ["box", "box", "samples", "samples"]
    assert all(r["kappa"] == pytest.approx(exact, rel=1e-9) for r in res["rows"])
    assert res["grid"]["kappa"].to_numpy() == pytest.approx(exact, rel=1e-9)
    assert res["cost"]["orbits"] == 256 and res["cost"]["orbit_time"] == pytest.approx(512.0)
    rec = uc.convergence_record(0.3, res["grid"], res["boot_grid"], res["kappa"], {"kappa0": (exact, 0.001)})
    assert rec["kappa_inf"] == pytest.approx(exact, rel=1e-9) and rec["verdict_kappa0"].startswith("agrees")
    far = uc.convergence_record(0.3, res["grid"], res["boot_grid"], res["kappa"], {"kappa0": (0.5, 0.001)})
    assert far["verdict_kappa0"].startswith(("agrees (z = −", "differs (z = −")) and far["residual_kappa0"] < 0


def test_measure_on_cut_boxes_counts_the_boxes_and_the_heaviest_sample():
    """One box of 16 cut to 4 samples, one of them 9 times heavier than the rest: the cut box is 1/16 of the
    class, holds 12/(12 + 15·16) of the flux weight, and its heaviest sample carries 9/12 of the box's."""
    w = np.ones(256)
    w[0] = 9.0  # box 0, rank 0
    tab = _boxes(cut_box=0, kept=4, w=w)
    res = uc.energy_results(tab, (-1, 1, -1, 1), 0.5, [1], [16], 16, 2, 2, 1, 0.3)
    r = uc.measure_on_cut_boxes(res, 16)
    assert r["cut_share"] == pytest.approx(1 / 16)
    assert r["cut_weight"] == pytest.approx(12 / (12 + 15 * 16))
    assert r["cut_top_weight"] == pytest.approx(9 / 12) and r["full_top_weight"] == pytest.approx(1 / 16)
    assert 0 < r["cut_nu"] < 1


def test_kappa_convergence_fits_a_replicate_on_the_partitions_where_it_has_a_kappa():
    """A replicate without κ at one partition (no open class left) is extrapolated on the other eight: with
    exact model data its intercept is still κ∞, so three such replicates and one complete give no spread."""
    g = _grid(0.33, 0.2, 0.03, 0.5)
    reps = []
    for r in range(4):
        part = g.assign(rep=r)
        if r < 3:
            part.loc[(part.box == part.box.min()) & (part.samples == 4), "kappa"] = np.nan
        reps.append(part)
    c = uc.kappa_convergence(g, pd.concat(reps))
    assert c["stat_err"] == pytest.approx(0.0, abs=1e-12) and math.isfinite(c["err"])
