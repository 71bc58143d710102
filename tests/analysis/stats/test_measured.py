"""The measured value: its JSON shape, and its error propagation against closed forms written here by hand and
against a Monte-Carlo sample of independent Gaussian inputs."""

from __future__ import annotations

import ast
import doctest
import json
import math
from pathlib import Path

import numpy as np
import pytest

from hhscatter.analysis.stats.measured import Measured
from hhscatter.studies.jsonio import write_json_atomic


def test_to_dict_is_the_numbers_json_shape_and_round_trips():
    m = Measured(0.2705, 0.0012, "MLE", 5000)
    assert m.to_dict() == {"value": 0.2705, "err": 0.0012}
    assert list(m.to_dict()) == ["value", "err"]
    back = Measured.from_dict(json.loads(json.dumps(m.to_dict())), "MLE", 5000)
    assert back == m


def test_the_json_writer_writes_a_measured_as_the_literal_dict(tmp_path):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    write_json_atomic(a, {"mu": Measured(0.93, float("nan"), "fit"), "k": [Measured(1.0, 0.1)]})
    write_json_atomic(b, {"mu": {"value": 0.93, "err": float("nan")}, "k": [{"value": 1.0, "err": 0.1}]})
    assert a.read_bytes() == b.read_bytes()
    assert json.loads(a.read_text())["mu"] == {"value": 0.93, "err": None}


ROOT = Path(__file__).resolve().parents[3]


def _value_err_literals(path: Path) -> list[str]:
    """Dict displays of ``path`` whose keys are exactly "value" and "err": a number with its error written by hand."""
    hits = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Dict) and len(node.keys) == 2:
            if {getattr(k, "value", None) for k in node.keys} == {"value", "err"}:
                hits.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return hits


def test_product_code_writes_a_value_with_its_error_as_a_measured():
    # Measured.to_dict is the one place that spells the shape; records with more fields (table rows) are not counted
    files = sorted((ROOT / "hhscatter").rglob("*.py")) + sorted((ROOT / "studies").rglob("*.py"))
    hits = [h for f in files for h in _value_err_literals(f)]
    own = [h for h in hits if h.startswith("hhscatter/analysis/stats/measured.py:")]
    assert len(own) == 1, own
    assert [h for h in hits if h not in own] == []


def _records_with_value_and_err(path: Path) -> list[str]:
    """Dict displays of ``path`` with "value" and "err" among more keys: a table row or record spelling a measured
    value by hand."""
    hits = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Dict) and len(node.keys) > 2:
            if {"value", "err"} <= {getattr(k, "value", None) for k in node.keys}:
                hits.append(f"{path.relative_to(ROOT)}:{node.lineno}")
    return hits


def test_records_with_more_fields_take_their_value_and_error_from_a_measured():
    files = sorted((ROOT / "hhscatter").rglob("*.py")) + sorted((ROOT / "studies").rglob("*.py"))
    assert [h for f in files for h in _records_with_value_and_err(f)] == []


def _doctest_inputs_with_value_and_err(path: Path) -> list[str]:
    """Docstring examples of ``path`` whose input (a ``>>>`` line, not the expected output) spells a dict with
    "value" and "err" keys: a measured value a reader should see as a Measured."""
    parser = doctest.DocTestParser()
    hits = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not (isinstance(node, ast.Constant) and isinstance(node.value, str) and ">>>" in node.value):
            continue
        for ex in parser.get_examples(node.value):
            for sub in ast.walk(ast.parse(ex.source)):
                if isinstance(sub, ast.Dict) and {"value", "err"} <= {getattr(k, "value", None) for k in sub.keys}:
                    hits.append(f"{path.relative_to(ROOT)}:{node.lineno + ex.lineno}")
    return hits


def test_docstring_examples_write_a_value_with_its_error_as_a_measured():
    # Measured.from_dict's own examples read the literal shape back; every other example builds it from a Measured
    files = sorted((ROOT / "hhscatter").rglob("*.py")) + sorted((ROOT / "studies").rglob("*.py"))
    hits = [h for f in files for h in _doctest_inputs_with_value_and_err(f)]
    own = [h for h in hits if h.startswith("hhscatter/analysis/stats/measured.py:")]
    assert len(own) == 2, own
    assert [h for h in hits if h not in own] == []


def test_is_frozen():
    with pytest.raises(AttributeError):
        Measured(1.0, 0.1).value = 2.0


