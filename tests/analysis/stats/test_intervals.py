"""Binomial fractions: the error, and the one-sided bound at a count of 0 or of all (Clopper–Pearson, scipy)."""

import math

import pytest
from scipy.stats import beta

from hhscatter.analysis.stats.intervals import fraction_with_bound


@pytest.mark.parametrize("n", [1, 20, 2000, 10000])
def test_a_zero_count_has_the_exact_one_sided_upper_bound_not_zero_error(n):
    f = fraction_with_bound(0, n)
    assert f.value == 0 and f.err is None and f.lower is None
    assert f.upper == pytest.approx(beta.ppf(0.95, 1, n), rel=1e-12)  # Clopper–Pearson, one-sided 95 %


def test_a_full_count_has_the_exact_one_sided_lower_bound():
    f = fraction_with_bound(50, 50, cl=0.9)
    assert f.value == 1 and f.err is None and f.upper is None
    assert f.lower == pytest.approx(beta.ppf(0.1, 50, 1), rel=1e-12)


def test_an_inner_count_has_the_binomial_error():
    f = fraction_with_bound(300, 1000)
    assert f.err == pytest.approx(math.sqrt(0.3 * 0.7 / 1000)) and f.upper is None and f.lower is None


def test_the_record_names_the_bound_beside_the_value():
    assert fraction_with_bound(0, 2000).record("P") == {
        "P": 0.0,
        "P_err": None,
        "P_upper": round(beta.ppf(0.95, 1, 2000), 6),
        "P_cl": 0.95,
    }
    assert fraction_with_bound(3, 4).record() == {"value": 0.75, "err": pytest.approx(math.sqrt(0.75 * 0.25 / 4))}


@pytest.mark.parametrize("k, n, cl, what", [(1, 0, 0.95, "n must"), (5, 4, 0.95, "k must"), (0, 4, 1.0, "cl must")])
def test_bad_input_refused(k, n, cl, what):
    with pytest.raises(ValueError, match=what):
        fraction_with_bound(k, n, cl=cl)
