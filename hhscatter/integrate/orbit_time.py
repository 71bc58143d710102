"""Orbit time on a stream lane: the double nearest (lane time) − (orbit start), both double-length.

A stream lane's clock runs on across the orbits it carries; an orbit's time is the difference of two
double-length times (hi, lo). TwoSum keeps it exact to ~2⁻¹⁰⁶ of the lane time, and a near-tie rounds to even,
so orbit times do not depend on how orbits share lanes (:mod:`hhscatter.integrate.stream`).
"""

from __future__ import annotations

import math

import numpy as np

_ulp = math.ulp
TIE_BAND = 2.0**-30  # an orbit time this close (in gaps) to a tie of its rounding is a tie (>> the 2^-106 residue)


def _tie_to_even(r: float, rem: float) -> float:
    """The orbit time r + rem (r the double nearest it, rem the exact remainder) rounded half to even when
    it lies within TIE_BAND gaps of the midpoint between r and its neighbour on rem's side; r otherwise.

    The remainder of an orbit time carries ~2⁻¹⁰⁶ of the lane time of error that depends on the lane's
    start, which decides a tie's rounding; rounding near-ties to even makes it the same in every lane.
    Called only when :func:`_orbit_time`'s screen finds ``rem`` near a half or quarter ulp (the gap below
    a power of two is half the ulp).

    >>> r = 1.0 + 2.0 ** -52                      # odd mantissa; its upper neighbour is even
    >>> _tie_to_even(r, 2.0 ** -53 - 2.0 ** -140) == r + 2.0 ** -52
    True
    >>> _tie_to_even(r, 2.0 ** -55) == r          # not a tie: r is the nearest
    True
    """
    n = math.nextafter(r, math.inf if rem > 0 else -math.inf)
    gap = abs(n - r)
    if abs(abs(rem) - 0.5 * gap) > gap * TIE_BAND:
        return r
    m = math.frexp(r)[0]
    return r if int(m * 9007199254740992.0) % 2 == 0 else n  # the even mantissa of the two


def _orbit_time(a: float, el: float, a0: float, el0: float) -> float:
    """The orbit time (a + el) − (a0 + el0) of double-length lane times (hi, lo), as the double nearest it:
    TwoSum of the high parts, the low parts added, near-ties rounded to even (:func:`_tie_to_even`; the
    screen costs one ``math.ulp`` per call: every orbit end passes here)."""
    b = -a0
    s = a + b
    bb = s - a
    c = ((a - (s - bb)) + (b - bb)) + (el - el0)
    r = s + c
    rem = c - (r - s)
    if rem:
        u, h = _ulp(r), abs(rem)
        if abs(h - 0.5 * u) <= u * TIE_BAND or abs(h - 0.25 * u) <= u * TIE_BAND:  # (the gap below 2^k is u/2)
            return _tie_to_even(r, rem)
    return r


def _orbit_times(a, el, a0, el0) -> np.ndarray:
    """:func:`_orbit_time` of arrays, element by element, in numpy: the same operations in the same order (IEEE
    double, no fused operations), so every element is bit for bit the scalar function's; the rare near-ties
    go through :func:`_tie_to_even` one by one.

    >>> a, el = np.array([3.5, 1.0 + 2.0**-52]), np.array([2.0**-60, 0.0])
    >>> a0, el0 = np.array([1.25, 0.0]), np.array([0.0, 0.0])
    >>> [float(t) for t in _orbit_times(a, el, a0, el0)] == [_orbit_time(*v) for v in zip(a, el, a0, el0)]
    True
    """
    b = -a0
    s = a + b
    bb = s - a
    c = ((a - (s - bb)) + (b - bb)) + (el - el0)
    r = s + c
    rem = c - (r - s)
    u, h = np.spacing(np.abs(r)), np.abs(rem)
    near = (rem != 0) & ((np.abs(h - 0.5 * u) <= u * TIE_BAND) | (np.abs(h - 0.25 * u) <= u * TIE_BAND))
    for i in np.flatnonzero(near):
        r[i] = _tie_to_even(float(r[i]), float(rem[i]))
    return r


__all__ = ["TIE_BAND"]