@pytest.mark.parametrize(
    ("op", "value", "err"),
    [
        ("ratio", 6.0 / 2.0, 6.0 / 2.0 * math.sqrt((0.3 / 6.0) ** 2 + (0.1 / 2.0) ** 2)),
        ("product", 12.0, 12.0 * math.sqrt((0.3 / 6.0) ** 2 + (0.1 / 2.0) ** 2)),
        ("difference", 4.0, math.sqrt(0.3**2 + 0.1**2)),
        ("sum", 8.0, math.sqrt(0.3**2 + 0.1**2)),
    ],
)
def test_binary_propagation_matches_the_closed_forms(op, value, err):
    a, b = Measured(6.0, 0.3), Measured(2.0, 0.1)
    got = getattr(a, op)(b)
    assert got.value == pytest.approx(value, rel=1e-15)
    assert got.err == pytest.approx(err, rel=1e-14)
    assert got.method == op
    sym = {"ratio": a / b, "product": a * b, "difference": a - b, "sum": a + b}[op]
    assert sym == got


def test_log_and_scaling_match_the_closed_forms():
    m = Measured(5.0, 0.25, "fit", 7)
    assert m.log().value == pytest.approx(math.log(5.0))
    assert m.log().err == pytest.approx(0.05)
    assert m.scaled(-3.0) == Measured(-15.0, 0.75, "fit", 7)


def test_a_zero_numerator_or_factor_keeps_a_finite_error():
    assert Measured(0.0, 0.4) / Measured(2.0, 0.1) == Measured(0.0, 0.2, "ratio")
    assert (Measured(0.0, 0.4) * Measured(2.0, 0.1)).err == pytest.approx(0.8)


def test_an_exact_number_has_no_error():
    assert (Measured(6.0, 0.3) / 2.0).err == pytest.approx(0.15)
    assert (Measured(6.0, 0.3) - 2.0).err == pytest.approx(0.3)


@pytest.mark.parametrize("op", ["ratio", "product", "difference", "sum", "log"])
def test_propagation_agrees_with_a_monte_carlo_sample(op):
    """Small relative errors (1 %, 2 %): first order is right to ~1 %; 200 000 draws give the std to ~0.2 %."""
    a, b = Measured(3.0, 0.03), Measured(1.5, 0.03)
    rng = np.random.default_rng(7)
    xa = rng.normal(a.value, a.err, 200_000)
    xb = rng.normal(b.value, b.err, 200_000)
    sample = {
        "ratio": xa / xb,
        "product": xa * xb,
        "difference": xa - xb,
        "sum": xa + xb,
        "log": np.log(xa),
    }[op]
    got = a.log() if op == "log" else getattr(a, op)(b)
    assert got.err == pytest.approx(float(sample.std(ddof=1)), rel=0.02)
    # the value is the first-order one: its second-order bias (ratio: a/b (σb/b)²) is a few % of σ here
    assert got.value == pytest.approx(float(sample.mean()), abs=0.05 * got.err)


def test_z_is_the_distance_in_combined_sigma():
    assert Measured(1.3, 0.3).z(1.0, 0.4) == pytest.approx(0.3 / 0.5)


def test_an_estimator_result_gives_its_estimates_as_measured():
    """The MLE escape rate of exponential lifetimes, all escaped inside the window: κ = n / Σt, σ = κ/√n."""
    from hhscatter.analysis.survival.escape_rate import escape_rate_mle

    t = np.random.default_rng(3).exponential(10.0, 400)
    m = escape_rate_mle(t, np.ones(t.size, bool), 0.0, float(t.max()) + 1.0).measured("kappa")
    kappa = 400 / t.sum()
    assert m.value == pytest.approx(kappa, rel=1e-12)
    assert m.err == pytest.approx(kappa / math.sqrt(400), rel=1e-12)
    assert (m.n, m.method) == (400, "maximum likelihood (events / exposure)")


def test_a_result_without_that_estimate_is_refused():
    from hhscatter.analysis.survival.escape_rate import escape_rate_mle

    t = np.array([1.0, 2.0, 3.0])
    with pytest.raises(AttributeError, match="n_events"):
        escape_rate_mle(t, np.ones(3, bool), 0.0, 5.0).measured("n_events")


def test_over_an_exact_number_divides_value_and_error_once():
    """a/c ± σ/|c| with the method and n kept; one rounding each: σ/c itself, where the ratio's |a/c| · σ/|a| is
    one unit in the last place off (a = 1.1, σ = 0.07, c = 0.3)."""
    assert Measured(0.3, 0.06, "MLE", 50).over(-2.0) == Measured(-0.15, 0.03, "MLE", 50)
    m = Measured(1.1, 0.07).over(0.3)
    assert (m.value, m.err) == (1.1 / 0.3, 0.07 / 0.3)
    assert m.err == pytest.approx((Measured(1.1, 0.07) / 0.3).err, rel=1e-15)
    nan = Measured(math.nan, math.nan).over(4.0)
    assert math.isnan(nan.value) and math.isnan(nan.err)
