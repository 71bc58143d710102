"""Pearson's χ² with pooled cells against hand-counted cells and against samples of a known law."""

import math

import numpy as np
import pytest

from hhscatter.analysis.stats.goodness import pool_cells, pooled_pearson


def test_a_tail_cell_joins_its_neighbour_and_totals_are_kept():
    o, e = pool_cells([40, 30, 3, 1, 1], [42.0, 28.0, 6.0, 0.9, 1e-5])
    assert o.tolist() == [40.0, 30.0, 5.0] and e == pytest.approx([42.0, 28.0, 6.90001])
    # an underfull remainder (4 + 0.9 + 1e-5 < 5) joins the cell before it
    o, e = pool_cells([40, 30, 3, 1, 1], [42.0, 28.0, 4.0, 0.9, 1e-5])
    assert o.tolist() == [40.0, 35.0] and e == pytest.approx([42.0, 32.90001])


def test_chi2_and_dof_are_counted_after_pooling():
    g = pooled_pearson([40, 30, 3, 1, 1], [42.0, 28.0, 6.0, 0.9, 1e-5], n_fitted=1)
    by_hand = 2**2 / 42 + 2**2 / 28 + 1.90001**2 / 6.90001
    assert (g.cells, g.dof) == (3, 1) and g.chi2 == pytest.approx(by_hand)
    assert g.p_value == pytest.approx(math.erfc(math.sqrt(by_hand / 2)))  # χ²₁ tail: erfc(√(x/2))
    assert not g.too_few


def test_one_observation_in_a_nearly_empty_cell_does_not_decide_the_test():
    # unpooled: (1 − 1e-5)²/1e-5 ≈ 1e5 from that cell alone
    g = pooled_pearson([50, 30, 20, 1], [50.5, 30.0, 20.5, 1e-5], n_fitted=1)
    assert g.chi2 < 1 and g.p_value > 0.3


def test_too_few_orbits_is_neither_yes_nor_no():
    g = pooled_pearson([2, 3, 1, 0], [2.0, 2.0, 1.5, 0.5], n_fitted=1)
    assert g.too_few and math.isnan(g.p_value) and math.isnan(g.chi2) and g.cells == 1


@pytest.mark.parametrize("bad", [dict(observed=[1, 2], expected=[1.0]), dict(observed=[1], expected=[-1.0])])
def test_bad_counts_refused(bad):
    with pytest.raises(ValueError, match="observed"):
        pool_cells(bad["observed"], bad["expected"])


def test_p_values_of_a_true_multinomial_are_uniform():
    rng = np.random.default_rng(11)
    probs = np.array([0.3, 0.3, 0.2, 0.15, 0.04, 0.009, 0.001])  # the tail cells expect < 5 at n = 200
    n = 200
    p = np.array([pooled_pearson(rng.multinomial(n, probs), n * probs).p_value for _ in range(400)])
    # rejections at 5 %: 20 expected of 400, binomial 1σ 4.4; within ±3σ
    assert 7 <= int((p < 0.05).sum()) <= 33
    assert 0.4 < float((p < 0.5).mean()) < 0.6
