"""Verdicts of our numbers against the paper's: the rule every table and page applies, the kinds of reference,
the smoke scale that states none. Pure functions of numbers (no I/O).

* :data:`RULE` and :func:`row_verdict` — **the one rule** (:func:`hhscatter.analysis.stats.verdicts.verdict`:
  "agrees" when |ours − reference| ≤ 2σ with σ = √(σ_ours² + σ_ref²)) applied to a paper-vs-ours row, saying
  why when it cannot (never a "not a number"), and no verdict at the tiny scale (:data:`SMOKE_SCALES`,
  :data:`NO_VERDICT`, :func:`without_verdicts`);
* :data:`REFERENCE_KINDS`, :func:`reference_kind`, :func:`reference_err` — the reference's own uncertainty kind
  (printed, propagated, exact, or not the same quantity);
* :func:`row_bound` — the one-sided bound of a row whose number is a fraction counted at 0 or at all (its
  verdict: :data:`BOUND_INSIDE` when the reference lies inside the bound);
* :func:`claim_verdict` — a claim record's verdict, by :func:`row_verdict`;
* :func:`quoted_verdict` — 2σ, then the paper's printed precision (it gives no errors);
* :func:`verdict_beside_authors` — the project's rule that "differs" is kept for a difference that
  survives the authors' convention;
* :func:`comparison_row` — one row of a study's paper comparison, as the reproduction functions return them.
"""

from __future__ import annotations

import math
import re

from hhscatter.analysis.stats.intervals import fraction_with_bound
from hhscatter.analysis.stats.verdicts import half_unit, verdict


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


#: the kinds of reference a number of ours is compared with, each with the uncertainty it carries
REFERENCE_KINDS = {
    "printed": "a number the paper prints without an error: half a unit of its last printed digit "
    "('≈ 17' stands for [16.5, 17.5))",
    "propagated": "a number derived from printed ones (a τ2 computed from the paper's μ carries μ's uncertainty) "
    "or another measurement of ours: its own 1σ",
    "exact": "a value of theory (an exponent 2, a limit 1, a predicted shift 0): no uncertainty",
    "other": "not the same quantity: shown side by side, no verdict, with why",
}

#: the verdict rule, stated once (the docs' studies index and the report print this text)
RULE = (
    "**agrees** when |ours − reference| ≤ 2σ, σ = √(σ_ours² + σ_ref²): both uncertainties, ours (1σ, "
    "resampled over orbits) and the reference's own kind: **printed** by the paper (half a unit of its last "
    "printed digit, so '≈ 17' stands for [16.5, 17.5)), **propagated** (derived from printed numbers, or "
    "another measurement: its 1σ), **exact** (theory: an exponent 2, a limit 1, a predicted shift 0); "
    "**differs** otherwise; z = (ours − reference)/σ. A reference that is **not the same quantity** is shown "
    "side by side with why, and no verdict. A cell without a number or without our uncertainty says so "
    "instead of a verdict; the tiny scale (a smoke test of a few hundred orbits) gives no verdicts. A fraction "
    "counted at 0 (or at all) has no σ but its one-sided 95 % bound: **consistent (bound)** when the reference "
    "lies inside the bound, **differs (outside the bound)** otherwise, no z."
)
#: the verdict of a bound (a fraction counted at 0 or at all) whose reference lies inside it
BOUND_INSIDE = "consistent (bound)"
#: the verdict of a bound whose reference lies outside it
BOUND_OUTSIDE = "differs (outside the bound)"
#: scales whose outputs are smoke tests: their rows carry no verdict
SMOKE_SCALES = ("tiny",)
#: what a smoke-scale output states in place of a verdict
NO_VERDICT = "no verdict (tiny scale: a smoke test)"


_CLAIM = re.compile(r"^\[\w+\] ")


