"""What a scene records besides each orbit's lifetime: the crossings of the section ṙ = 0, φ̇ > 0
(:class:`SectionWindow`), the energies at snapshot times (:class:`SnapshotGrid`, or a tuple of times) and the
crossings of circles by orbits followed past their escape (:class:`Follow`), each validated on construction
(a :class:`~hhscatter.errors.ConfigError` naming the key). Times in time units, energies in the potential's units,
radii in length units.

Examples
--------
>>> SnapshotGrid(0, 10, 2.5)
(0.0, 2.5, 5.0, 7.5, 10.0)
>>> Follow([1.0, 1.5]).radii
(1.0, 1.5)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hhscatter.errors import ConfigError

__all__ = [
    "SNAPSHOTS_MAX",
    "SNAPSHOT_LIST_MAX",
    "Follow",
    "SectionWindow",
    "SnapshotGrid",
    "finite_number",
    "plus_zero",
]

#: at most SNAPSHOTS_MAX snapshot times: every live orbit writes one row per time (24 B), a chunk's
#: snapshot rows are held in memory until written
SNAPSHOTS_MAX = 100_000
#: a start/stop/step snapshot grid longer than this is stored (scene.json, part metadata, hash) as its
#: definition, not as every time (shorter grids are stored as their times, as before: same hashes)
SNAPSHOT_LIST_MAX = 1000


class SnapshotGrid(tuple):
    """SnapshotGrid(start, stop, step) -> the times start, start + step, … ≤ stop (both ends included).

    A tuple of the times (what the engine uses) that remembers its definition, so that a long grid is
    stored as ``{"start", "stop", "step"}`` (see :data:`SNAPSHOT_LIST_MAX`). The count is checked against
    :data:`SNAPSHOTS_MAX` before any time is made. Example: ``SnapshotGrid(0, 10, 2.5)`` is
    (0.0, 2.5, 5.0, 7.5, 10.0).
    """

    def __new__(cls, start, stop, step):
        start, stop, step = (
            finite_number(f"snapshots.{k}", v) for k, v in (("start", start), ("stop", stop), ("step", step))
        )
        if not step > 0:
            raise ConfigError(f"snapshots.step must be > 0, got {step}")
        span = (stop - start) / step  # inf when the span overflows (0:1e300:1e-300)
        count = math.floor(span + 0.5) + 1 if span < 1e15 else math.inf
        if count > SNAPSHOTS_MAX:
            shown = count if count < math.inf else f"{span + 1:.3g}"
            raise ConfigError(
                f"snapshots: {start:g}:{stop:g}:{step:g} gives {shown} times, more than "
                f"{SNAPSHOTS_MAX} (every live orbit writes one row per time; a chunk holds them "
                "in memory): use a larger step"
            )
        self = super().__new__(cls, (float(t) for t in np.arange(start, stop + 0.5 * step, step)))
        self.definition = {"start": start, "stop": stop, "step": step}
        return self

    def __reduce__(self):
        d = self.definition
        return (SnapshotGrid, (d["start"], d["stop"], d["step"]))


def plus_zero(v):
    """v with a float −0.0 written as 0.0 (−0 is the same value: it must not make another scene or read "γ=-0")."""
    return 0.0 if isinstance(v, float) and v == 0.0 else v


def finite_number(name, value):
    """``value`` as a float, refused by ``name`` unless it is a finite number (never text or a boolean)."""
    # a number, never text or a boolean ("0.3" would pass float() and fail deep inside the engine)
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise ConfigError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(v):
        raise ConfigError(f"{name} must be finite, got {value!r}")
    return v


@dataclass(frozen=True)
class SectionWindow:
    """Which crossings of the section ṙ = 0, φ̇ > 0 a scene records (paper, App. "Initial Conditions").

    Those at orbit times t_from ≤ t ≤ t_to whose energy lies in [e_min, e_max]; with ``first_only`` only the
    first such crossing of each orbit. The initial point itself (t = 0) is never recorded.

    Parameters
    ----------
    t_from, t_to : float
        Orbit-time window (time units), 0 ≤ t_from < t_to ≤ ∞.
    e_min, e_max : float
        Energy window of the crossing (units of the potential); with drag, a band around a target energy.
    first_only : bool
        Only the first crossing in the window, per orbit.
    stop : bool
        With ``first_only``: end the orbit at that crossing (one-return runs, e.g. Ulam's method).

    Raises
    ------
    ConfigError
        A value that is not a number, or an empty window.

    Examples
    --------
    The first crossing after t* = 17 (paper Fig. 5a), and the first crossing in an energy band (Fig. 5b):

    >>> import hhscatter
    >>> a = hhscatter.SectionWindow(t_from=17.0, first_only=True)
    >>> b = hhscatter.SectionWindow(e_min=0.295, e_max=0.305, first_only=True)
    >>> a.t_to, b.e_max
    (inf, 0.305)
    """

    t_from: float = 0.0
    t_to: float = math.inf
    e_min: float = -math.inf
    e_max: float = math.inf
    first_only: bool = False
    stop: bool = False

    def __post_init__(self):
        for name in ("t_from", "t_to", "e_min", "e_max"):
            object.__setattr__(self, name, plus_zero(getattr(self, name)))
        for name in ("first_only", "stop"):
            if not isinstance(getattr(self, name), bool):
                raise ConfigError(f"sections.{name} must be true or false, got {getattr(self, name)!r}")
        for name in ("t_from", "t_to", "e_min", "e_max"):
            v = getattr(self, name)
            if not isinstance(v, (int, float)) or math.isnan(v):
                raise ConfigError(f"sections.{name} must be a number, got {v!r}")
        if self.t_from < 0 or math.isinf(self.t_from):
            raise ConfigError(f"sections.t_from must be finite and ≥ 0, got {self.t_from}")
        if not self.t_to > self.t_from:
            raise ConfigError(f"sections.t_to must be > t_from = {self.t_from}, got {self.t_to}")
        if not self.e_max > self.e_min:
            raise ConfigError(f"sections.e_max must be > e_min = {self.e_min}, got {self.e_max}")
        if self.stop and not (self.first_only or math.isfinite(self.t_to)):
            raise ConfigError(
                "sections.stop needs first_only = true or a finite t_to "
                "(otherwise the window never closes and the orbit is always needed)"
            )


@dataclass(frozen=True)
class Follow:
    """Follow(radii) -> keep integrating escaped orbits (conservative scenes).

    After its escape (the outward r_esc crossing, which stays the orbit's
    t_end) the orbit is followed until it reaches r_far or t_max, and every
    crossing of a circle r = R for R in ``radii`` and of r_esc (both directions,
    from t = 0) goes to the ``crossings`` table: the check that an 'escaped' orbit does
    not come back (study ``resc``).
    """

    radii: tuple = ()

    def __post_init__(self):
        try:
            radii = tuple(float(r) for r in self.radii)
        except (TypeError, ValueError):
            raise ConfigError(f"follow.radii must be a list of numbers, got {self.radii!r}") from None
        if not radii or not all(math.isfinite(r) and r > 0 for r in radii):
            raise ConfigError(f"follow.radii must be a non-empty list of finite radii > 0, got {self.radii!r}")
        if any(b <= a for a, b in zip(radii, radii[1:])):
            raise ConfigError("follow.radii must be strictly increasing")
        object.__setattr__(self, "radii", radii)
