"""Pearson's χ² goodness of fit that holds in the tails: cells pooled to an expected count of at least 5.

Pearson's χ² = Σ (O − E)²/E follows its χ² distribution only when every expected count E is large (the usual
rule: E ≥ 5). A cell with E ~ 1e-5 that holds one observation adds 1e5 to χ² by itself: the test then measures
that one observation, not the fit. :func:`pooled_pearson` merges adjacent cells (in their order, so a tail cell
joins its neighbour) until every pooled cell expects at least ``min_expected``, counts the degrees of freedom
after pooling (pooled cells − 1 − fitted parameters) and, when fewer than ``min_dof`` remain, reports "too few
orbits" instead of a p-value: a verdict is then neither yes nor no.

Examples
--------
>>> g = pooled_pearson([50, 30, 15, 4, 1], [48.0, 31.0, 14.0, 6.9, 0.1], n_fitted=1)
>>> g.cells, g.dof, round(g.chi2, 3)      # the last two pooled (5 against 7): 4/48 + 1/31 + 1/14 + 4/7
(4, 2, 0.758)
>>> pooled_pearson([3, 2], [2.5, 2.5], n_fitted=1).too_few
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

#: the smallest expected count of a pooled cell
MIN_EXPECTED = 5.0
#: the verdict of a goodness-of-fit test left without a degree of freedom by the pooling (``PooledPearson.too_few``)
TOO_FEW = "too few orbits"


@dataclass(frozen=True)
class PooledPearson:
    """Result of :func:`pooled_pearson`.

    Attributes
    ----------
    chi2 : float
        Pearson's χ² over the pooled cells (NaN when ``too_few``).
    dof : int
        Pooled cells − 1 − fitted parameters.
    p_value : float
        P(χ²_dof ≥ chi2); NaN when ``too_few``.
    cells : int
        The number of cells after pooling.
    too_few : bool
        True when the pooled cells leave fewer than ``min_dof`` degrees of freedom: too few orbits for a verdict.
    """

    chi2: float
    dof: int
    p_value: float
    cells: int
    too_few: bool


def pool_cells(observed, expected, min_expected: float = MIN_EXPECTED) -> tuple[np.ndarray, np.ndarray]:
    """pool_cells(observed, expected, min_expected=5) -> (observed, expected) of the pooled cells.

    Adjacent cells are merged from the first on until the running expected count reaches ``min_expected``; an
    underfull remainder at the end (the tail) joins the last pooled cell. Totals are kept.

    >>> o, e = pool_cells([10, 2, 1, 9, 0], [9.0, 3.0, 2.5, 8.0, 1e-5])
    >>> o.tolist(), e.round(5).tolist()
    ([10.0, 3.0, 9.0], [9.0, 5.5, 8.00001])
    """
    o = check.numbers(observed, "observed", min_size=0)
    e = check.numbers(expected, "expected", min_size=0)
    check.number(min_expected, "min_expected")
    if o.shape != e.shape:
        raise ConfigError(f"observed and expected differ in length ({o.size} and {e.size})")
    if (e < 0).any() or (o < 0).any():
        raise ConfigError("observed and expected counts must be ≥ 0")
    if not min_expected > 0:
        raise ConfigError(f"min_expected must be > 0, got {min_expected}")
    po, pe, acc_o, acc_e = [], [], 0.0, 0.0
    for a, b in zip(o, e):
        acc_o, acc_e = acc_o + a, acc_e + b
        if acc_e >= min_expected:
            po.append(acc_o)
            pe.append(acc_e)
            acc_o = acc_e = 0.0
    if acc_e > 0 or acc_o > 0:
        if pe:
            po[-1] += acc_o
            pe[-1] += acc_e
        else:
            po.append(acc_o)
            pe.append(acc_e)
    return np.array(po), np.array(pe)


def pooled_pearson(
    observed, expected, *, n_fitted: int = 0, min_expected: float = MIN_EXPECTED, min_dof: int = 1
) -> PooledPearson:
    """pooled_pearson(observed, expected, n_fitted=0, min_expected=5, min_dof=1) -> PooledPearson.

    Pearson's χ² of counts ``observed`` against ``expected`` (same cells, in an order where neighbours may be
    merged: time bins, the tail last) after :func:`pool_cells`; degrees of freedom pooled cells − 1 − ``n_fitted``
    (the model's parameters fitted on the same data). With fewer than ``min_dof`` degrees of freedom left the
    result is ``too_few`` (χ² and p NaN): too few orbits for a verdict.

    Parameters
    ----------
    observed, expected : array (cells,)
        Counts per cell (orbits), with the same total.
    n_fitted : int
        Parameters fitted on these data.
    min_expected : float
        The smallest expected count of a pooled cell (5: the usual validity rule of the χ² approximation).
    min_dof : int
        The fewest degrees of freedom for which a p-value is given.

    Examples
    --------
    >>> pooled_pearson([20, 20, 20], [20.0, 20.0, 20.0]).p_value
    1.0
    """
    check.count(n_fitted, "n_fitted", 0)
    check.count(min_dof, "min_dof", 0)
    from scipy.stats import chi2 as chi2_dist  # deferred: scipy loads on first use

    o, e = pool_cells(observed, expected, min_expected)
    keep = e > 0
    cells = int(keep.sum())
    dof = cells - 1 - int(n_fitted)
    if dof < max(int(min_dof), 1) or (cells and e[keep].min() < min_expected):
        return PooledPearson(math.nan, dof, math.nan, cells, True)
    chi2 = float((((o - e) ** 2)[keep] / e[keep]).sum())
    return PooledPearson(chi2, dof, float(chi2_dist.sf(chi2, dof)), cells, False)