def reference_kind(row: dict) -> str:
    """reference_kind(paper-vs-ours row) -> the kind of its reference, one of :data:`REFERENCE_KINDS` (or
    "recorded").

    The row's ``reference_kind`` when it states one; else, for rows written before rows stated it:
    "propagated" when it records ``paper_err``; "recorded" for a claim record (quantity "[n] …"), whose verdict
    the claims library made by this rule against the reference it names (theory exact, another measurement
    with its 1σ) unless that verdict names the paper's printed number ("printed"); "exact" for a reference 0
    or 1 (a predicted shift, a limit); else "printed".

    Examples
    --------
    >>> reference_kind({"ours": 1.46, "err": 0.12, "paper": 2.0, "reference_kind": "exact"})
    'exact'
    >>> reference_kind({"ours": 0.2705, "err": 0.001, "paper": 0.27}), reference_kind({"ours": 0.1, "paper": 0})
    ('printed', 'exact')
    """
    kind = row.get("reference_kind")
    if kind:
        if kind not in REFERENCE_KINDS:
            raise ValueError(f"reference_kind {kind!r}: expected one of {', '.join(REFERENCE_KINDS)}")
        return kind
    if _finite(row.get("paper_err")):
        return "propagated"
    if _CLAIM.match(str(row.get("quantity", ""))) and row.get("verdict"):
        return "printed" if "the paper's" in str(row["verdict"]) else "recorded"
    paper = row.get("paper")
    if _finite(paper) and paper in (0, 1):
        return "exact"
    return "printed"


def reference_err(row: dict, kind: str | None = None) -> float | None:
    """reference_err(row, kind=None) -> the 1σ of the row's reference by its kind: half a unit of the last printed
    digit (printed), ``paper_err`` (propagated; None when not recorded), 0 (exact).

    Examples
    --------
    >>> reference_err({"paper": 17.0}), reference_err({"paper": 2.0, "reference_kind": "exact"})
    (0.5, 0.0)
    """
    kind = kind or reference_kind(row)
    paper = row.get("paper")
    if kind == "printed":
        return half_unit(paper) if _finite(paper) else None
    if kind == "propagated":
        e = row.get("paper_err")
        return float(e) if _finite(e) else None
    return 0.0


def row_bound(row: dict) -> dict | None:
    """row_bound(paper-vs-ours row) -> {"upper" or "lower": bound, "cl": level} of a row whose ``ours`` is a
    fraction counted at 0 (or at all), else None.

    The bound is the row's own (``ours_upper`` / ``ours_lower`` with ``ours_cl``, as
    :meth:`~hhscatter.analysis.stats.intervals.BoundedFraction.record` writes them), else derived from its
    number of trials ``n`` by :func:`~hhscatter.analysis.stats.intervals.fraction_with_bound` (one-sided,
    95 %): a count of 0 is never "0 ± σ".

    Examples
    --------
    >>> row_bound({"ours": 0.0, "paper": 0.0, "n": 60000})  # 1 − 0.05^(1/60000)
    {'upper': 4.9928e-05, 'cl': 0.95}
    >>> row_bound({"ours": 0.0, "ours_upper": 3e-4, "ours_cl": 0.95}), row_bound({"ours": 0.2, "n": 10})
    ({'upper': 0.0003, 'cl': 0.95}, None)
    """
    ours = row.get("ours")
    if not _finite(ours):
        return None
    found = {k: float(row[f"ours_{k}"]) for k in ("upper", "lower") if _finite(row.get(f"ours_{k}"))}
    if len(found) == 1:
        return {**found, "cl": float(row.get("ours_cl") or 0.95)}
    n = row.get("n")
    if ours not in (0, 1) or not isinstance(n, int) or isinstance(n, bool) or n <= 0:
        return None
    b = fraction_with_bound(round(ours * n), n)
    key, bound = ("upper", b.upper) if b.upper is not None else ("lower", b.lower)
    return {key: float(f"{bound:.5g}"), "cl": b.cl}


