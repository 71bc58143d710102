"""A measured value: its value, its 1σ uncertainty, the method that made it and the number of independent units.

:class:`Measured` is what an estimator returns for a number with an error, and the one way such a number is
written: ``.to_dict()`` gives ``{"value": v, "err": e}``, the shape of every numbers JSON, and
:meth:`Measured.from_dict` reads it back. First-order (linear) error propagation for independent inputs:
:meth:`~Measured.ratio`, :meth:`~Measured.product`, :meth:`~Measured.difference`, :meth:`~Measured.sum`,
:meth:`~Measured.log`, :meth:`~Measured.scaled` and :meth:`~Measured.over`; the operators ``/ * - +`` are the same
operations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

__all__ = ["Measured", "WithErrors"]


def _as_measured(x) -> Measured:
    return x if isinstance(x, Measured) else Measured(x, 0.0, "exact")


@dataclass(frozen=True)
class Measured:
    """Measured(value, err=NaN, method="", n=None): a value with its 1σ uncertainty (same unit as the value).

    Parameters
    ----------
    value : float
        The estimate (any unit; the error has the same unit).
    err : float
        Its 1σ standard error (NaN: not known, ``None`` in JSON).
    method : str
        What made it (e.g. "MLE", "bootstrap", "ratio"); not written by :meth:`to_dict`.
    n : int or None
        The number of independent units behind it (orbits, runs), when it has one; not written either.

    Examples
    --------
    >>> k = Measured(0.25, 0.01, "MLE", 1000)
    >>> k.to_dict()
    {'value': 0.25, 'err': 0.01}
    >>> Measured.from_dict({"value": 0.25, "err": 0.01}) == Measured(0.25, 0.01)
    True
    >>> round(k.rel_err, 3), k.n
    (0.04, 1000)
    """

    value: float
    err: float = math.nan
    method: str = ""
    n: int | None = None

    def to_dict(self) -> dict:
        """``{"value": v, "err": e}``: the numbers JSON's shape of a value with its error (method and n left out).

        Examples
        --------
        >>> Measured(1.5, 0.2, "fit").to_dict()
        {'value': 1.5, 'err': 0.2}
        """
        return {"value": self.value, "err": self.err}

    @classmethod
    def from_dict(cls, d, method: str = "", n: int | None = None) -> Measured:
        """The :class:`Measured` of a numbers-JSON leaf ``{"value": v, "err": e}`` (a missing or null err is NaN).

        Examples
        --------
        >>> Measured.from_dict({"value": 3.0, "err": None})
        Measured(value=3.0, err=nan, method='', n=None)
        """
        err = d.get("err")
        return cls(d["value"], math.nan if err is None else err, method, n)

    @classmethod
    def of(cls, value, err, method: str = "", n: int | None = None) -> Measured:
        """Measured with value and err as Python floats (``None``: NaN, not measured), e.g. from numpy scalars.

        Examples
        --------
        >>> import numpy as np
        >>> Measured.of(np.float64(2.0), None)
        Measured(value=2.0, err=nan, method='', n=None)
        """
        return cls(math.nan if value is None else float(value), math.nan if err is None else float(err), method, n)

    @property
    def rel_err(self) -> float:
        """err / |value| (NaN for a zero value).

        Examples
        --------
        >>> Measured(-4.0, 0.2).rel_err
        0.05
        """
        return self.err / abs(self.value) if self.value else math.nan

    def ratio(self, other) -> Measured:
        """self / other: σ = |a/b| √((σa/a)² + (σb/b)²) (σa/|b| when a = 0); ``other`` may be an exact number.

        Examples
        --------
        >>> r = Measured(6.0, 0.3).ratio(Measured(2.0, 0.1))
        >>> r.value, round(r.err, 12) == round(3.0 * math.sqrt(0.05**2 + 0.05**2), 12)
        (3.0, True)
        >>> Measured(0.0, 0.3).ratio(2.0).err
        0.15
        """
        o = _as_measured(other)
        r = self.value / o.value
        if self.value == 0:
            err = abs(self.err / o.value)
        else:
            err = abs(r) * math.hypot(self.err / self.value, o.err / o.value)
        return Measured(r, err, "ratio")

    def product(self, other) -> Measured:
        """self · other: σ = |ab| √((σa/a)² + (σb/b)²) (√((σa b)² + (a σb)²) when a factor is 0).

        Examples
        --------
        >>> p = Measured(3.0, 0.3).product(Measured(2.0, 0.4))
        >>> p.value, round(p.err, 12) == round(6.0 * math.sqrt(0.1**2 + 0.2**2), 12)
        (6.0, True)
        """
        o = _as_measured(other)
        p = self.value * o.value
        if self.value == 0 or o.value == 0:
            err = math.hypot(self.err * o.value, self.value * o.err)
        else:
            err = abs(p) * math.hypot(self.err / self.value, o.err / o.value)
        return Measured(p, err, "product")

    def difference(self, other) -> Measured:
        """self − other: σ = √(σa² + σb²).

        Examples
        --------
        >>> Measured(5.0, 0.3).difference(Measured(2.0, 0.4))
        Measured(value=3.0, err=0.5, method='difference', n=None)
        """
        o = _as_measured(other)
        return Measured(self.value - o.value, math.hypot(self.err, o.err), "difference")

    def sum(self, other) -> Measured:
        """self + other: σ = √(σa² + σb²).

        Examples
        --------
        >>> Measured(5.0, 0.3).sum(Measured(2.0, 0.4))
        Measured(value=7.0, err=0.5, method='sum', n=None)
        """
        o = _as_measured(other)
        return Measured(self.value + o.value, math.hypot(self.err, o.err), "sum")

    def log(self) -> Measured:
        """ln(self) (value > 0): σ = σa / a.

        Examples
        --------
        >>> m = Measured(math.e, 0.1 * math.e).log()
        >>> m.value, round(m.err, 15)
        (1.0, 0.1)
        """
        return Measured(math.log(self.value), self.err / self.value, "log")

    def scaled(self, c: float) -> Measured:
        """c · self for an exact number c: σ = |c| σa; method and n are kept (a change of unit).

        Examples
        --------
        >>> Measured(0.5, 0.02, "MLE", 10).scaled(-2.0)
        Measured(value=-1.0, err=0.04, method='MLE', n=10)
        """
        return Measured(c * self.value, abs(c) * self.err, self.method, self.n)

    def over(self, c: float) -> Measured:
        """self / c for an exact number c (a theory's value, a unit): σ = σa/|c|; method and n are kept.

        The same as ``self / c`` to first order, with one rounding per number (the ratio's σ is |a/c| · σa/|a|).

        Examples
        --------
        >>> Measured(0.3, 0.06, "MLE", 50).over(-2.0)
        Measured(value=-0.15, err=0.03, method='MLE', n=50)
        >>> Measured(math.nan, math.nan).over(4.0)
        Measured(value=nan, err=nan, method='', n=None)
        """
        return Measured(self.value / c, self.err / abs(c), self.method, self.n)

    def z(self, ref, ref_err: float = 0.0) -> float:
        """(value − ref) / √(err² + ref_err²): how many combined σ self lies from a reference.

        Examples
        --------
        >>> Measured(1.3, 0.3).z(1.0, 0.4)
        0.6000000000000001
        """
        return (self.value - ref) / math.hypot(self.err, ref_err)

    __truediv__ = ratio
    __mul__ = product
    __sub__ = difference
    __add__ = sum


class WithErrors:
    """Mixin of an estimator's result whose estimates are fields ``x`` with their 1σ ``x_err``:
    ``result.measured("x")`` is the :class:`Measured` of ``x`` (the result's method, its number of units).

    A result class sets ``method`` (what made its estimates) and ``n_field`` (the field counting the independent
    units behind them, or None).

    Examples
    --------
    >>> @dataclass(frozen=True)
    ... class Rate(WithErrors):
    ...     method: ClassVar[str] = "MLE"
    ...     n_field: ClassVar[str] = "n_events"
    ...     kappa: float
    ...     kappa_err: float
    ...     n_events: int
    >>> Rate(0.2, 0.01, 400).measured("kappa")
    Measured(value=0.2, err=0.01, method='MLE', n=400)
    """

    method: ClassVar[str] = ""
    n_field: ClassVar[str | None] = None

    def measured(self, name: str) -> Measured:
        """The :class:`Measured` of the estimate ``name`` (a field with a ``<name>_err`` field beside it)."""
        if not hasattr(self, f"{name}_err"):
            raise AttributeError(f"{type(self).__name__} has no estimate {name!r} with an error {name}_err")
        n = getattr(self, self.n_field) if self.n_field else None
        return Measured(getattr(self, name), getattr(self, f"{name}_err"), self.method or type(self).__name__, n)
