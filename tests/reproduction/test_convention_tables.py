"""κ under the conventions of the κ figure and the κ(E) law's spread across them
(hhscatter.reproduction.convention_tables), on synthetic rows with known answers."""

import math
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from hhscatter.analysis.survival.escape_rate import escape_rate
from hhscatter.errors import ConfigError
from hhscatter.reproduction.convention_tables import convention_rows, fit_laws, law_spread, stable_energies


def test_stable_energies_need_agreement_of_the_defined_conventions():
    rows = []
    for e, ks, defined in (
        (0.2, [0.020, 0.021, 0.030, 0.0], [1, 1, 1, 0]),  # 40 % range: unstable
        (0.3, [0.200, 0.205, 0.198, 0.0], [1, 1, 1, 0]),  # 3.5 %: stable (undefined one ignored)
        (0.4, [0.3, 0.0, 0.0, 0.0], [1, 0, 0, 0]),
    ):  # one convention only: unstable
        rows += [{"energy": e, "kappa": k, "defined": bool(d)} for k, d in zip(ks, defined)]
    s = stable_energies(pd.DataFrame(rows), rel_tol=0.1).set_index("energy")
    assert list(s["stable"]) == [False, True, False]
    assert s.loc[0.3, "rel_range"] == pytest.approx((0.205 - 0.198) / np.mean([0.2, 0.205, 0.198]))
    assert list(s["n_defined"]) == [3, 3, 1]


def test_law_spread_is_half_the_range_across_conventions():
    def fit(a, err):
        return SimpleNamespace(a=a, b=0.1, c=1.4, E_b=0.27, a_err=err, b_err=0.01, c_err=0.02, E_b_err=0.005)

    out = law_spread({"one": fit(10.0, 1.0), "two": fit(14.0, 2.0)})
    assert out["a"]["value"] == 12.0 and out["a"]["spread"] == 2.0 and out["a"]["err_stat"] == 2.0
    assert out["a"]["err"] == pytest.approx(math.hypot(2.0, 2.0))
    assert out["c"]["spread"] == 0.0 and out["a"]["per_convention"] == {"one": 10.0, "two": 14.0}


def test_convention_rows_recover_the_rate_of_exponential_lifetimes_under_both_rules():
    t = np.random.default_rng(3).exponential(1 / 0.2, 40000)
    obs = np.ones(t.size, bool)
    rows = convention_rows(t, obs, escape_rate(t, obs, detect_tail=False))
    assert [r["windows"] for r in rows] == ["plateau", "plevel"]
    for r in rows:
        assert r["defined"] and r["n"] == 40000 and abs(r["kappa"] - 0.2) < 4 * r["kappa_err"]


def test_no_fits_to_spread_are_refused():
    with pytest.raises(ConfigError, match="fits must hold at least 1"):
        law_spread({})


@pytest.mark.parametrize(
    ("f", "kwargs", "arg"),
    [
        (stable_energies, {"table": pd.DataFrame({"energy": [0.3], "kappa": [0.2]})}, "table"),
        (
            stable_energies,
            {"table": pd.DataFrame({"energy": [0.3], "kappa": [0.2], "defined": [True]}), "rel_tol": "x"},
            "rel_tol",
        ),  # fmt: skip
        (
            fit_laws,
            {"table": pd.DataFrame(), "names": ["a"], "energies": [0.3], "E_c": 1 / 6, "n_boot": 0, "seed": 0},
            "table",
        ),  # fmt: skip
        (convention_rows, {"t_end": "x", "observed": [True], "result": None}, "t_end"),
        (convention_rows, {"t_end": [1.0, 2.0], "observed": [True, True], "result": None}, "result"),
    ],
)
def test_a_wrong_argument_is_refused_naming_it(f, kwargs, arg):
    with pytest.raises(ConfigError, match=arg):
        f(**kwargs)
