"""Library warnings inside an analysis are counted, not shown and not dropped (hhscatter.analysis.stats.counted)."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.stats import counted, reset_warning_counts, warning_counts


@pytest.fixture(autouse=True)
def _empty_tally():
    reset_warning_counts()
    yield
    reset_warning_counts()


def test_each_warning_counted_under_its_place_and_not_shown():
    with warnings.catch_warnings(record=True) as outside:
        warnings.simplefilter("always")
        with counted("a.fit"):
            for _ in range(3):
                np.exp(np.array([1000.0]))  # numpy's overflow RuntimeWarning, three times
            warnings.warn("first line\nsecond line", UserWarning, stacklevel=2)
        with counted("b.sample"):
            warnings.warn("first line\nsecond line", UserWarning, stacklevel=2)
    assert outside == []  # nothing reached the caller
    got = {(r["where"], r["category"], r["message"]): r["count"] for r in warning_counts()}
    assert got == {
        ("a.fit", "RuntimeWarning", "overflow encountered in exp"): 3,
        ("a.fit", "UserWarning", "first line"): 1,
        ("b.sample", "UserWarning", "first line"): 1,
    }


def test_an_error_passes_through_and_the_warnings_before_it_are_kept():
    with pytest.raises(ValueError, match="bad fit"):
        with counted("c.fit"):
            warnings.warn("before the error", RuntimeWarning, stacklevel=2)
            raise ValueError("bad fit")
    assert warning_counts() == [
        {"where": "c.fit", "category": "RuntimeWarning", "message": "before the error", "count": 1}
    ]


def test_a_claims_rate_counts_what_its_fit_warns(monkeypatch):
    """The claims' escape rate used to silence its fit's warnings; now they reach the tally under its name."""
    from hhscatter.reproduction.claims import kappa

    def warns(*a, **k):
        warnings.warn("Covariance of the parameters could not be estimated", RuntimeWarning, stacklevel=2)
        raise ValueError("too few escapes")

    monkeypatch.setattr(kappa, "escape_rate_from_lifetimes", warns)
    lt = pd.DataFrame({"t_end": np.arange(1.0, 11.0), "outcome": ["escaped"] * 10})
    res, reason = kappa.rate_or_reason(lt, 50.0)
    assert res is None and reason == "too few escapes"
    assert warning_counts() == [
        {
            "where": "claims.kappa.rate_or_reason",
            "category": "RuntimeWarning",
            "message": "Covariance of the parameters could not be estimated",
            "count": 1,
        }
    ]