def row_verdict(row: dict, scale: str | None = None) -> str:
    """row_verdict(paper-vs-ours row, scale) -> the text of its verdict cell by :data:`RULE`: **the one function**
    every table, claim, report row and sentence takes its verdict from.

    A row with numbers (``ours``, ``err``, ``paper``) is judged against its
    reference with the uncertainty of the reference's kind
    (:func:`reference_kind`: printed, propagated, exact); a reference of
    another quantity ("other") is side by side, no verdict, with the row's
    ``why``; a claim record keeps the verdict the claims library made by this
    rule ("recorded"); a qualitative row (text, or no reference) keeps the
    verdict its study wrote, or "—"; at a smoke scale (tiny) no verdict.
    A "differs" that the study qualified (e.g. "differs in our convention
    only; agrees under the authors' …") keeps its qualification. A fraction
    counted at 0 or at all (:func:`row_bound`) has no σ and no z: the
    reference inside its one-sided bound is :data:`BOUND_INSIDE`, outside
    it :data:`BOUND_OUTSIDE`.

    Examples
    --------
    >>> row_verdict({"ours": 0.2705, "err": 0.001, "paper": 0.27})
    'agrees (z = +0.1)'
    >>> row_verdict({"ours": 1.46, "err": 0.12, "paper": 2.0, "reference_kind": "exact"})
    'differs (z = −4.5)'
    >>> row_verdict({"ours": 1.46, "err": 0.12, "paper": 2.0, "reference_kind": "other", "why": "another window"})
    'not the same quantity: another window'
    >>> row_verdict({"ours": 0.2705, "err": 0.001, "paper": 0.27}, "tiny")
    'no verdict (tiny scale: a smoke test)'
    >>> row_verdict({"ours": 0.0, "err": None, "paper": 0.0, "n": 60000})
    'consistent (bound)'
    """
    if scale in SMOKE_SCALES:
        return NO_VERDICT
    ours, paper = row.get("ours"), row.get("paper")
    stored = str(row.get("verdict") or "")
    numeric = (
        isinstance(ours, (int, float))
        and not isinstance(ours, bool)
        and isinstance(paper, (int, float))
        and not isinstance(paper, bool)
    )
    if not numeric:
        if isinstance(ours, float) and not math.isfinite(ours):
            return "undetermined: no value of ours (not measurable here)"
        return stored or "—"
    kind = reference_kind(row)
    if kind == "other":
        return f"not the same quantity: {row.get('why') or 'see the note'}"
    if kind == "recorded":
        return stored
    ref_err = reference_err(row, kind)
    if ref_err is None:
        return "undetermined: the reference's propagated uncertainty is not recorded"
    bound = row_bound(row)
    if bound is not None:
        # the reference (widened by its own 1σ) reaches inside the one-sided bound
        inside = paper - ref_err <= bound["upper"] if "upper" in bound else paper + ref_err >= bound["lower"]
        return BOUND_INSIDE if inside else BOUND_OUTSIDE
    v = verdict(ours, row.get("err"), paper, ref_err)
    if v.word == "differs" and stored.startswith("differs") and ";" in stored:
        return f"{v.text()}; {stored.split(';', 1)[1].strip()}"
    return v.text()


def claim_verdict(rec: dict, scale: str | None = None) -> str:
    """claim_verdict(claim record, scale) -> its verdict by :func:`row_verdict`, as the record's row of the
    paper-vs-ours table ('[claim] quantity — system') gets it: one number, one verdict.

    Examples
    --------
    >>> from hhscatter.analysis.stats import Measured
    >>> claim_verdict({"claim": "1", "quantity": "κ0", "system": "hh", **Measured(0.2, 0.01).to_dict(), "reference": 0.27,
    ...                "verdict": "differs from the paper's 0.27 (z = −7.0)"})
    'differs (z = −6.3)'
    """
    row = {
        "quantity": f"[{rec.get('claim')}] {rec.get('quantity')} — {rec.get('system')}",
        "ours": rec.get("value"),
        "err": rec.get("err"),
        "paper": rec.get("reference"),
        "verdict": rec.get("verdict"),
        **{k: rec[k] for k in ("reference_kind", "paper_err", "why") if k in rec},
    }
    return row_verdict(row, scale)


