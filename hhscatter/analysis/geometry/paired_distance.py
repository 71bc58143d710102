"""Paired differences of distances between point sets on the section, resampling the independent unit (orbits):
is set B farther from a reference than set A, with an interval that accounts for the points of one orbit being
correlated and for sets that share orbits. The distances themselves are :mod:`hhscatter.analysis.geometry.distance`.

Units: positions in the section's units; Hellinger distances are dimensionless.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.geometry.distance import _cells, box_histograms, hellinger
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "PairedDifference",
    "UnitSet",
    "paired_hellinger_difference",
    "paired_hellinger_replicates",
    "percentile_interval",
]


# ---------------------------------------------------------------------------
# paired differences of distances, resampling orbits
# ---------------------------------------------------------------------------
class UnitSet(NamedTuple):
    """A point set for :func:`paired_hellinger_replicates`: its points, the independent unit of each point
    (e.g. the orbit's ``traj_id``) and its group: sets of one group share one id space (one run, e.g. 5a and
    5b, or a set and its subset) and are half-sampled together; different groups independently."""

    points: np.ndarray  # (n, 2) points (x, y)
    units: np.ndarray  # (n,) unit of each point
    group: str  # the run whose units the set shares


class PairedDifference(NamedTuple):
    """Result of :func:`paired_hellinger_difference` (Hellinger distances, dimensionless)."""

    d_a: float  # debiased, offset-averaged H(A, R): mean over half-sample replicates
    d_b: float  # the same for B
    delta: float  # d_b − d_a (mean over replicates)
    lo: float  # percentile interval of Δ over the replicates (level ``level``)
    hi: float
    d_a_interval: tuple  # percentile intervals of d_a and d_b
    d_b_interval: tuple
    offset_spread: float  # std over grid offsets of the full-sample Δ (not debiased): grid dependence
    n_boot: int


def _offset_extents(extent, box: float, k: int):
    """The k × k shifted partitions of ``extent`` by (i, j)·box/k, widened by one box so none loses a point."""
    x0, x1, y0, y1 = map(float, extent)
    return [(x0 - i * box / k, x1 + box, y0 - j * box / k, y1 + box) for i in range(k) for j in range(k)]


def _h2(P, Q, box, extents) -> np.ndarray:
    """Squared Hellinger of P, Q on each partition of ``extents``."""
    return np.array([hellinger(*box_histograms(P, Q, box, e)) ** 2 for e in extents])


def _dense_cells(X, box: float, extent):
    """(cell id of each point in [0, K), K): the box cells of ``extent`` numbered densely, K − 1 the overflow."""
    x0, x1, y0, y1 = map(float, extent)
    k = (int(np.floor((x1 - x0) / box)) + 1) * (int(np.floor((y1 - y0) / box)) + 1)
    c = _cells(X, box, extent)
    return np.where(c < 0, k, c).astype(np.intp), k + 1


def _h2_counts(cp, cq) -> float:
    """Squared Hellinger distance of two count vectors on one partition (as :func:`hellinger` ** 2)."""
    d = np.sqrt(cp / cp.sum()) - np.sqrt(cq / cq.sum())
    return min(0.5 * float(np.dot(d, d)), 1.0)


def percentile_interval(values, level: float = 0.95):
    """percentile_interval(values, level=0.95) -> (mean, lo, hi) over replicates along axis 0.

    The mean and the central percentile interval of coverage ``level`` of half-sample (or bootstrap)
    replicates, e.g. of a paired difference ``reps[:, 1] − reps[:, 0]`` of
    :func:`paired_hellinger_replicates`. Scalars for 1-D input, arrays otherwise.

    Examples
    --------
    >>> [round(v, 9) for v in percentile_interval(np.arange(101.0), 0.9)]
    [50.0, 5.0, 95.0]
    """
    check.numbers(values, "values")
    v = np.asarray(values, dtype=float)
    if v.ndim == 0:
        raise ConfigError(f"values must be an array of replicates (axis 0), got the single number {values!r}")
    if not 0 < check.number(level, "level") < 1:
        raise ConfigError(f"level must be in (0, 1), got {level!r}")
    q = (1 - level) / 2
    m, lo, hi = v.mean(axis=0), np.quantile(v, q, axis=0), np.quantile(v, 1 - q, axis=0)
    return (float(m), float(lo), float(hi)) if v.ndim == 1 else (m, lo, hi)


def paired_hellinger_replicates(
    sets,
    pairs,
    boxes,
    extent,
    *,
    offsets: int = 2,
    n_boot: int = 100,
    seed: int = 0,
) -> np.ndarray:
    """Debiased Hellinger distances of several pairs of sets, on common half-samples of every set's units.

    Each replicate draws half of the units of every group of ``sets`` (without replacement; the groups
    independently, in the order they first appear in ``sets``), and for every pair (X, R) of ``pairs`` and
    every box side ε of ``boxes`` computes the debiased squared Hellinger distance of the half-samples,
    H²_deb(X, R) = H²(X_h, R_h) − ½ H²(X_h, X_c) − ½ H²(R_h, R_c) (X_c, R_c: the complementary halves, which
    remove the finite-sample bias), averaged over ``offsets``² placements of the box grid (shifts by
    ε/offsets), and H = √max(H²_deb, 0). A set used in several pairs is the same half-sample in all of them,
    so any difference of two columns is *paired*: its spread over replicates is the sampling spread of the
    difference (for smooth statistics a half-sample's spread equals the full sample's). Use it for two sets
    against one reference (5b vs 5a against μ_c^{E1}), one set against two references (5a against μ_c^{E1} and
    μ_c^{E2}), or several runs against one reference (5a at several γ, panel (d)).

    Parameters
    ----------
    sets : mapping name -> UnitSet (or a (points, units, group) tuple)
        The point sets, each with its units and its group (the run whose id space it shares).
    pairs : sequence of (name, name)
        The (set, reference) pairs whose distances are wanted.
    boxes : sequence of float
        Box sides ε (units of x, y).
    extent : (x0, x1, y0, y1)
        The partition's anchor and span (every offset partition is widened by one box).
    offsets : int
        Grid placements per axis (1: the anchored grid only).
    n_boot : int
        Half-sample replicates (≥ 2).
    seed : int
        Seed of the replicates (deterministic).

    Returns
    -------
    ndarray, shape (n_boot, len(pairs), len(boxes))
        Debiased, offset-averaged Hellinger distance (dimensionless) per replicate, pair and box.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> R1, R2, A = rng.random((3000, 2)), rng.random((3000, 2)) ** 2, rng.random((3000, 2))
    >>> ids = np.arange(3000)
    >>> sets = {"A": UnitSet(A, ids, "run"), "R1": UnitSet(R1, ids, "r1"), "R2": UnitSet(R2, ids, "r2")}
    >>> reps = paired_hellinger_replicates(sets, [("A", "R1"), ("A", "R2")], [0.25], (0, 1, 0, 1), n_boot=20)
    >>> reps.shape
    (20, 2, 1)
    >>> d, lo, hi = percentile_interval(reps[:, 1, 0] - reps[:, 0, 0])   # A is closer to R1: Δ > 0
    >>> bool(lo > 0)
    True
    """
    sets, pairs, boxes, group_units = _checked_unit_sets(sets, pairs, boxes, offsets, n_boot)
    _checks.extent(extent)
    check.count(seed, "seed", 0)
    extents = [_offset_extents(extent, b, int(offsets)) for b in boxes]
    used = sorted({n for p in pairs for n in p}, key=list(sets).index)
    # dense cell ids of every point on every partition, computed once: a replicate only counts them
    cells = {n: [[_dense_cells(sets[n].points, b, e) for e in exts] for b, exts in zip(boxes, extents)] for n in used}
    totals = {n: [[np.bincount(c, minlength=k) for c, k in row] for row in cells[n]] for n in used}
    rng = np.random.default_rng(seed)
    out = np.empty((int(n_boot), len(pairs), len(boxes)))
    for r in range(int(n_boot)):
        halves = {g: rng.permutation(u)[: u.size // 2] for g, u in group_units.items()}
        counts = {n: _half_counts(n, sets[n], halves, cells[n], totals[n]) for n in used}
        noise = {n: [np.array([_h2_counts(h, c) for h, c in row]) for row in counts[n]] for n in used}
        for i, (x, ref) in enumerate(pairs):
            for j in range(len(boxes)):
                h2 = (
                    np.array([_h2_counts(hx, hr) for (hx, _), (hr, _) in zip(counts[x][j], counts[ref][j])])
                    - 0.5 * noise[x][j]
                    - 0.5 * noise[ref][j]
                )
                out[r, i, j] = np.sqrt(max(h2.mean(), 0.0))
    return out


def _checked_unit_sets(sets, pairs, boxes, offsets, n_boot):
    """(sets as UnitSets of (n, 2) points, pairs, box sides, {group: its units}), checked with the options."""
    if not isinstance(sets, dict) or not sets:
        raise ConfigError(f"sets must be a mapping name -> (points, units, group), got {type(sets).__name__}")
    for k, v in sets.items():
        if not isinstance(v, tuple) or len(v) != 3:
            raise ConfigError(f"sets[{k!r}] must be a UnitSet or a (points, units, group) tuple, got {v!r:.60}")
    if isinstance(pairs, (str, bytes, dict)) or not isinstance(pairs, (list, tuple)):
        raise ConfigError(f"pairs must be a list of (set, reference) names, got {type(pairs).__name__}")
    if not all(isinstance(p, (list, tuple)) for p in pairs):
        raise ConfigError(f"pairs must be (set, reference) names of sets, got {pairs!r:.60}")
    boxes = check.numbers(boxes, "boxes", positive=True).tolist()
    check.count(offsets, "offsets", 1)
    check.count(n_boot, "n_boot", 2)
    sets = {k: UnitSet(*v) for k, v in sets.items()}
    pairs = [tuple(p) for p in pairs]
    for name, s in sets.items():
        pts = _checks.points(s.points, f"sets[{name!r}].points")
        check.numbers(s.units, f"sets[{name!r}].units")
        un = np.asarray(s.units)
        if un.shape[0] != pts.shape[0]:
            raise ConfigError(
                f"sets[{name!r}]: the units must have one entry per point ({un.shape[0]} vs {pts.shape[0]})"
            )
        sets[name] = UnitSet(pts, un, s.group)
    missing = sorted({n for p in pairs for n in p} - set(sets))
    if missing or not pairs or any(len(p) != 2 for p in pairs):
        raise ConfigError(f"pairs must be (set, reference) names of sets; unknown: {missing}")
    if int(offsets) < 1 or int(n_boot) < 2 or not boxes or min(boxes) <= 0:
        raise ConfigError(f"need offsets ≥ 1, n_boot ≥ 2 and box sides > 0, got {offsets!r}, {n_boot!r}, {boxes!r}")
    groups = {}
    for s in sets.values():
        groups.setdefault(s.group, []).append(s.units)
    group_units = {g: np.unique(np.concatenate(u)) for g, u in groups.items()}
    if any(u.size < 4 for u in group_units.values()):
        raise ConfigError("need at least 4 units in every group of sets")
    return sets, pairs, boxes, group_units


def _half_counts(name, s, halves, cells, totals):
    """[box][offset] (counts of the half-sample, counts of its complement) of set ``s`` on every partition."""
    inh = np.isin(s.units, halves[s.group])
    if inh.all() or not inh.any():
        raise ConfigError(f"a half-sample of set {name!r} is empty: too few units")
    out = []
    for row, trow in zip(cells, totals):
        half = [np.bincount(c[inh], minlength=k) for c, k in row]
        out.append([(h, t - h) for h, t in zip(half, trow)])
    return out


def paired_hellinger_difference(
    A,
    B,
    R,
    box: float,
    extent,
    *,
    units_a,
    units_b,
    units_r,
    offsets: int = 2,
    n_boot: int = 100,
    level: float = 0.95,
    seed: int = 0,
) -> PairedDifference:
    """Δ = H(B, R) − H(A, R) with a paired interval that resamples the independent unit of every set.

    The question is whether a set B (e.g. the crossings in an energy band) lies closer to a
    reference R (e.g. a c-measure) than a set A (e.g. every crossing). Points are not independent: one orbit may give
    several crossings, and B may share orbits with A. So the *units* (orbit ids) are resampled, never the
    points, and A and B are resampled together (one draw of the dissipative run's orbits serves both),
    while R's units are drawn once per replicate and serve both distances: the interval of Δ is paired.

    Each replicate is a half-sample (half of the units of A ∪ B, and half of R's, without replacement):
    for smooth statistics its spread equals the sampling spread of the full-sample estimate. In each
    replicate the finite-sample bias of the squared Hellinger distance is removed with the complementary
    halves, H²_deb(X, R) = H²(X_h, R_h) − ½ H²(X_h, X_c) − ½ H²(R_h, R_c), averaged over ``offsets``²
    placements of the box grid (shifts by box/offsets), and H = √max(H²_deb, 0)
    (:func:`paired_hellinger_replicates` with A, B in one group and R in another).

    Parameters
    ----------
    A, B, R : array_like (n, 2)
        Points (x, y) of the two sets and of the reference.
    box : float
        Box side ε (units of x, y).
    extent : (x0, x1, y0, y1)
        The partition's anchor and span (every offset partition is widened by one box).
    units_a, units_b, units_r : array_like (n,)
        The independent unit of each point (e.g. ``traj_id``); A and B share one id space.
    offsets : int
        Grid placements per axis (1: the anchored grid only).
    n_boot : int
        Half-sample replicates.
    level : float
        Coverage of the percentile intervals.
    seed : int
        Seed of the replicates (deterministic).

    Returns
    -------
    PairedDifference
        Debiased distances, Δ with its interval, and the spread of the full-sample Δ over grid offsets.

    Examples
    --------
    >>> import numpy as np
    >>> rng = np.random.default_rng(0)
    >>> R = rng.random((4000, 2)); A = rng.random((4000, 2)); ids = np.arange(4000)
    >>> r = paired_hellinger_difference(A, A[:2000], R, 0.25, (0, 1, 0, 1), units_a=ids, units_b=ids[:2000],
    ...                                 units_r=ids, n_boot=40)
    >>> bool(r.lo < 0 < r.hi), bool(abs(r.delta) < 0.05)     # B is a random half of A: no difference
    (True, True)
    """
    A, B, R = _checks.points(A, "A"), _checks.points(B, "B"), _checks.points(R, "R")
    box = check.number(box, "box", positive=True)
    _checks.extent(extent)
    for name, units, pts in (("units_a", units_a, A), ("units_b", units_b, B), ("units_r", units_r, R)):
        if check.numbers(units, name).size != pts.shape[0]:
            raise ConfigError(f"{name} must have one entry per point of its set ({np.size(units)} vs {pts.shape[0]})")
    check.count(offsets, "offsets", 1)
    check.count(n_boot, "n_boot", 2)
    check.count(seed, "seed", 0)
    if not 0 < check.number(level, "level") < 1:
        raise ConfigError(f"level must be in (0, 1), got {level!r}")
    sets = {"A": UnitSet(A, units_a, "run"), "B": UnitSet(B, units_b, "run"), "R": UnitSet(R, units_r, "ref")}
    reps = paired_hellinger_replicates(
        sets, [("A", "R"), ("B", "R")], [box], extent, offsets=offsets, n_boot=n_boot, seed=seed
    )[:, :, 0]
    da, db = reps[:, 0], reps[:, 1]
    d, lo, hi = percentile_interval(db - da, level)
    extents = _offset_extents(extent, float(box), int(offsets))
    full = np.sqrt(_h2(B, R, box, extents)) - np.sqrt(_h2(A, R, box, extents))
    return PairedDifference(
        d_a=float(da.mean()),
        d_b=float(db.mean()),
        delta=d,
        lo=lo,
        hi=hi,
        d_a_interval=percentile_interval(da, level)[1:],
        d_b_interval=percentile_interval(db, level)[1:],
        offset_spread=float(full.std(ddof=1)) if full.size > 1 else 0.0,
        n_boot=int(n_boot),
    )
