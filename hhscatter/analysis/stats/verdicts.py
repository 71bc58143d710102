"""A value against a reference by the 2σ rule: pure functions of numbers (no I/O).

* :func:`verdict` — "agrees" when |value − reference| ≤ 2σ with σ = √(σ_value² + σ_ref²), both uncertainties,
  "differs" otherwise, "undetermined" (with why) without a value, a reference or an uncertainty; z = Δ/σ;
* :func:`verdict_class` — agrees, differs or neither, from a verdict's text;
* :func:`signed` — a signed number as verdicts print it ("−");
* :func:`value_err` — "value ± error" as verdicts print it: two significant digits of the error, "−";
* :func:`half_unit` — half a unit of the last digit of a printed number (the uncertainty a number printed
  without an error carries).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError


@dataclass(frozen=True)
class Verdict:
    """One verdict: ``word`` "agrees" / "differs" / "undetermined" / "no verdict", ``z`` (None when undefined)
    and ``why`` (the reason of an undetermined cell)."""

    word: str
    z: float | None = None
    why: str = ""

    def text(self) -> str:
        """The cell: "agrees (z = +1.3)", "differs (z = −4.2)", "undetermined: no uncertainty of ours"."""
        if self.z is not None:
            return f"{self.word} (z = {signed(self.z)})"
        return f"{self.word}: {self.why}" if self.why else self.word


def signed(x: float, spec: str = "+.1f") -> str:
    """signed(x, spec="+.1f") -> x formatted with ``spec`` and a minus sign "−" (U+2212), as verdicts print numbers.

    Examples
    --------
    >>> signed(-4.21), signed(1.25, "+.0f"), signed(-0.0071, "+.3f")
    ('−4.2', '+1', '−0.007')
    """
    if isinstance(x, bool) or not isinstance(x, (int, float, np.integer, np.floating)):
        raise ConfigError(f"x must be a number, got {type(x).__name__}")
    if not isinstance(spec, str):
        raise ConfigError(f"spec must be a format specification (a string), got {type(spec).__name__}")
    return format(x, spec).replace("-", "−")


def _finite(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def verdict(value, err, ref, ref_err=0.0) -> Verdict:
    """verdict(ours, its 1σ, reference, reference's 1σ) -> :class:`Verdict` by the 2σ rule: "agrees" when |value − ref| ≤ 2σ, σ = √(err² + ref_err²).

    Examples
    --------
    >>> verdict(1.435, 0.017, 1.41, 0.005).text()   # |Δ| = 0.025, σ = 0.0177: z = 1.4
    'agrees (z = +1.4)'
    >>> verdict(10.5, 0.3, 13.63, 0.005).text()
    'differs (z = −10.4)'
    >>> verdict(0.2, None, 0.3).text()
    'undetermined: no uncertainty of ours'
    """
    if not _finite(value):
        return Verdict("undetermined", why="no value of ours (not measurable here)")
    if not _finite(ref):
        return Verdict("undetermined", why="no reference value")
    if not _finite(err) or err < 0:
        return Verdict("undetermined", why="no uncertainty of ours")
    ref_err = ref_err if _finite(ref_err) and ref_err > 0 else 0.0
    sigma = math.hypot(float(err), float(ref_err))
    d = float(value) - float(ref)
    if sigma == 0:
        return Verdict("agrees" if d == 0 else "differs", None, "" if d == 0 else "exact numbers that differ")
    z = d / sigma
    return Verdict("agrees" if abs(z) <= 2 else "differs", z)


_Z = re.compile(r"\(z = ([−+-]?\d+(?:\.\d+)?)\)")


def verdict_class(text: str) -> str:
    """verdict_class(verdict text) -> "ok" (agrees), "bad" (differs) or "meh" (qualified, qualitative, not
    comparable, no verdict): a verdict with a z by |z| ≤ 2 whatever its words ("not quadratic (z = −4.5)" is
    "bad"), a difference in our convention only "meh".

    Examples
    --------
    >>> [verdict_class(v) for v in ("not quadratic (z = −4.5)", "quadratic onset (b = 0) (z = +1.2)",
    ...  "not the same quantity: another window", "differs in our convention only; agrees under the authors' (x)")]
    ['bad', 'ok', 'meh', 'meh']
    """
    if text is not None and not isinstance(text, str):
        raise ConfigError(f"text must be a verdict's text (a string), got {type(text).__name__}")
    v = str(text or "").strip()
    low = v.lower()
    if not v:
        return ""
    if low.startswith("differs in") and "only" in low:
        return "meh"
    m = _Z.search(v)
    if m:
        return "ok" if abs(float(m.group(1).replace("−", "-"))) <= 2 else "bad"
    if low.startswith(("not the same", "not applicable", "no verdict", "undetermined")):
        return "meh"
    if low.startswith(("agree", "consistent", "reproduced")):
        return "ok"
    if low.startswith(("differ", "not")):
        return "bad"
    return "meh"


def value_err(value: float, err: float, sign: str = "") -> str:
    """value_err(value, err, sign="") -> "value ± err" as verdicts print it: both to the decimal of the error's second
    significant digit (three decimals where the error is 0), the minus sign "−" (U+2212); ``sign`` "+" writes the
    value's sign always.

    Examples
    --------
    >>> value_err(-0.02, 0.005), value_err(0.035, 0.023, "+"), value_err(0.5, 0.0)
    ('−0.0200 ± 0.0050', '+0.035 ± 0.023', '0.500 ± 0.000')
    """
    v, e = check.number(value, "value"), check.number(err, "err", minimum=0.0)
    if sign not in ("", "+"):
        raise ConfigError(f"sign must be '' or '+', got {sign!r}")
    digits = max(0, 1 - math.floor(math.log10(e))) if e > 0 else 3
    return f"{v:{sign}.{digits}f} ± {e:.{digits}f}".replace("-", "−")


def half_unit(printed: float) -> float:
    """half_unit(printed) -> half a unit of its last printed decimal: 0.005 for 0.27 or 13.63, 0.5 for 100.

    >>> half_unit(13.63), half_unit(100.0)
    (0.005, 0.5)
    """
    check.number(printed, "printed")
    exp = Decimal(repr(float(printed))).normalize().as_tuple().exponent
    return 0.5 * 10.0 ** min(int(exp), 0)
