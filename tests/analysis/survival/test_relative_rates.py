"""Rates relative to a reference ensemble: κ = n/Σt for lifetimes all inside the window (by hand), and the
ratio's error σ_r = r √((σ/κ)² + (σ_ref/κ_ref)²) with σ = κ/√n."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hhscatter.analysis.survival.relative_rates import relative_rates


def test_rates_and_ratios_against_the_closed_forms():
    rng = np.random.default_rng(5)
    a, b = rng.exponential(50.0, 900), rng.exponential(25.0, 400)
    rows = relative_rates([(a, np.ones(a.size, bool)), (b, np.ones(b.size, bool))], 0.0, 1e5)
    ka, kb = 900 / a.sum(), 400 / b.sum()
    assert rows[0].rate.kappa == pytest.approx(ka, rel=1e-12)
    assert rows[1].rate.kappa == pytest.approx(kb, rel=1e-12)
    assert rows[1].ratio.value == pytest.approx(kb / ka, rel=1e-12)
    assert rows[1].ratio.err == pytest.approx(kb / ka * math.sqrt(1 / 400 + 1 / 900), rel=1e-12)
    assert rows[0].ratio.value == 1.0


def test_without_a_reference_there_is_no_ratio_and_a_bad_reference_is_refused():
    t = np.array([1.0, 2.0, 4.0])
    assert relative_rates([(t, np.ones(3, bool))], 0.0, 10.0, ref=None)[0].ratio is None
    with pytest.raises(ValueError, match="ref = 3"):
        relative_rates([(t, np.ones(3, bool))], 0.0, 10.0, ref=3)
