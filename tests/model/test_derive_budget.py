"""The symbolic derivation has a time budget: a dense polynomial with many-digit coefficients is refused with a
clear message (and the way around it) instead of running for hours."""

from __future__ import annotations

import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

from hhscatter.errors import ConfigError
from hhscatter.model.landscape import BUDGET_ENV, symbolic_budget, unbounded_derivation


def _dense_polynomial(degree: int = 8, seed: int = 1) -> str:
    """V = (x² + y²)/2 + every monomial of degree 3..degree with a six-digit coefficient (a lex Gröbner basis of
    its gradient takes minutes to hours)."""
    rng = random.Random(seed)
    terms = ["0.5*(x**2 + y**2)"]
    for d in range(3, degree + 1):
        for i in range(d + 1):
            terms.append(f"{rng.uniform(-0.3, 0.3):.6f}*x**{i}*y**{d - i}")
    return " + ".join(terms).replace("+ -", "- ")


def test_a_dense_polynomial_is_refused_within_the_budget(tmp_path):
    potential = _dense_polynomial()
    assert 700 < len(potential) < 1000
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[2]), **{BUDGET_ENV: "1"})
    args = ["simulate", "--system", potential, "--energy", "0.3", "-n", "10", "--out", "o"]
    try:
        r = subprocess.run(
            [sys.executable, "-m", "hhscatter", *args],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=90,
        )
    except subprocess.TimeoutExpired:
        pytest.fail("the derivation ran past its budget")
    assert r.returncode == 2, r.stderr
    assert "the critical points of the potential were not derived within 1 s" in r.stderr
    assert "give `critical_energy` and `exits` in [system]" in r.stderr and "Traceback" not in r.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("text", ["0", "-1", "soon", "nan", "inf"])
def test_the_budget_must_be_a_positive_number_of_seconds(monkeypatch, text):
    monkeypatch.setenv(BUDGET_ENV, text)
    with pytest.raises(ConfigError, match=f"{BUDGET_ENV} must be a number of seconds > 0, got {text!r}"):
        symbolic_budget()


def test_a_worker_rebuilding_an_accepted_system_has_no_budget(monkeypatch):
    monkeypatch.setenv(BUDGET_ENV, "2.5")
    assert symbolic_budget() == 2.5
    with unbounded_derivation():
        assert symbolic_budget() is None
    assert symbolic_budget() == 2.5
