"""Verdicts of our numbers against the paper's: pure functions of numbers (no I/O).

* :func:`quoted_verdict` — 2σ, then the paper's printed precision (it gives no errors);
* :func:`half_unit` — half a unit of the last digit of a printed number;
* :func:`verdict_beside_authors` — the project's rule that "differs" is kept for a difference that
  survives the authors' convention.
"""
from __future__ import annotations

from decimal import Decimal


def half_unit(printed: float) -> float:
    """half_unit(printed) -> half a unit of its last printed decimal: 0.005 for 0.27 or 13.63, 0.5 for 100."""
    exp = Decimal(repr(float(printed))).normalize().as_tuple().exponent
    return 0.5 * 10.0 ** min(int(exp), 0)


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
