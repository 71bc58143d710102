"""Distances between point sets on the surface of section.

Reference: Sec. III.B.2 of Burton, Dullin & Altmann (2023).

That reference compares, by eye, the section crossings (x, y) of dissipative orbits
alive at t* with the conservative c-measure μ_c^{E1}, and claims that "the
agreement is expected to hold up to a finite spatial scale, which becomes
increasingly small as the time for the distributions to relax increases"
(below Eq. (eqn:c-measure_model)).  This module makes that comparison
quantitative.

Distances provided
------------------
* Box-counting histograms on a common partition of boxes of side ε:
  total variation TV = ½ Σ|p_i − q_i| ∈ [0, 1] and Hellinger
  H = (½ Σ(√p_i − √q_i)²)^{1/2} ∈ [0, 1] (:func:`histogram_distance`), and
  their dependence on ε (:func:`distance_vs_scale`).  They obey
  H² ≤ TV ≤ √2 H.
* Sliced Wasserstein SW_p (:func:`sliced_wasserstein`): the W_p distance of
  1-D projections averaged over directions; in units of x, y.
* :func:`bootstrap_distance` (resampling spread; one or several distances per
  resample), :func:`split_half_baseline` (finite-sample noise floor of one set)
  and :func:`split_half_noise` (the same for two sets, as
  :func:`distance_vs_scale` uses it).

Which distance to headline
--------------------------
**Hellinger on box histograms, as a function of ε.**  The claim is
scale-resolved — agreement "up to a finite spatial scale" — and so is
H(ε): at box side ε it is blind to structure finer than ε and sensitive to
everything coarser, so the curve H(ε) against its noise floor yields the
agreement scale directly (:func:`agreement_scale`).  Hellinger is preferred
over TV because (i) it is a sum of per-box terms whose finite-sample bias is
nearly independent of the box masses, E[H²] ≈ B/8 (1/n_P + 1/n_Q) for B
occupied boxes with many counts, so the split-half noise floor is clean and
predictable; (ii) it weights low-mass boxes (thin filaments of the unstable
manifold, where supports differ) more than TV does, which is where a
fractal c-measure and a noisier dissipative distribution disagree; (iii) it is
bounded and a metric, so values are comparable across ε and data sets.  TV is
reported alongside (same information, more common interpretation: the
largest difference in probability of any set of boxes).

The sliced Wasserstein distance is scale-free: one number in units of
length, dominated by where the bulk of the mass is, and nearly insensitive to
fine filaments (moving mass by δ costs only ~δ).  It is a good global check
(e.g. that one c-measure is closer than another to a set) but cannot
by itself say down to which scale two sets agree.

Finite-sample baseline and the agreement scale
----------------------------------------------
Histogram distances between two finite samples are biased upwards: two
independent samples of the *same* distribution have H(ε) > 0, growing as ε
shrinks (fewer points per box) until H → 1 when boxes hold ≤ 1 point.
:func:`distance_vs_scale` (with ``n_splits`` > 0) therefore compares like with
like at a common sample size m = ⌊min(n_P, n_Q)/2⌋: for random disjoint halves
P1, P2 of P and Q1, Q2 of Q it records d_PQ = mean(d(P1,Q1), d(P2,Q2)) and the
noise floor d_noise = mean(d(P1,P2), d(Q1,Q2)), each averaged over
``n_splits`` random splits (their spread over splits is reported as *_std).
If P and Q come from one distribution, d_PQ and d_noise have the same
expectation.  The two sets are said to *agree at scale ε* when
d_PQ ≤ d_noise + z·σ, with σ the combined split-to-split spread of d_PQ and
d_noise (z = 2 by default), and the scale is *informative* when
d_noise ≤ noise_max (default 0.5; beyond it the boxes are so sparsely filled
that any two samples look different).  The agreement scale
ε* (:func:`agreement_scale`) is the smallest ε such that the sets agree at
every informative box size ≥ ε.  Since the noise floor shrinks with sample
size, ε* is a statement about the data at hand: with more points a real
difference becomes detectable at coarser ε.

Inputs are arrays of shape (n, 2) with columns (x, y) (any 2-D coordinates).
Outputs: dimensionless for TV/H, length units for SW.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.stats import _arguments as check
from hhscatter.errors import ConfigError

__all__ = [
    "BootstrapResult",
    "agreement_scale",
    "agreement_scale_debiased",
    "bootstrap_distance",
    "box_distances",
    "box_histograms",
    "debiased_distance",
    "distance_vs_scale",
    "first_crossings",
    "hellinger",
    "histogram_distance",
    "points",
    "sliced_wasserstein",
    "split_half_baseline",
    "split_half_noise",
    "total_variation",
    "wasserstein_1d",
]

KINDS = ("hellinger", "tv")


class BootstrapResult(NamedTuple):
    """(mean, std) of a resampled distance."""

    mean: float
    std: float


def points(df: pd.DataFrame, columns=("x", "y")) -> np.ndarray:
    """points(df, columns=("x", "y")) -> (n, 2) float array, e.g. from the engine's ``sections`` table.

    Examples
    --------
    >>> sections = pd.DataFrame({"traj_id": [0, 1], "t": [2.0, 3.5], "x": [0.1, -0.2], "y": [0.3, 0.4]})
    >>> points(sections).tolist()
    [[0.1, 0.3], [-0.2, 0.4]]
    """
    if isinstance(columns, (str, bytes)) or not hasattr(columns, "__iter__"):
        raise ConfigError(f"columns must be a sequence of column names, got {columns!r}")
    check.table(df, "df", tuple(columns), min_rows=0)
    return np.column_stack([df[c].to_numpy(dtype=float) for c in columns])


def first_crossings(
    sections: pd.DataFrame, t_from: float, *, e_min: float = -np.inf, e_max: float = np.inf
) -> pd.DataFrame:
    """first_crossings(sections, t_from, *, e_min=-inf, e_max=inf) -> DataFrame, one row per orbit.

    For each ``traj_id`` of the engine's ``sections`` table (columns traj_id,
    t, x, y, px, py, energy), its first crossing of the section ṙ = 0, φ̇ > 0
    at orbit time t ≥ ``t_from``; orbits without such a crossing (escaped or
    settled before it) are absent.  This is the sprinkler sample
    (t_from = recording time) and the first intersection for t ≥ t*
    (t_from = t*).  The energy filter is applied *after* choosing the first
    crossing (it keeps only the surviving points whose energy at the time of
    the crossing is in the interval), so it selects among the rows without
    the filter, it does not look further in time.
    Requires every crossing after ``t_from`` to be in the table (a section
    window starting at or before ``t_from``, not ``first_only`` with a later
    start).  Rows sorted by traj_id.

    Examples
    --------
    Orbit 0 crosses at t = 1, 3, 5; orbit 1 only at t = 2, before ``t_from``:

    >>> s = pd.DataFrame({"traj_id": [0, 0, 0, 1], "t": [1.0, 3.0, 5.0, 2.0], "x": [0.1, 0.2, 0.3, 0.4], "y": 0.0})
    >>> first_crossings(s, 2.5)[["traj_id", "t", "x"]].to_dict("records")
    [{'traj_id': 0, 't': 3.0, 'x': 0.2}]
    """
    need = {"traj_id", "t"}
    check.table(sections, "sections", min_rows=0)
    t_from = check.number(t_from, "t_from")
    for name, v in (("e_min", e_min), ("e_max", e_max)):
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)) or math.isnan(v):
            raise ConfigError(f"{name} must be a number (±inf: no bound), got {v!r}")
    if not need <= set(sections.columns):
        raise ConfigError(f"sections needs columns {sorted(need)}, has {sorted(sections.columns)}")
    s = sections[sections["t"] >= t_from]
    s = s.sort_values(["traj_id", "t"], kind="stable").drop_duplicates("traj_id", keep="first")
    if "energy" in s.columns and (np.isfinite(e_min) or np.isfinite(e_max)):
        s = s[(s["energy"] >= e_min) & (s["energy"] <= e_max)]
    return s.reset_index(drop=True)


def _as_points(X, name: str = "points") -> np.ndarray:
    return _checks.points(X, name)


def _box(box, name: str = "box") -> float:
    return check.number(box, name, positive=True)


def _weights(w, n: int, name: str):
    if w is None:
        return None
    if check.numbers(w, name, minimum=0.0).size != n or not np.sum(w) > 0:
        raise ConfigError(f"{name} must be one weight ≥ 0 per point ({np.size(w)} vs {n}), not all 0")
    return w


def _kind(kind) -> str:
    if not isinstance(kind, str) or kind not in KINDS:
        raise ConfigError(f"kind must be one of {KINDS}, got {kind!r}")
    return kind


def _distance_table(table, kind):
    check.table(table, "table", ("box",))
    _kind(kind)


def _extent_of(*sets, pad=1e-9):
    allp = np.vstack(sets)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    w = np.maximum(hi - lo, 1e-12)
    return (lo[0] - pad * w[0], hi[0] + pad * w[0], lo[1] - pad * w[1], hi[1] + pad * w[1])


def _cells(X, box, extent):
    """Box index of each point; −1 for points outside ``extent`` (one overflow cell)."""
    x0, x1, y0, y1 = map(float, extent)
    if not (x1 > x0 and y1 > y0):
        raise ConfigError(f"bad extent {extent!r}")
    if not box > 0:
        raise ConfigError(f"box size must be > 0, got {box!r}")
    ny = int(np.floor((y1 - y0) / box)) + 1
    ix = np.floor((X[:, 0] - x0) / box)
    iy = np.floor((X[:, 1] - y0) / box)
    inside = (X[:, 0] >= x0) & (X[:, 0] <= x1) & (X[:, 1] >= y0) & (X[:, 1] <= y1)
    return np.where(inside, ix.astype(np.int64) * ny + iy.astype(np.int64), -1)


def box_histograms(P, Q, box: float, extent=None, weights_P=None, weights_Q=None):
    """box_histograms(P, Q, box, extent=None) -> (p, q) probability vectors on the occupied boxes.

    Common partition of ``extent`` = (x_min, x_max, y_min, y_max) (default:
    bounding box of P ∪ Q) into squares of side ``box`` anchored at
    (x_min, y_min); points outside ``extent`` share one overflow cell so that
    no mass is lost.  Only boxes occupied by P or Q are returned (memory does
    not grow with 1/ε²).  Optional non-negative weights per point.

    Examples
    --------
    Boxes of side 0.5 on the unit square: P has one point in each of two boxes, Q both in the first.

    >>> P, Q = [[0.1, 0.1], [0.6, 0.1]], [[0.1, 0.1], [0.2, 0.3]]
    >>> [a.tolist() for a in box_histograms(P, Q, 0.5, (0, 1, 0, 1))]
    [[0.5, 0.5], [1.0, 0.0]]
    """
    P, Q = _as_points(P, "P"), _as_points(Q, "Q")
    _box(box)
    if extent is not None:
        _checks.extent(extent)
    _weights(weights_P, P.shape[0], "weights_P")
    _weights(weights_Q, Q.shape[0], "weights_Q")
    if extent is None:
        extent = _extent_of(P, Q)
    cp, cq = _cells(P, box, extent), _cells(Q, box, extent)
    uniq, inv = np.unique(np.concatenate([cp, cq]), return_inverse=True)
    wp = np.ones(P.shape[0]) if weights_P is None else np.asarray(weights_P, dtype=float)
    wq = np.ones(Q.shape[0]) if weights_Q is None else np.asarray(weights_Q, dtype=float)
    p = np.bincount(inv[: P.shape[0]], weights=wp, minlength=uniq.size)
    q = np.bincount(inv[P.shape[0] :], weights=wq, minlength=uniq.size)
    return p / p.sum(), q / q.sum()


def _probabilities(p, q):
    if check.numbers(p, "p", minimum=0.0).size != check.numbers(q, "q", minimum=0.0).size:
        raise ConfigError(f"p and q must be probability vectors on the same boxes ({np.size(p)} vs {np.size(q)})")


def total_variation(p, q) -> float:
    """total_variation(p, q) -> ½ Σ|p_i − q_i| ∈ [0, 1] for probability vectors.

    Examples
    --------
    Half the mass moves to a box of its own: TV = ½ (½ + ½) = ½.

    >>> total_variation([0.5, 0.5, 0.0], [0.0, 0.5, 0.5]), total_variation([1, 0], [0, 1])
    (0.5, 1.0)
    """
    _probabilities(p, q)
    return float(0.5 * np.sum(np.abs(np.asarray(p) - np.asarray(q))))


def hellinger(p, q) -> float:
    """hellinger(p, q) -> (½ Σ(√p_i − √q_i)²)^{1/2} ∈ [0, 1] for probability vectors.

    Examples
    --------
    H² = 1 − Σ √(p_i q_i): ½ here (H = √½ = 0.7071), 1 for disjoint supports.

    >>> round(hellinger([0.5, 0.5, 0.0], [0.0, 0.5, 0.5]), 4), hellinger([1, 0], [0, 1])
    (0.7071, 1.0)
    """
    _probabilities(p, q)
    d = np.sqrt(np.asarray(p, dtype=float)) - np.sqrt(np.asarray(q, dtype=float))
    return float(np.sqrt(min(0.5 * np.sum(d * d), 1.0)))


def histogram_distance(
    P, Q, box: float, extent=None, kind: str = "hellinger", *, weights_P=None, weights_Q=None
) -> float:
    """histogram_distance(P, Q, box, extent, kind="hellinger") -> float in [0, 1].

    Hellinger (``kind="hellinger"``) or total-variation (``kind="tv"``)
    distance between the box histograms of the point sets P, Q ((n, 2)
    arrays) on the common partition of ``extent`` into boxes of side ``box``
    (see :func:`box_histograms`).  Dimensionless; H² ≤ TV ≤ √2 H.

    Examples
    --------
    P splits its mass between two boxes of side 0.5, Q holds all of it in the first: H² = 1 − √½ = 0.2929.

    >>> P, Q = [[0.1, 0.1], [0.6, 0.1]], [[0.1, 0.1], [0.2, 0.3]]
    >>> round(histogram_distance(P, Q, 0.5, (0, 1, 0, 1)) ** 2, 4), histogram_distance(P, Q, 0.5, (0, 1, 0, 1), "tv")
    (0.2929, 0.5)
    """
    _kind(kind)
    p, q = box_histograms(P, Q, box, extent, weights_P, weights_Q)
    if kind == "hellinger":
        return hellinger(p, q)
    if kind == "tv":
        return total_variation(p, q)
    raise ConfigError(f"kind must be one of {KINDS}, got {kind!r}")


_DISTANCE = {"hellinger": hellinger, "tv": total_variation}


def _check_kinds(kinds):
    if isinstance(kinds, (str, bytes, dict)) or not isinstance(kinds, (list, tuple)) or not kinds:
        raise ConfigError(f"kinds must be a non-empty sequence of {KINDS}, got {kinds!r}")
    for k in kinds:
        if k not in KINDS:
            raise ConfigError(f"kind must be one of {KINDS}, got {k!r}")


def box_distances(P, Q, boxes, extent=None, kinds=KINDS) -> np.ndarray:
    """box_distances(P, Q, boxes, extent=None, kinds=("hellinger", "tv")) -> array (len(boxes), len(kinds)).

    :func:`histogram_distance` of the point sets P, Q at every box side of
    ``boxes`` (in the given order), every kind from one histogram pair per box.

    Examples
    --------
    P in the left half of the unit square, Q in the right one: disjoint at ε = 0.5, one common box at ε = 2.

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((100, 2)) * [0.5, 1], rng.random((100, 2)) * [0.5, 1] + [0.5, 0]
    >>> box_distances(P, Q, [0.5, 2.0], (0, 1, 0, 1)).tolist()  # columns: hellinger, tv
    [[1.0, 1.0], [0.0, 0.0]]
    """
    P, Q = _as_points(P, "P"), _as_points(Q, "Q")
    check.numbers(boxes, "boxes", positive=True)
    if extent is not None:
        _checks.extent(extent)
    _check_kinds(kinds)
    if extent is None:
        extent = _extent_of(P, Q)
    out = np.empty((len(boxes), len(kinds)))
    for j, eps in enumerate(boxes):
        p, q = box_histograms(P, Q, eps, extent)
        out[j] = [_DISTANCE[k](p, q) for k in kinds]
    return out


def _split_halves(P, Q, m: int, n_splits: int, rng):
    """(P1, P2, Q1, Q2) per split: disjoint random halves of m points of P and of Q (one permutation each)."""
    for _ in range(n_splits):
        ip, iq = rng.permutation(P.shape[0]), rng.permutation(Q.shape[0])
        yield P[ip[:m]], P[ip[m : 2 * m]], Q[iq[:m]], Q[iq[m : 2 * m]]


def _common_m(P, Q, m):
    m_max = min(P.shape[0], Q.shape[0]) // 2
    if m_max < 1:
        raise ConfigError("need at least 2 points in each set for the split-half baseline")
    if m is None:
        return m_max
    if not 1 <= int(m) <= m_max:
        raise ConfigError(f"m must be in [1, {m_max}] = [1, ⌊min(n_P, n_Q)/2⌋], got {m!r}")
    return int(m)


def distance_vs_scale(
    P,
    Q,
    boxes,
    extent=None,
    *,
    kinds=KINDS,
    n_splits: int = 8,
    seed: int = 0,
    m: int | None = None,
) -> pd.DataFrame:
    """distance_vs_scale(P, Q, boxes, extent=None, *, kinds=("hellinger", "tv"), n_splits=8, seed=0, m=None) -> DataFrame.

    One row per box side ε in ``boxes`` (sorted decreasing) with columns

    * ``box`` and, per kind, ``<kind>``: the distance between the full sets;
    * if ``n_splits`` > 0, at the common sample size m = ⌊min(n_P, n_Q)/2⌋
      (column ``m``): ``<kind>_pq`` (mean of d(P1,Q1), d(P2,Q2)),
      ``<kind>_pq_std``, ``<kind>_noise`` (split-half noise floor, mean of
      d(P1,P2), d(Q1,Q2)), ``<kind>_noise_std`` and ``<kind>_excess`` =
      pq − noise, over ``n_splits`` random splits (module docstring).

    ``m`` fixes the common sample size of the split-half comparison (default
    ⌊min(n_P, n_Q)/2⌋; it must not exceed that).  Since the noise floor and
    hence the agreement scale depend on the sample size, comparisons of
    several pairs of sets (e.g. several dissipation rates) must use
    one common ``m`` to be comparable.

    ``extent`` defaults to the bounding box of P ∪ Q; the same partition is
    used for every comparison.  Deterministic for a given ``seed``.

    Examples
    --------
    P uniform on the unit square, Q uniform on the black squares of a checkerboard of side 0.1: the same mass in
    every box of side ≥ 0.2, half the support at 0.1 (H² = 1 − 50·√(1/100 · 1/50) = 1 − √½, H = 0.541).

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((2000, 2)), rng.random((4000, 2))
    >>> Q = Q[np.floor(Q / 0.1).sum(axis=1) % 2 == 0]
    >>> t = distance_vs_scale(P, Q, [0.1, 0.5, 0.2], (0, 1, 0, 1))
    >>> t[["box", "hellinger", "hellinger_pq", "hellinger_noise"]].round(2).values.tolist()
    [[0.5, 0.02, 0.03, 0.03], [0.2, 0.05, 0.08, 0.07], [0.1, 0.55, 0.56, 0.13]]
    """
    P, Q = _as_points(P, "P"), _as_points(Q, "Q")
    check.numbers(boxes, "boxes", positive=True)
    if extent is not None:
        _checks.extent(extent)
    n_splits = check.count(n_splits, "n_splits", 0)
    check.count(seed, "seed", 0)
    if m is not None:
        check.count(m, "m", 1)
    if extent is None:
        extent = _extent_of(P, Q)
    boxes = np.sort(np.asarray(boxes, dtype=float).ravel())[::-1]
    _check_kinds(kinds)
    fn = _DISTANCE
    full = box_distances(P, Q, boxes, extent, kinds)
    out = pd.DataFrame({"box": boxes.astype(float), **{k: full[:, i] for i, k in enumerate(kinds)}})
    if n_splits > 0:
        m = _common_m(P, Q, m)
        rng = np.random.default_rng(seed)
        pq = np.empty((n_splits, boxes.size, len(kinds)))
        nz = np.empty_like(pq)
        for s, (P1, P2, Q1, Q2) in enumerate(_split_halves(P, Q, m, n_splits, rng)):
            for j, eps in enumerate(boxes):
                # one histogram pair per comparison, shared by all kinds
                h = [box_histograms(A, B, eps, extent) for A, B in ((P1, Q1), (P2, Q2), (P1, P2), (Q1, Q2))]
                for i, k in enumerate(kinds):
                    pq[s, j, i] = 0.5 * (fn[k](*h[0]) + fn[k](*h[1]))
                    nz[s, j, i] = 0.5 * (fn[k](*h[2]) + fn[k](*h[3]))
        out["m"] = m
        ddof = 1 if n_splits > 1 else 0
        for i, k in enumerate(kinds):
            out[f"{k}_pq"] = pq[:, :, i].mean(axis=0)
            out[f"{k}_pq_std"] = pq[:, :, i].std(axis=0, ddof=ddof)
            out[f"{k}_noise"] = nz[:, :, i].mean(axis=0)
            out[f"{k}_noise_std"] = nz[:, :, i].std(axis=0, ddof=ddof)
            out[f"{k}_excess"] = out[f"{k}_pq"] - out[f"{k}_noise"]
    return out


def agreement_scale(table: pd.DataFrame, kind: str = "hellinger", z: float = 2.0, noise_max: float = 0.5):
    """agreement_scale(table, kind="hellinger", z=2.0, noise_max=0.5) -> float or None.

    From a :func:`distance_vs_scale` table computed with ``n_splits`` ≥ 2:
    the smallest box side ε* such that at every informative box size
    ε ≥ ε* (noise floor ``<kind>_noise`` ≤ ``noise_max``) the sets agree
    within sampling noise, ``<kind>_pq`` ≤ ``<kind>_noise`` + z·σ with
    σ = √(``<kind>_noise_std``² + ``<kind>_pq_std``²) (the split-to-split
    spreads; for two independent samples of one distribution the resulting
    z-scores have a spread ≲ 1, so z = 2 rarely flags a false disagreement).
    None if they already disagree at the coarsest informative scale (or no
    scale is informative).  Same units as the boxes.

    Examples
    --------
    The checkerboard of :func:`distance_vs_scale`: the sets agree down to ε = 0.2 and differ at 0.1.

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((2000, 2)), rng.random((4000, 2))
    >>> Q = Q[np.floor(Q / 0.1).sum(axis=1) % 2 == 0]
    >>> agreement_scale(distance_vs_scale(P, Q, [0.5, 0.2, 0.1], (0, 1, 0, 1)))
    0.2
    """
    _distance_table(table, kind)
    z, noise_max = check.number(z, "z", minimum=0.0), check.number(noise_max, "noise_max", minimum=0.0)
    need = {f"{kind}_pq", f"{kind}_pq_std", f"{kind}_noise", f"{kind}_noise_std"}
    if not need <= set(table.columns):
        raise ConfigError("table lacks the split-half columns; run distance_vs_scale with n_splits >= 2")
    tab = table.sort_values("box", ascending=False)
    tab = tab[tab[f"{kind}_noise"] <= noise_max]
    best = None
    for _, r in tab.iterrows():
        sigma = np.hypot(r[f"{kind}_noise_std"], r[f"{kind}_pq_std"])
        if r[f"{kind}_pq"] <= r[f"{kind}_noise"] + z * sigma:
            best = float(r["box"])
        else:
            break
    return best


def debiased_distance(table: pd.DataFrame, kind: str = "hellinger"):
    """debiased_distance(table, kind="hellinger") -> (d, d_lo, d_hi) arrays, one per row (box side).

    Finite-sample-corrected distance at each box side from a
    :func:`distance_vs_scale` table: d = √max(d_pq² − d_noise², 0), the
    split-half noise floor removed in quadrature, with a 1σ band (d_lo, d_hi)
    from σ(d²) = 2 √((d_pq σ_pq)² + (d_noise σ_noise)²).  For Hellinger and
    boxes holding many points, E[H²_pq] ≈ H²_true + E[H²_noise] when P ≈ Q
    (both bias terms are B/8 · 2/m for B commonly occupied boxes), so d
    estimates the distance between the two underlying distributions
    coarse-grained at ε, nearly independent of the sample size m — unlike
    d_pq − d_noise.  Where the supports differ, boxes occupied by one set only
    carry no bias and d is slightly underestimated (by ≈ (B_noise − B_pq)/(4m)
    in H²).  Dimensionless.

    Examples
    --------
    The checkerboard of :func:`distance_vs_scale`: ≈ 0 where the boxes hold equal masses, H = 0.541 at ε = 0.1.

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((2000, 2)), rng.random((4000, 2))
    >>> Q = Q[np.floor(Q / 0.1).sum(axis=1) % 2 == 0]
    >>> d, lo, hi = debiased_distance(distance_vs_scale(P, Q, [0.5, 0.2, 0.1], (0, 1, 0, 1)))
    >>> np.round(d, 2).tolist()
    [0.01, 0.02, 0.54]
    """
    _distance_table(table, kind)
    need = {f"{kind}_pq", f"{kind}_pq_std", f"{kind}_noise", f"{kind}_noise_std"}
    if not need <= set(table.columns):
        raise ConfigError("table lacks the split-half columns; run distance_vs_scale with n_splits >= 2")
    pq, sp = table[f"{kind}_pq"].to_numpy(float), table[f"{kind}_pq_std"].to_numpy(float)
    nz, sn = table[f"{kind}_noise"].to_numpy(float), table[f"{kind}_noise_std"].to_numpy(float)
    d2 = pq**2 - nz**2
    s2 = 2.0 * np.hypot(pq * sp, nz * sn)
    return (np.sqrt(np.maximum(d2, 0.0)), np.sqrt(np.maximum(d2 - s2, 0.0)), np.sqrt(np.maximum(d2 + s2, 0.0)))


def agreement_scale_debiased(table: pd.DataFrame, delta: float = 0.1, kind: str = "hellinger", noise_max: float = 0.5):
    """agreement_scale_debiased(table, delta=0.1, kind="hellinger", noise_max=0.5) -> float or None.

    Like :func:`agreement_scale`, but with a tolerance instead of a
    significance test: the smallest box side ε such that the
    finite-sample-corrected distance (:func:`debiased_distance`) is ≤
    ``delta`` at every informative box size ≥ ε (noise floor ≤ ``noise_max``).
    Unlike the significance test, whose answer shrinks towards the
    finest resolvable scale as samples grow, this estimates a property of the
    two distributions ("they differ by less than δ down to scale ε*"), and so
    can be compared between data sets of different sizes.  None if already
    d > δ at the coarsest informative scale.  Units of the boxes.

    Examples
    --------
    The checkerboard of :func:`distance_vs_scale`: within δ = 0.1 down to ε = 0.2 (H = 0.541 at 0.1).

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((2000, 2)), rng.random((4000, 2))
    >>> Q = Q[np.floor(Q / 0.1).sum(axis=1) % 2 == 0]
    >>> agreement_scale_debiased(distance_vs_scale(P, Q, [0.5, 0.2, 0.1], (0, 1, 0, 1)), delta=0.1)
    0.2
    """
    _distance_table(table, kind)
    delta, noise_max = check.number(delta, "delta", minimum=0.0), check.number(noise_max, "noise_max", minimum=0.0)
    d, _, _ = debiased_distance(table, kind)
    order = np.argsort(-table["box"].to_numpy(float))
    noise = table[f"{kind}_noise"].to_numpy(float)
    best = None
    for i in order:
        if noise[i] > noise_max:
            continue
        if d[i] <= delta:
            best = float(table["box"].to_numpy(float)[i])
        else:
            break
    return best


# ---------------------------------------------------------------------------
# sliced Wasserstein
# ---------------------------------------------------------------------------
def _w1d_sorted(xs, ys, p):
    """W_p^p between sorted samples along axis 0 (columns = projections)."""
    n, m = xs.shape[0], ys.shape[0]
    if n == m:
        return np.mean(np.abs(xs - ys) ** p, axis=0)
    u = np.union1d(np.arange(1, n + 1) / n, np.arange(1, m + 1) / m)
    du = np.diff(np.concatenate([[0.0], u]))
    mid = u - 0.5 * du
    ix = np.minimum((mid * n).astype(np.int64), n - 1)
    iy = np.minimum((mid * m).astype(np.int64), m - 1)
    return du @ (np.abs(xs[ix] - ys[iy]) ** p)


def wasserstein_1d(x, y, p: float = 1) -> float:
    """wasserstein_1d(x, y, p=1) -> W_p between two 1-D empirical distributions (exact, via quantile functions).

    Examples
    --------
    A shift by 0.5 moves every point by 0.5; with unequal sizes the quantile functions are compared.

    >>> wasserstein_1d([0, 1, 2], [0.5, 1.5, 2.5]), wasserstein_1d([0, 1], [0, 0, 1, 1])
    (0.5, 0.0)
    """
    check.numbers(x, "x")
    check.numbers(y, "y")
    check.number(p, "p", minimum=1.0)
    xs = np.sort(np.asarray(x, dtype=float).ravel())[:, None]
    ys = np.sort(np.asarray(y, dtype=float).ravel())[:, None]
    return float(_w1d_sorted(xs, ys, p)[0] ** (1.0 / p))


def sliced_wasserstein(
    P, Q, n_proj: int = 128, seed: int = 0, *, p: float = 1, directions: str = "stratified"
) -> float:
    """sliced_wasserstein(P, Q, n_proj=128, seed=0, *, p=1, directions="stratified") -> float.

    SW_p(P, Q) = ( mean_θ W_p(⟨P,θ⟩, ⟨Q,θ⟩)^p )^{1/p} over ``n_proj`` unit
    directions θ in the plane (θ and −θ are equivalent, so angles lie in
    [0, π)).  ``directions="stratified"`` (default) uses equally spaced
    angles with a random common offset (error O(1/n_proj²) for smooth
    integrands); ``"random"`` draws i.i.d. uniform angles.  Deterministic for
    a given ``seed``.  The 1-D distances are exact for unequal sample sizes.
    Units of the coordinates.  For Q = P + s (pure translation) and p = 1,
    SW_1 = E_θ|⟨s,θ⟩| = 2|s|/π; for p = 2, SW_2 = |s|/√2.

    Examples
    --------
    A translation by s = (1, 0): SW_1 = 2|s|/π = 0.6366, SW_2 = |s|/√2 = 0.7071.

    >>> P = np.random.default_rng(0).normal(size=(500, 2))
    >>> round(sliced_wasserstein(P, P + [1, 0]), 4), round(sliced_wasserstein(P, P + [1, 0], p=2), 4)
    (0.6366, 0.7071)
    """
    P, Q = _as_points(P, "P"), _as_points(Q, "Q")
    n_proj = check.count(n_proj, "n_proj", 1)
    check.count(seed, "seed", 0)
    check.number(p, "p", minimum=1.0)
    rng = np.random.default_rng(seed)
    if directions == "stratified":
        ang = rng.uniform(0.0, np.pi / n_proj) + np.pi * np.arange(n_proj) / n_proj
    elif directions == "random":
        ang = rng.uniform(0.0, np.pi, n_proj)
    else:
        raise ConfigError("directions must be 'stratified' or 'random'")
    dirs = np.column_stack([np.cos(ang), np.sin(ang)])
    total = 0.0
    chunk = max(1, int(4_000_000 // max(P.shape[0] + Q.shape[0], 1)))
    for s in range(0, n_proj, chunk):
        D = dirs[s : s + chunk].T
        xs = np.sort(P @ D, axis=0)
        ys = np.sort(Q @ D, axis=0)
        total += float(np.sum(_w1d_sorted(xs, ys, p)))
    return float((total / n_proj) ** (1.0 / p))


# ---------------------------------------------------------------------------
# resampling
# ---------------------------------------------------------------------------
def bootstrap_distance(P, Q, fn: Callable, n_boot: int = 100, seed: int = 0) -> BootstrapResult:
    """bootstrap_distance(P, Q, fn, n_boot=100, seed=0) -> BootstrapResult(mean, std).

    Resamples P and Q independently with replacement ``n_boot`` times and
    returns the mean and standard deviation (ddof = 1) of fn(P*, Q*), e.g.
    ``fn = lambda A, B: histogram_distance(A, B, 0.01, extent)``.  The std
    is the sampling error of fn(P, Q).  ``fn`` may return an array (mean and
    std are then arrays of its shape) or a tuple of values and arrays (then
    tuples): several distances of the same resamples, e.g.
    ``lambda A, B: (box_distances(A, B, boxes, extent), sliced_wasserstein(A, B))``.
    Note that resampling with replacement duplicates points, which biases
    histogram distances upwards (fewer distinct points); judge closeness
    against :func:`split_half_baseline`, not against zero.  Deterministic for
    a given ``seed``.

    Examples
    --------
    The difference of the mean x of two samples of 400 unit Gaussians: its std is √(2/400) = 0.071.

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.normal(size=(400, 2)), rng.normal(size=(400, 2)) + [1, 0]
    >>> r = bootstrap_distance(P, Q, lambda A, B: B[:, 0].mean() - A[:, 0].mean(), n_boot=200)
    >>> round(r.mean, 2), round(r.std, 3)  # the shift of these samples, 1.11, and its error
    (1.11, 0.065)
    """
    P, Q = _as_points(P, "P"), _as_points(Q, "Q")
    check.function(fn, "fn")
    check.count(n_boot, "n_boot", 1)
    check.count(seed, "seed", 0)
    rng = np.random.default_rng(seed)
    draws = [
        fn(P[rng.integers(0, P.shape[0], P.shape[0])], Q[rng.integers(0, Q.shape[0], Q.shape[0])])
        for _ in range(int(n_boot))
    ]
    return _mean_std(draws)


def _mean_std(draws) -> BootstrapResult:
    """Mean and std (ddof = 1; 0 for one draw) over draws of a scalar, an array or a tuple of them."""
    ddof = 1 if len(draws) > 1 else 0

    def one(vals):
        a = np.asarray(vals, dtype=float)
        mean, std = a.mean(axis=0), a.std(axis=0, ddof=ddof)
        return (float(mean), float(std)) if a.ndim == 1 else (mean, std)

    if isinstance(draws[0], tuple):
        parts = [one([d[k] for d in draws]) for k in range(len(draws[0]))]
        return BootstrapResult(tuple(m for m, _ in parts), tuple(s for _, s in parts))
    return BootstrapResult(*one(draws))


def split_half_noise(P, Q, fn: Callable, m: int | None = None, n_splits: int = 8, seed: int = 0) -> BootstrapResult:
    """split_half_noise(P, Q, fn, m=None, n_splits=8, seed=0) -> BootstrapResult(mean, std).

    Finite-sample noise floor of the distance ``fn`` at the sample size m
    (default ⌊min(n_P, n_Q)/2⌋) for a comparison of P with Q: over
    ``n_splits`` random splits of each set into disjoint halves P1, P2 and
    Q1, Q2 of m points, the mean and std of ½ (fn(P1, P2) + fn(Q1, Q2)) — the
    value of fn for two sets that agree perfectly, each as large as the
    halves :func:`distance_vs_scale` compares. The splits are those of
    :func:`distance_vs_scale` with the same ``seed`` and ``m``.

    Examples
    --------
    Two uniform samples on the unit square, Hellinger at ε = 0.25 (B = 16 boxes): the floor at m = 500 points is
    near √(B/8 · 2/m) = 0.089.

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((1000, 2)), rng.random((1000, 2))
    >>> r = split_half_noise(P, Q, lambda A, B: histogram_distance(A, B, 0.25, (0, 1, 0, 1)))
    >>> round(r.mean, 2)
    0.09
    """
    P, Q = _as_points(P, "P"), _as_points(Q, "Q")
    check.function(fn, "fn")
    if m is not None:
        check.count(m, "m", 1)
    check.count(n_splits, "n_splits", 1)
    check.count(seed, "seed", 0)
    m = _common_m(P, Q, m)
    rng = np.random.default_rng(seed)
    vals = [0.5 * (fn(P1, P2) + fn(Q1, Q2)) for P1, P2, Q1, Q2 in _split_halves(P, Q, m, int(n_splits), rng)]
    return _mean_std(vals)


def split_half_baseline(P, fn: Callable, n_splits: int = 20, seed: int = 0, size: int | None = None) -> BootstrapResult:
    """split_half_baseline(P, fn, n_splits=20, seed=0, size=None) -> BootstrapResult(mean, std).

    Finite-sample noise floor of the distance ``fn``: mean and std (ddof = 1)
    of fn(A, B) over ``n_splits`` random splits of P into two disjoint
    subsets A, B of ``size`` points each (default ⌊n/2⌋).  A and B are
    independent samples of the same distribution, so fn(A, B) is what fn
    returns for two sets that agree perfectly at that sample size.  Compare
    with fn on two *different* sets subsampled to the same size (as
    :func:`distance_vs_scale` does), since the floor decreases with size
    (for Hellinger with well-filled boxes, E[H²] ≈ B/8 · (1/n_A + 1/n_B)).
    Deterministic for a given ``seed``.

    Examples
    --------
    Halves of 500 points of a uniform sample, Hellinger at ε = 0.25 (B = 16 boxes): near √(B/8 · 2/500) = 0.089.

    >>> P = np.random.default_rng(0).random((1000, 2))
    >>> r = split_half_baseline(P, lambda A, B: histogram_distance(A, B, 0.25, (0, 1, 0, 1)))
    >>> round(r.mean, 2)
    0.09
    """
    P = _as_points(P, "P")
    check.function(fn, "fn")
    check.count(n_splits, "n_splits", 1)
    check.count(seed, "seed", 0)
    h = P.shape[0] // 2 if size is None else check.count(size, "size", 1)
    if h < 1 or 2 * h > P.shape[0]:
        raise ConfigError(f"cannot split {P.shape[0]} points into two halves of {h}")
    rng = np.random.default_rng(seed)
    vals = np.empty(int(n_splits))
    for i in range(vals.size):
        perm = rng.permutation(P.shape[0])
        vals[i] = fn(P[perm[:h]], P[perm[h : 2 * h]])
    return BootstrapResult(float(vals.mean()), float(vals.std(ddof=1)) if vals.size > 1 else 0.0)
