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
