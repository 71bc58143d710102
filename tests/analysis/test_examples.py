"""Every public function of the modules of ``hhscatter.analysis`` (exported by its package or not: a function
named as its module is reached through the module) shows a runnable example in its own docstring (the examples run
as doctests in the suite).

A new public function without one fails here at once.
"""

from __future__ import annotations

import inspect

import pytest
from test_every_estimator import FUNCTIONS  # every public function, by subpackage[.module].name


def has_example(f) -> bool:
    """Whether the docstring of ``f`` holds a doctest line."""
    return any(line.lstrip().startswith(">>> ") for line in (inspect.getdoc(f) or "").splitlines())


def test_the_check_tells_an_example_from_prose():
    def with_one():
        """Twice x.

        >>> 2 * 3
        6
        """

    def without():
        """Twice x (see the example >>> elsewhere)."""

    assert has_example(with_one) and not has_example(without)


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_every_public_function_has_an_example(name):
    assert has_example(FUNCTIONS[name])


def test_the_functions_named_as_their_module_are_seen():
    assert {"survival.escape_rate.escape_rate", "dissipative.survival_model.survival_model"} <= set(FUNCTIONS)
