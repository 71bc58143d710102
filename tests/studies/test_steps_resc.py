"""Direct tests of steps of the resc figure on synthetic tables with known answers."""

from __future__ import annotations

import importlib

import numpy as np
import pandas as pd
import pytest

from hhscatter.studies import stage_module

fig = importlib.import_module(f"{stage_module('resc').__package__}.figure")  # the folder's figure module


def test_logx_offsets_in_decades_of_r_minus_one():
    np.testing.assert_allclose(fig._logx([1.03, 2.0]), [0.03, 1.0], rtol=1e-15)
    np.testing.assert_allclose(fig._logx([1.1], 1.0), [1.0], rtol=1e-12)


def test_kappa_shift_ylim_holds_the_bars_and_the_cross_checks():
    """Range in % of κ(r_ref): min/max over the ±1σ bars and both cross-check markers, padded 0.6·span."""
    kappa = pd.DataFrame(
        {
            "energy": [0.3, 0.3],
            "r_esc": [1.03, 2.0],
            "kappa": [2.0, 2.1],
            "kappa_shift": [0.0, 0.1],  # 0 %, +5 %
            "kappa_shift_err": [0.0, 0.02],  # ±1 %  -> bars [0, 0] and [4, 6] %
            "mle_shift": [0.0, 0.16],  # +8 %: above the bars
            "kappa_lsq": [4.0, 3.8],  # −5 %: below the bars
        }
    )
    lo, hi = fig._kappa_shift_ylim(kappa, [0.3], 1.03)
    pad = 0.6 * (8.0 - (-5.0))
    assert lo == pytest.approx(-5.0 - pad, rel=1e-12)
    assert hi == pytest.approx(8.0 + 0.5 * pad, rel=1e-12)
    # a span below 1 % is padded as 1 %
    flat = kappa.assign(kappa_shift=0.0, kappa_shift_err=0.0, mle_shift=0.0, kappa_lsq=4.0)
    assert fig._kappa_shift_ylim(flat, [0.3], 1.03) == pytest.approx((-0.6, 0.3), abs=1e-12)


def test_a_return_count_of_zero_is_drawn_at_the_one_sided_bound_the_table_prints():
    """Panel (c): 0 returns of 60 000 escapes sit at 1 − 0.05^(1/60000) ≈ 5.0e−5 (the table's "< 5.0e−5 (95 %)"),
    not at the two-sided 95 % Wilson upper limit 1.96²/(n + 1.96²) ≈ 6.4e−5; the legend says which bound it is."""
    from matplotlib.figure import Figure

    n = 60000
    returns = pd.DataFrame(
        {
            "energy": [0.3, 0.3],
            "r_esc": [1.03, 2.0],
            "n_escaped": [n, n],
            "n_returned": [177, 0],
            "frac": [177 / n, 0.0],
            "lo": [0.0027, 0.0],
            "hi": [0.0032, 1.0 / (n + 1)],
            "upper95": [0.0034, 1.96**2 / (n + 1.96**2)],  # what the returns table once held for a count of 0
        }
    )
    lyapunov = pd.DataFrame({"energy": [0.3], "r_min": [1.1], "r_max": [1.3]})
    ax = Figure().subplots()
    fig._panel_returns(ax, returns, lyapunov, [0.3], [1.03, 2.0], {0.3: "k"})
    drawn = [line for line in ax.get_lines() if line.get_marker() == "v" and len(line.get_ydata())]
    assert len(drawn) == 1
    np.testing.assert_allclose(drawn[0].get_ydata(), [1 - 0.05 ** (1 / n)], rtol=1e-4)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("one-sided 95 % upper bound" in " ".join(t.split()) for t in labels), labels