def without_verdicts(doc, scale: str | None):
    """without_verdicts(doc, scale) -> ``doc`` with every ``"verdict"`` value stated as :data:`NO_VERDICT` at a
    smoke scale (:data:`SMOKE_SCALES`); ``doc`` itself (unchanged) at any other scale.

    The values, errors and references stay: a smoke test shows that the pipeline runs and what it
    measured, not whether a few hundred orbits agree with the paper.

    Examples
    --------
    >>> without_verdicts({"rows": [{"ours": 1.0, "verdict": "agrees (z = +0.3)"}]}, "tiny")
    {'rows': [{'ours': 1.0, 'verdict': 'no verdict (tiny scale: a smoke test)'}]}
    >>> without_verdicts({"verdict": "differs"}, "quick")
    {'verdict': 'differs'}
    """
    if scale not in SMOKE_SCALES:
        return doc

    def strip(o):
        if isinstance(o, dict):
            return {k: NO_VERDICT if k == "verdict" else strip(v) for k, v in o.items()}
        if isinstance(o, list):
            return [strip(v) for v in o]
        return o

    return strip(doc)


def quoted_verdict(value: float, err: float, paper: float, half_unit: float) -> str:
    """quoted_verdict(value, err, paper, half_unit) -> verdict of our number against the paper's printed one.

    ``err`` is our 1σ error (e.g. a bootstrap over orbits of μ of Eq.
    (eqn:energy_exp_decay)); ``half_unit`` is half a unit of the last
    digit the paper prints (0.005 for its "0.91", which stands for any μ in
    [0.905, 0.915)).  Returns "agrees within 2σ" if |μ − paper| ≤ 2 err,
    else "agrees to the paper's quoted digits" if |μ − paper| ≤ 2 err +
    half_unit (our error can be far below the paper's rounding: a 2σ test alone
    would fail a number that prints as the paper's), else "differs".
    """
    d = abs(float(value) - float(paper))
    if d <= 2 * float(err):
        return "agrees within 2σ"
    if d <= 2 * float(err) + float(half_unit):
        return "agrees to the paper's quoted digits"
    return "differs"


def verdict_beside_authors(verdict: str, authors_rows) -> str:
    """verdict_beside_authors(verdict, authors_rows) -> our row's verdict, knowing the authors'-convention rows.

    The project's rule: "differs" is kept for a difference that survives
    the authors' convention.  If ``verdict`` is "differs" and one of
    ``authors_rows`` (dicts with ``verdict`` and ``label``) agrees, the
    verdict says that the difference is in our convention only and names
    the rows under which it agrees; otherwise it is returned unchanged.
    """
    if verdict != "differs":
        return verdict
    agree = [r["label"] for r in authors_rows if str(r.get("verdict", "")).startswith("agrees")]
    if not agree:
        return verdict
    return f"differs in our convention only; agrees under the authors' ({'; '.join(agree)})"


def comparison_row(quantity: str, ours, err=None, paper=None, **fields) -> dict:
    """One row of a study's paper comparison: the keyword arguments of ``Study.compare``.

    ``quantity`` names what is compared, ``ours`` is our number (or text) with its 1σ ``err``, ``paper`` the
    paper's number (or statement); ``fields`` the rest (``verdict``, ``note``, ``unit``, ``convention``,
    ``authors``). Analysis functions return such rows; the study records them in order.

    Examples
    --------
    >>> comparison_row("τ0", 5.2, 0.3, None, unit="time")
    {'quantity': 'τ0', 'ours': 5.2, 'err': 0.3, 'paper': None, 'unit': 'time'}
    """
    return {"quantity": quantity, "ours": ours, "err": err, "paper": paper, **fields}
