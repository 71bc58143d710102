"""Every public function of the modules of ``hhscatter.analysis``, called with wrong arguments (hypothesis).

Each such function gets every required argument replaced by one wrong thing (nothing, a word, a mapping, an
empty array, an array with a NaN, a NaN): it must refuse with an :class:`~hhscatter.errors.HHScatterError` or
return a result without a numpy warning and without a NaN for a number. A TypeError, IndexError, ZeroDivisionError
or a warning from deep inside numpy is a failure. The functions of :data:`MATCHED` also get valid arguments with one
per-orbit array one value short: a mismatched length must be refused, never truncated or broadcast.

:data:`NOT_YET_CHECKED` lists the functions that do not check their arguments before work yet; each is an
expected failure here (strict: a function that starts checking its arguments fails until it leaves the list).
"""

from __future__ import annotations

import inspect
import math
import warnings

import numpy as np
import pytest
from _walk import public_callables
from hypothesis import given, settings
from hypothesis import strategies as st

from hhscatter.errors import HHScatterError

PROFILE = settings(max_examples=12)  # the rest from the suite's profile (conftest.py)

#: the wrong things put in place of every required argument
WRONG = st.sampled_from(
    [None, "x", {"a": 1}, np.array([]), np.array([math.nan, 1.0]), math.nan, [math.inf], -1.0],
)


def _public_functions() -> dict[str, object]:
    """Every public function of every public module of the subpackages, exported or not: ``sub.name`` where the
    package exports it, ``sub.module.name`` where it does not (a function named as its module, whose name the
    package gives to the module: ``survival.escape_rate.escape_rate``)."""
    out = {}
    for sub, pkg, stem, name, obj in public_callables():
        if inspect.isfunction(obj):
            exported = pkg._EXPORTS.get(name) == stem
            out[f"{sub}.{name}" if exported else f"{sub}.{stem}.{name}"] = obj
    return out


FUNCTIONS = _public_functions()

#: functions that do not check their arguments before work yet (each fails the test below): none now; a function
#: listed here is a strict expected failure, so one that starts checking fails the suite until it leaves the list
NOT_YET_CHECKED: frozenset[str] = frozenset()


def _required(f) -> list[str]:
    kinds = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    return [p.name for p in inspect.signature(f).parameters.values() if p.kind in kinds and p.default is p.empty]


def _check_outcome(f, kwargs):
    """f(**kwargs) refuses with the project's error, or returns without a numpy warning and without a NaN number."""
    with warnings.catch_warnings(), np.errstate(all="raise"):
        warnings.simplefilter("error")
        try:
            out = f(**kwargs)
        except HHScatterError:
            return
    if isinstance(out, float):
        assert not math.isnan(out), "a NaN returned for wrong arguments"
    if isinstance(out, np.ndarray) and out.dtype.kind == "f":
        assert not np.isnan(out).any(), "a NaN returned for wrong arguments"


def _params(names):
    return [
        pytest.param(n, marks=pytest.mark.xfail(strict=True, reason="arguments not checked before work"))
        if n in NOT_YET_CHECKED
        else n
        for n in names
    ]


def test_the_list_names_public_functions_only():
    assert NOT_YET_CHECKED <= set(FUNCTIONS)


@pytest.mark.parametrize("name", _params(sorted(FUNCTIONS)))
@PROFILE
@given(wrong=WRONG)
def test_wrong_arguments_are_refused_or_harmless(name, wrong):
    f = FUNCTIONS[name]
    _check_outcome(f, {arg: wrong for arg in _required(f)})


# -- mismatched lengths: valid arguments, one per-orbit array one value short ------------------------------------
N = 40
T_END = np.linspace(0.5, 20.0, N)
ESCAPED = np.arange(N) % 4 > 0

#: {function: (valid keyword arguments, the per-orbit arrays among them)}
MATCHED = {
    "survival.escape_rate_mle": (
        {"t_end": T_END, "observed": ESCAPED, "t_start": 1.0, "t_stop": 15.0},
        ("t_end", "observed"),
    ),
    "survival.power_law_exponent_mle": (
        {"t_end": T_END, "observed": ESCAPED, "t_start": 1.0, "t_stop": 15.0},
        ("t_end", "observed"),
    ),
    "noise.thermal_rate": ({"t_end": T_END, "escaped": ESCAPED, "t_start": 1.0, "t_stop": 15.0}, ("t_end", "escaped")),
    "noise.exit_fractions": (
        {
            "t_end": T_END,
            "escaped": ESCAPED,
            "exit_channel": np.arange(N) % 3,
            "t_start": 1.0,
            "t_stop": 15.0,
            "n_exits": 3,
        },  # fmt: skip
        ("t_end", "escaped", "exit_channel"),
    ),
    "noise.reactivation_survival": (
        {"t": np.array([1.0, 2.0]), "t_end": T_END, "escaped": ESCAPED, "settled": ~ESCAPED, "rate": 0.1},
        ("t_end", "escaped", "settled"),
    ),
    "survival.paired_bootstrap_ratio": (
        {
            "t_ref": T_END,
            "observed_ref": ESCAPED,
            "t_alt": 0.9 * T_END,
            "observed_alt": ESCAPED,
            "estimator": lambda t, o: o.sum() / t.sum(),
            "n_boot": 5,
        },  # fmt: skip
        ("t_ref", "observed_ref", "t_alt", "observed_alt"),
    ),
}


def test_the_matched_table_names_public_functions_and_their_arguments():
    for name, (kwargs, arrays) in MATCHED.items():
        assert name in FUNCTIONS, name
        assert set(arrays) <= set(kwargs) <= set(inspect.signature(FUNCTIONS[name]).parameters), name


@pytest.mark.parametrize("name", sorted(MATCHED))
def test_the_valid_arguments_of_the_matched_table_give_a_result(name):
    kwargs, _ = MATCHED[name]
    assert FUNCTIONS[name](**kwargs) is not None


@pytest.mark.parametrize("name", sorted(MATCHED))
@PROFILE
@given(data=st.data())
def test_a_per_orbit_array_one_short_is_refused(name, data):
    kwargs, arrays = MATCHED[name]
    short = data.draw(st.sampled_from(arrays))
    bad = {**kwargs, short: np.asarray(kwargs[short])[:-1]}
    with pytest.raises(HHScatterError):
        FUNCTIONS[name](**bad)
