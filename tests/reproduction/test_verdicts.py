"""The one comparison rule with the reference's own uncertainty kind: printed (half a unit of its last digit),
propagated (its 1σ), exact (theory), not the same quantity (no verdict). Expected values are computed here by hand
from the definition z = (ours − reference)/√(σ_ours² + σ_ref²)."""

from __future__ import annotations

import math

import pytest

from hhscatter.analysis.stats.verdicts import verdict_class
from hhscatter.reproduction.verdicts import REFERENCE_KINDS, claim_verdict, reference_kind, row_verdict


def _z(ours, err, ref, ref_err):
    return f"{(ours - ref) / math.hypot(err, ref_err):+.1f}".replace("-", "−")


def test_a_theoretical_exponent_is_exact_not_a_printed_digit():
    """β = 1.46 ± 0.12 against the exponent 2 of theory: 4.5σ away, not 1.0σ as against '2' ± 0.5."""
    row = {"quantity": "β", "ours": 1.46, "err": 0.12, "paper": 2.0, "reference_kind": "exact"}
    assert row_verdict(row) == f"differs (z = {_z(1.46, 0.12, 2.0, 0.0)})" == "differs (z = −4.5)"
    printed = {**row, "reference_kind": "printed"}
    assert row_verdict(printed) == f"agrees (z = {_z(1.46, 0.12, 2.0, 0.5)})"


def test_a_propagated_reference_carries_its_own_error():
    """τ2 from the paper's μ = 0.91: its σ is τ2 · 0.005/0.91, not half a unit of a 16-digit float."""
    tau2, ours, err = 64.59194119803506, 63.0, 0.3
    ref_err = tau2 * 0.005 / 0.91
    row = {"ours": ours, "err": err, "paper": tau2, "paper_err": ref_err}
    assert reference_kind(row) == "propagated"
    assert row_verdict(row) == f"differs (z = {_z(ours, err, tau2, ref_err)})"
    assert row_verdict({**row, "reference_kind": "propagated", "paper_err": None}).startswith("undetermined")


def test_a_printed_number_stands_for_half_a_unit_of_its_last_digit():
    assert row_verdict({"ours": 16.2, "err": 0.3, "paper": 17.0}) == f"agrees (z = {_z(16.2, 0.3, 17.0, 0.5)})"
    assert reference_kind({"ours": 0.1, "err": 0.01, "paper": 0}) == "exact"


def test_not_the_same_quantity_has_no_verdict_but_says_why():
    row = {"ours": 0.2, "err": 0.01, "paper": 0.003, "reference_kind": "other", "why": "another initial ensemble"}
    assert row_verdict(row) == "not the same quantity: another initial ensemble"
    assert verdict_class(row_verdict(row)) == "meh"
    with pytest.raises(ValueError, match="reference_kind 'guess'"):
        row_verdict({**row, "reference_kind": "guess"})
    assert set(REFERENCE_KINDS) == {"printed", "propagated", "exact", "other"}


def test_a_claim_and_its_table_row_have_one_verdict():
    """The claims table and the paper-vs-ours row of one claim record give the same text."""
    rec = {
        "claim": "1",
        "quantity": "exponent β below the break (κ0 ∝ ε^β)",
        "system": "henon_heiles",
        "value": 1.46,
        "err": 0.12,
        "reference": 2.0,
        "verdict": "not quadratic (z = −4.5)",
    }
    row = {"quantity": f"[1] {rec['quantity']} — henon_heiles", "ours": 1.46, "err": 0.12, "paper": 2.0}
    row["verdict"] = rec["verdict"]
    assert claim_verdict(rec) == row_verdict(row) == "not quadratic (z = −4.5)"
    # a claim against the paper's printed number is judged as printed (half a unit of 0.91)
    mu = {**rec, "quantity": "μ measured", "value": 0.94, "err": 0.005, "reference": 0.91}
    mu["verdict"] = "differs from the paper's 0.91 (z = +6.0)"
    assert claim_verdict(mu) == f"differs (z = {_z(0.94, 0.005, 0.91, 0.005)})"


@pytest.mark.parametrize(
    ("text", "cls"),
    [
        ("not quadratic (z = −4.5)", "bad"),
        ("quadratic onset (b = 0) (z = +1.2)", "ok"),
        ("agrees (z = −1.0)", "ok"),
        ("differs in our convention only; agrees under the authors' (x)", "meh"),
        ("undetermined: no uncertainty of ours", "meh"),
        ("differs", "bad"),
    ],
)
def test_verdict_class_reads_z_not_words(text, cls):
    assert verdict_class(text) == cls


def test_a_study_row_records_its_reference_kind_and_the_rules_verdict():
    """Study.compare with ``reference=``: the row carries the kind (and the propagated 1σ) and the rule's verdict;
    a kind it does not know, or a propagated reference without its error, is refused naming the argument."""
    from pathlib import Path

    from hhscatter.errors import StudyError
    from hhscatter.studies.study import load_study

    study = load_study("fig3", "quick", root=Path(__file__).resolve().parents[2] / "studies")
    row = study.compare("β", 1.46, 0.12, 2.0, reference="exact")
    assert row["reference_kind"] == "exact" and row["verdict"] == "differs (z = −4.5)"
    row = study.compare("τ2", 64.0, 0.3, 64.6, reference="propagated", paper_err=0.36)
    assert row["paper_err"] == 0.36 and row["verdict"] == f"agrees (z = {_z(64.0, 0.3, 64.6, 0.36)})"
    with pytest.raises(StudyError, match="reference must be one of"):
        study.compare("x", 1.0, 0.1, 1.0, reference="guess")
    with pytest.raises(StudyError, match="paper_err"):
        study.compare("x", 1.0, 0.1, 1.0, reference="propagated")


def test_a_count_of_zero_is_judged_by_its_one_sided_bound_not_a_z_score():
    """No return among n orbits against the reference 0: the fraction has no σ, so no z; the bound
    1 − 0.05^(1/n) (exact one-sided 95 %, computed here) contains 0: "consistent (bound)"."""
    from hhscatter.reproduction.verdicts import row_bound

    n = 60000
    row = {"quantity": "fraction returning", "ours": 0.0, "err": None, "paper": 0.0, "n": n}
    assert row_bound(row) == {"upper": pytest.approx(1 - 0.05 ** (1 / n), rel=1e-4), "cl": 0.95}
    assert row_verdict(row) == "consistent (bound)"
    assert verdict_class(row_verdict(row)) == "ok"
    # a reference outside the bound: 10 orbits, none returns, against a reference fraction 0.5 > 1 − 0.05^(1/10)
    assert row_verdict({**row, "n": 10, "paper": 0.5, "reference_kind": "exact"}) == "differs (outside the bound)"
    # a count of all: the lower bound 0.05^(1/n) against a limit 1
    assert row_verdict({**row, "ours": 1.0, "paper": 1.0}) == "consistent (bound)"
    # a bound the row records itself
    assert row_bound({"ours": 0.0, "ours_upper": 3e-4, "ours_cl": 0.9}) == {"upper": 3e-4, "cl": 0.9}
    # a count between 0 and n keeps its σ and its z
    assert row_verdict({**row, "ours": 0.5, "err": 0.1, "paper": 0.4, "reference_kind": "exact"}) == "agrees (z = +1.0)"
