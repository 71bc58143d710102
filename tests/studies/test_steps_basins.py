"""Direct tests of steps of the basins study's analyze on synthetic input with known answers."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from hhscatter.studies import stage_module

mod = stage_module("basins")

ALPHA, C, N = 0.4, 0.5, 200_000


def _unc(eps, k_override=None):
    """An f(ε) table of the exact power law f = C ε^α with counts k = round(f n) (``k_override``: {index: k})."""
    eps = np.asarray(eps, dtype=float)
    k = np.round(C * eps**ALPHA * N).astype(int)
    for i, v in (k_override or {}).items():
        k[i] = v
    return pd.DataFrame({"eps": eps, "f": k / N, "k": k, "n": N})


def test_uncertainty_fits_choose_the_resolved_window():
    # ε decreasing, as in the study; the two smallest ε are unresolved (k < 10) and far off the power law:
    # the window must leave them out
    eps = np.geomspace(1e-2, 1e-9, 8)
    unc = _unc(eps, {6: 9, 7: 3})
    ok, fit, cut = mod._uncertainty_fits(unc, 10)
    np.testing.assert_array_equal(ok.to_numpy(), [True] * 6 + [False, False])
    assert fit.eps_range == (eps[5], eps[0])
    assert fit.n_points == 6
    assert fit.alpha == pytest.approx(ALPHA, abs=5e-3)  # rounding of the counts only
    assert cut is not None and not cut.detected  # a single power law: no cut-off


def test_uncertainty_fits_need_three_points_for_alpha_and_five_for_the_cutoff():
    eps = np.geomspace(1e-2, 1e-6, 6)
    for n_ok, has_fit, has_cut in [(2, False, False), (3, True, False), (4, True, False), (5, True, True)]:
        unc = _unc(eps, {i: 0 for i in range(n_ok, len(eps))})
        ok, fit, cut = mod._uncertainty_fits(unc, 10)
        assert int(ok.sum()) == n_ok
        assert (fit is not None, cut is not None) == (has_fit, has_cut), n_ok


def test_point_numbers_tau2_and_smallest_resolved_eps():
    """τ2 = ln(E0/E_c)/γ (Eq. (eq:tau2) with μ = 1; ∞ at γ = 0) and the smallest resolved ε's decision time."""
    eps = np.geomspace(1e-2, 1e-6, 6)  # decreasing, as in the study
    unc = _unc(eps, {5: 0}).assign(t_decide_median=np.arange(6.0) + 10)
    ok, fit, cut = mod._uncertainty_fits(unc, 10)

    class Frac:
        frac, lo, hi, n = [1.0, 0, 0, 0, 0], [0.9, 0, 0, 0, 0], [1.0, 0, 0, 0, 0], 100

    class Wada:
        wada, wada_fraction, r_wada, hausdorff_slope = False, np.array([0.1, 0.2]), 5, 1.0

    class Chans:
        p_value, frac = 0.5, [1 / 3] * 3

    ent = pd.DataFrame({"box": [5], "S_b": [0.3], "S_b_err": [0.01], "S_bb": [0.8], "S_bb_err": [0.02],
                        "log2_fractal": [True]})
    loc = pd.DataFrame({"eps_mid": [1e-3, 1e-4], "d": [1.5, math.nan], "d_err": [0.1, math.nan]})
    m = {"fr": Frac, "present": [0], "wada": Wada, "chans": Chans, "exits": [0], "wada_x": None, "slim": None,
         "rate": None, "ok": ok, "fit": fit, "cut": cut}
    ec = 1 / 6
    p = mod._point_numbers(0.3, 0.01, 5, ec, ent, unc, loc, m)
    assert p["tau2_mu1"] == pytest.approx(math.log(0.3 / ec) / 0.01, rel=1e-15)
    assert mod._point_numbers(0.3, 0.0, 5, ec, ent, unc, loc, m)["tau2_mu1"] == math.inf
    # the smallest resolved ε is the fifth row (the sixth has k = 0); its decision time comes along
    assert p["smallest_resolved_eps"] == eps[4] and p["t_decide_median_smallest_eps"] == 14.0
    assert p["S_bb"] == {"value": 0.8, "err": 0.02} and p["log2_fractal"] is True
    assert p["wada"]["W_at_r"] == 0.2  # r_wada beyond the table: its last entry
    assert p["local_d"] == [{"eps_mid": 1e-3, "d": 1.5, "d_err": 0.1}]  # NaN rows dropped
    # a headline box not in the table: no entropies
    assert mod._point_numbers(0.3, 0.01, 7, ec, ent, unc, loc, m)["S_b"] is None
