"""Measures of exit-basin maps: fractions, basin entropy, Wada test.

A *basin map* is a 2-D integer array of outcome labels on a regular grid of
initial conditions (e.g. the exit channel, settled, or still inside at
t_max: censored), one cell per initial condition.  One label value, ``outside``
(default −1), marks cells outside the energetically allowed region; those cells
are excluded from every measure here.  Cell (i, j) is row i, column j; lengths
are in cells unless stated.

Functions here are pure (arrays in, frozen result dataclasses or DataFrames
out; no file I/O, no integration, no plotting):

* :func:`basin_fractions` — fraction of the valid cells in each basin, with
  Wilson score intervals (:func:`~hhscatter.analysis.stats.intervals.wilson_interval`).
* :func:`basin_entropy`, :func:`basin_entropy_table` — basin entropy S_b and
  boundary basin entropy S_bb (Daza, Wagemakers, Georgeot, Guéry-Odelin and
  Sanjuán, Sci. Rep. 6, 31416 (2016)) at one box size or a table over box
  sizes, with the log 2 criterion.
* :func:`entropy_by_box` — S_b and S_bb at fixed physical box sides, so that
  maps of different resolutions compare like for like.
* :func:`wada_merging` — the merging method for the Wada property (Daza,
  Wagemakers and Sanjuán, Sci. Rep. 8, 9954 (2018)).

* :func:`box_counting_dimension` — the box-counting dimension of the boundary.

The uncertainty algorithm (f(ε), α, its cut-off) is in
:mod:`hhscatter.analysis.geometry.uncertainty`; the predicted cut-off in
:mod:`hhscatter.analysis.geometry.cutoff`.

Basin entropy
-------------
The map is cut into boxes of ``box`` × ``box`` cells (the last rows and
columns that do not fill a box are dropped).  In box i, with p_ij the
frequency of label j among its valid cells, the Gibbs entropy is
S_i = −Σ_j p_ij ln p_ij.  S_b is the mean of S_i over all N boxes, S_bb the
mean over the N_b *boundary* boxes (S_i > 0, i.e. more than one label).
Natural logarithms.  *Log 2 criterion* (Daza et al. 2016): S_bb > ln 2 is a
sufficient condition for a fractal boundary.  It is not necessary, and it
can never fire with two basins (then S_i ≤ ln 2 in every box); a smooth
boundary between two basins gives S_bb ≤ ln 2, with S_bb = ln 2 exactly for a
straight boundary through the middle of the boxes.

Errors: S_b and S_bb are means over boxes, so their standard errors are
those of a mean over boxes taken as the independent unit:
σ(S_b) = sd(S_i)/√N and, for the ratio S_bb = Σ S_i / N_b with N_b itself
random, the delta-method error √(Σ_b (S_i − S_bb)²/(N_b(N_b − 1))) over the
boundary boxes (the same as a bootstrap over boxes, to O(1/N)).  They
measure how S_b would scatter over other windows or grid offsets of a map
with the same statistics; neighbouring boundary boxes along one boundary
are correlated, so for smooth boundaries the error is a lower bound.

Wada test (merging method)
--------------------------
The boundary ∂B of the map is the set of valid cells with a valid
4-neighbour of another basin.  For each basin j the other basins are merged
into one, and ∂B_j, the boundary of that two-colour map, is computed
(∂B_j ⊆ ∂B).  A Wada boundary is the one boundary that does not change under
merging: ∂B_j = ∂B for every j.  On a grid, equality is tested up to a
dilation of r cells: for each cell of ∂B the Chebyshev (chessboard) distance
to ∂B_j is computed, and W(r), the fraction of ∂B within r of *every* ∂B_j, is
reported for r = 0 … r_max (a cell of ∂B between basins a and b lies on ∂B_a
and ∂B_b by construction, so W(r) asks whether the remaining basins are
within r cells).  The map is declared Wada when W(r_wada) ≥ 1 − tol.  The
test is repeated on the map subsampled every ``steps`` cells, and the growth
of the Hausdorff distance h (max over ∂B of the distance to ∂B_j, in cells of
each map) with the resolution is reported as the slope of ln h against
ln(resolution): about 1 when basins meet only at isolated points or curves
(h is then a fixed length in the plane, a number of cells proportional to
the resolution), about 0 for a Wada boundary (h stays at a few cells).

Limits at finite resolution: (i) structure finer than a cell is invisible, so
a Wada map shows cells of ∂B whose third basin is unresolved (W < 1 at small
r) and a map with only a few resolved layers of fine structure can look
Wada; (ii) three basins meeting at isolated points give W(r) > 0 near those
points, a fraction that shrinks as 1/resolution, so a small map of a
non-Wada boundary can pass at a generous r_wada — the subsampled maps show
this scaling; (iii) subsampling aliases structure a few cells wide (a Wada
map can lose W at a coarser step), so the verdict uses the full map only;
(iv) r_wada and tol are choices, stated with the result, not derived;
(v) the test is about the basins passed in ``basins``: cells of other labels
are treated as outside.

Units: box sizes, distances and r in grid cells (box sides in position units
in :func:`entropy_by_box`); entropies in nats.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy import ndimage

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.geometry.uncertainty import _int_labels, _positive_int
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import wilson_interval
from hhscatter.errors import ConfigError

__all__ = [
    "BasinEntropy",
    "BasinFractions",
    "BoxCountingDimension",
    "WadaTest",
    "basin_entropy",
    "basin_entropy_table",
    "basin_fractions",
    "box_counting_dimension",
    "commensurate_sides",
    "entropy_by_box",
    "every_kth_cell",
    "wada_merging",
]

LOG2 = math.log(2.0)


class _NoBoxes(ConfigError):
    """No box of the requested side has enough valid cells."""


# ---------------------------------------------------------------------------
# basin fractions
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class BasinFractions:
    """Result of :func:`basin_fractions`.

    basins (label values), counts (cells per basin), n (valid cells),
    n_outside (cells excluded), frac, lo, hi (Wilson interval at ±z), z.
    """

    basins: np.ndarray
    counts: np.ndarray
    n: int
    n_outside: int
    frac: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    z: float


def basin_fractions(labels, *, basins=None, outside: int = -1, z: float = 1.0) -> BasinFractions:
    """basin_fractions(labels, *, basins=None, outside=-1, z=1.0) -> BasinFractions(basins, counts, frac, lo, hi).

    Fraction of the valid cells of a basin map (any shape) in each basin, with
    Wilson score intervals at ±z (binomial: each cell an independent draw of
    the initial condition).  Cells labelled ``outside`` are excluded.
    ``basins``: the labels to report, in that order (absent ones get count 0);
    by default every label present, sorted.

    Examples
    --------
    Five valid cells (the −1 is outside the allowed region): two in basin 0, two in basin 1, one in basin 2.

    >>> r = basin_fractions([[0, 0, 1], [1, 2, -1]])
    >>> r.basins.tolist(), r.counts.tolist(), r.frac.tolist()
    ([0, 1, 2], [2, 2, 1], [0.4, 0.4, 0.2])
    """
    lab = _int_labels(labels, "labels")
    inside = lab != outside
    vals = lab[inside]
    if basins is None:
        keys = np.unique(vals)
    else:
        keys = np.asarray(basins, dtype=np.int64).ravel()
        if keys.size == 0 or np.unique(keys).size != keys.size:
            raise ConfigError(f"basins must be distinct labels, got {basins!r}")
        if np.any(keys == outside):
            raise ConfigError(f"basins must not contain the outside label {outside}")
    n = int(vals.size)
    if n == 0:
        raise ConfigError("labels has no valid cells (all are outside)")
    counts = np.array([np.count_nonzero(vals == k) for k in keys], dtype=np.int64)
    p, lo, hi = wilson_interval(counts, n, z)
    return BasinFractions(keys, counts, n, int(lab.size - n), p, lo, hi, float(z))


# ---------------------------------------------------------------------------
# basin entropy
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class BasinEntropy:
    """Result of :func:`basin_entropy` (entropies in nats).

    box (side in cells), n_boxes (N, boxes counted), n_boundary (N_b, boxes
    with more than one label), n_basins (N_A, labels present in the counted
    boxes), S_b, S_b_err, S_bb (NaN when N_b = 0), S_bb_err, log2_fractal
    (S_bb > ln 2: the sufficient condition for a fractal boundary),
    log2_z = (S_bb − ln 2)/S_bb_err; box_entropy: S_i of every counted box.
    """

    box: int
    n_boxes: int
    n_boundary: int
    n_basins: int
    S_b: float
    S_b_err: float
    S_bb: float
    S_bb_err: float
    log2_fractal: bool
    log2_z: float
    box_entropy: np.ndarray = field(repr=False)


def basin_entropy(labels, box: int, *, outside: int = -1, min_valid: float = 1.0) -> BasinEntropy:
    """basin_entropy(labels, box, *, outside=-1, min_valid=1.0) -> BasinEntropy(S_b, S_bb, n_boundary, log2_fractal, ...).

    Basin entropy S_b and boundary basin entropy S_bb of the 2-D basin map
    ``labels`` with boxes of ``box`` × ``box`` cells (Daza et al. 2016; see
    the module notes for the definitions, the errors and the log 2
    criterion).  Frequencies in a box count its valid cells only; a box enters
    when at least a fraction ``min_valid`` of its cells is valid (1: only
    boxes wholly inside the allowed region, every box then holds box² cells).

    Examples
    --------
    A straight boundary through the middle of a column of 2 × 2 boxes: those 4 of the 16 boxes hold half of each
    basin, S_i = ln 2 = 0.6931, so S_bb = ln 2 and S_b = 4 ln 2 / 16 = 0.1733 (no sign of a fractal boundary).

    >>> lab = np.zeros((8, 8), int); lab[:, 5:] = 1
    >>> r = basin_entropy(lab, 2)
    >>> r.n_boxes, r.n_boundary, round(r.S_b, 4), round(r.S_bb, 4), r.log2_fractal
    (16, 4, 0.1733, 0.6931, False)
    """
    lab = _int_labels(labels, "labels", ndim=2)
    box = _positive_int(box, "box")
    H, W = lab.shape
    if box > min(H, W):
        raise ConfigError(f"box = {box} exceeds the map's shape {lab.shape}")
    if not 0.0 < float(min_valid) <= 1.0:
        raise ConfigError(f"min_valid must be in (0, 1], got {min_valid}")
    nr, nc = H // box, W // box
    blocks = lab[: nr * box, : nc * box].reshape(nr, box, nc, box).transpose(0, 2, 1, 3).reshape(nr * nc, box * box)
    valid = blocks != outside
    keys, inv = np.unique(blocks[valid], return_inverse=True)
    code = np.full(blocks.shape, keys.size, dtype=np.int64)  # keys.size marks outside
    code[valid] = inv.ravel()
    nk = keys.size + 1
    counts = np.bincount(
        (np.arange(blocks.shape[0])[:, None] * nk + code).ravel(), minlength=blocks.shape[0] * nk
    ).reshape(blocks.shape[0], nk)[:, : keys.size]
    nvalid = counts.sum(axis=1)
    keep = (nvalid > 0) & (nvalid >= float(min_valid) * box * box - 1e-9)
    counts, nvalid = counts[keep], nvalid[keep]
    N = int(counts.shape[0])
    if N == 0:
        raise _NoBoxes(f"labels: no box of {box}×{box} cells has enough valid cells (min_valid = {min_valid})")
    p = counts / nvalid[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        S = -np.sum(np.where(p > 0, p * np.log(p), 0.0), axis=1)
    S = np.maximum(S, 0.0)
    bnd = np.count_nonzero(counts, axis=1) > 1
    Nb = int(np.count_nonzero(bnd))
    S_b = float(S.mean())
    S_b_err = float(S.std(ddof=1) / math.sqrt(N)) if N > 1 else math.nan
    if Nb > 0:
        Sb_vals = S[bnd]
        S_bb = float(Sb_vals.mean())
        S_bb_err = float(math.sqrt(np.sum((Sb_vals - S_bb) ** 2) / (Nb * (Nb - 1)))) if Nb > 1 else math.nan
    else:
        S_bb, S_bb_err = math.nan, math.nan
    n_basins = int(np.count_nonzero(counts.sum(axis=0)))
    fractal = bool(Nb > 0 and S_bb > LOG2)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = float((S_bb - LOG2) / S_bb_err) if Nb > 1 and S_bb_err > 0 else math.nan
    return BasinEntropy(box, N, Nb, n_basins, S_b, S_b_err, S_bb, S_bb_err, fractal, z, S)


def basin_entropy_table(
    labels, boxes=(2, 3, 4, 5, 8, 10, 16), *, outside: int = -1, min_valid: float = 1.0
) -> pd.DataFrame:
    """basin_entropy_table(labels, boxes=(2, 3, 4, 5, 8, 10, 16), *, outside=-1, min_valid=1.0) -> DataFrame.

    :func:`basin_entropy` at each box side in ``boxes`` (those larger than the
    map are skipped), one row each: box, n_boxes, n_boundary, n_basins, S_b,
    S_b_err, S_bb, S_bb_err, log2_fractal, log2_z (n_boxes = 0 and NaN
    entropies where no box has enough valid cells).  For a fractal boundary
    S_b grows with the box side as box^{α} (Daza et al. 2016, α the
    uncertainty exponent), for a smooth one linearly.

    Examples
    --------
    The straight boundary of :func:`basin_entropy` at two box sides: with boxes of 4 × 4 cells the boundary
    column holds 1/4 and 3/4, S_i = −¼ ln ¼ − ¾ ln ¾ = 0.5623 in 2 of the 4 boxes.

    >>> lab = np.zeros((8, 8), int); lab[:, 5:] = 1
    >>> basin_entropy_table(lab, (2, 4))[["box", "n_boxes", "n_boundary", "S_b", "S_bb"]].round(4).values.tolist()
    [[2.0, 16.0, 4.0, 0.1733, 0.6931], [4.0, 4.0, 2.0, 0.2812, 0.5623]]
    """
    lab = _int_labels(labels, "labels", ndim=2)
    sizes = [_positive_int(b, "boxes") for b in np.atleast_1d(boxes)]
    cols = ("box", "n_boxes", "n_boundary", "n_basins", "S_b", "S_b_err", "S_bb", "S_bb_err", "log2_fractal", "log2_z")
    rows = []
    for b in sizes:
        if b > min(lab.shape):
            continue
        try:
            r = basin_entropy(lab, b, outside=outside, min_valid=min_valid)
        except _NoBoxes:  # every box of this side has too many outside cells: a row of NaN
            rows.append(
                {
                    "box": b,
                    "n_boxes": 0,
                    "n_boundary": 0,
                    "n_basins": 0,
                    "S_b": math.nan,
                    "S_b_err": math.nan,
                    "S_bb": math.nan,
                    "S_bb_err": math.nan,
                    "log2_fractal": False,
                    "log2_z": math.nan,
                }
            )
            continue
        rows.append({k: getattr(r, k) for k in cols})
    if not rows:
        raise ConfigError(f"boxes: no box side ≤ the map's shape {lab.shape}")
    return pd.DataFrame(rows)


# ---------------------------------------------------------------------------
# Wada test: merging method
# ---------------------------------------------------------------------------
@dataclass(frozen=True)
class WadaTest:
    """Result of :func:`wada_merging` (distances in cells of the full map).

    wada (verdict: W(r_wada) ≥ 1 − tol on the full map), basins,
    r (0 … r_max), wada_fraction W(r) at full resolution (fraction of ∂B
    within r of every ∂B_j), covered (per basin j, fraction of ∂B within r of
    ∂B_j; shape (basins, r)), hausdorff (per basin, max over ∂B of the
    distance to ∂B_j, inf when ∂B_j is empty), n_boundary (cells of ∂B),
    r_wada, tol; hausdorff_slope (slope of ln max h against ln resolution
    over the steps: ≈ 1 not Wada, ≈ 0 Wada; NaN with one step);
    by_resolution: one row per subsampling step (step, shape, n_boundary,
    wada_fraction at r_wada, hausdorff = max h in cells of that map).
    """

    wada: bool
    basins: np.ndarray
    r: np.ndarray
    wada_fraction: np.ndarray
    covered: np.ndarray
    hausdorff: np.ndarray
    n_boundary: int
    r_wada: int
    tol: float
    hausdorff_slope: float
    by_resolution: pd.DataFrame = field(repr=False)


def _boundary_distances(lab, keys, outside_code):
    """∂B mask and, for each basin, the chessboard distance of every cell to ∂B_j."""
    bnd = np.zeros(lab.shape, dtype=bool)
    per = [np.zeros(lab.shape, dtype=bool) for _ in keys]
    for axis in (0, 1):
        a = np.take(lab, np.arange(lab.shape[axis] - 1), axis=axis)
        b = np.take(lab, np.arange(1, lab.shape[axis]), axis=axis)
        both = (a != outside_code) & (b != outside_code)
        diff = both & (a != b)
        lo = [slice(None)] * 2
        hi = [slice(None)] * 2
        lo[axis] = slice(0, -1)
        hi[axis] = slice(1, None)
        bnd[tuple(lo)] |= diff
        bnd[tuple(hi)] |= diff
        for j, m in enumerate(per):
            dj = both & ((a == j) != (b == j))
            m[tuple(lo)] |= dj
            m[tuple(hi)] |= dj
    dist = []
    for m in per:
        if m.any():
            dist.append(ndimage.distance_transform_cdt(~m, metric="chessboard")[bnd].astype(float))
        else:
            dist.append(np.full(int(bnd.sum()), np.inf))
    return bnd, np.array(dist).reshape(len(keys), -1)


def wada_merging(
    labels, *, basins=None, outside: int = -1, r_max: int = 10, r_wada: int = 3, tol: float = 0.01, steps=(1, 2, 4)
) -> WadaTest:
    """wada_merging(labels, *, basins=None, outside=-1, r_max=10, r_wada=3, tol=0.01, steps=(1, 2, 4)) -> WadaTest(wada, r, wada_fraction, ...).

    The merging method of Daza, Wagemakers and Sanjuán (2018) on the 2-D
    basin map ``labels`` (see the module notes for the definitions and the
    limits at finite resolution).  ``basins``: the labels tested (at least 3;
    default every label present), cells of other labels count as outside.
    The verdict is W(r_wada) ≥ 1 − tol on the full map; the test is repeated
    on the map subsampled every ``steps`` cells (1 must be among them) for the
    resolution scaling of the Hausdorff distance.

    Examples
    --------
    Three vertical stripes: each boundary separates two basins only, so no boundary cell is near all three
    (W(3) = 0): not Wada.

    >>> lab = np.repeat([[0] * 10 + [1] * 10 + [2] * 10], 30, axis=0)
    >>> r = wada_merging(lab)
    >>> r.wada, r.n_boundary, float(r.wada_fraction[3])
    (False, 120, 0.0)
    """
    lab = _int_labels(labels, "labels", ndim=2)
    r_max = _positive_int(r_max, "r_max", 0)
    r_wada = _positive_int(r_wada, "r_wada", 0)
    if r_wada > r_max:
        raise ConfigError(f"r_wada = {r_wada} exceeds r_max = {r_max}")
    if not 0.0 <= float(tol) < 1.0:
        raise ConfigError(f"tol must be in [0, 1), got {tol}")
    st = sorted({_positive_int(s, "steps") for s in np.atleast_1d(steps)})
    if st[0] != 1:
        raise ConfigError(f"steps must include 1 (the full map), got {steps!r}")
    present = np.unique(lab[lab != outside])
    keys = present if basins is None else np.asarray(basins, dtype=np.int64).ravel()
    if keys.size < 3 or np.unique(keys).size != keys.size or np.any(keys == outside):
        raise ConfigError(f"basins must be ≥ 3 distinct labels other than outside, got {keys.tolist()!r}")
    # recode: basin j → j, anything else → −1
    code = np.full(lab.shape, -1, dtype=np.int64)
    for j, key in enumerate(keys):
        code[lab == key] = j
    r = np.arange(r_max + 1)
    rows = []
    full = None
    for s in st:
        sub = code[::s, ::s]
        bnd, dist = _boundary_distances(sub, range(keys.size), -1)
        nb = int(bnd.sum())
        if nb == 0:
            if s == 1:
                raise ConfigError("labels: the map has no boundary between the basins tested")
            rows.append(
                {"step": s, "shape": sub.shape, "n_boundary": 0, "wada_fraction": math.nan, "hausdorff": math.nan}
            )
            continue
        dmax = dist.max(axis=0)
        W = np.array([np.mean(dmax <= ri) for ri in r])
        haus = dist.max(axis=1)
        rows.append(
            {
                "step": s,
                "shape": sub.shape,
                "n_boundary": nb,
                "wada_fraction": float(W[r_wada]),
                "hausdorff": float(haus.max()),
            }
        )
        if s == 1:
            covered = np.array([[np.mean(d <= ri) for ri in r] for d in dist])
            full = (W, covered, haus, nb)
    table = pd.DataFrame(rows)
    W, covered, haus, nb = full
    wada = bool(W[r_wada] >= 1.0 - float(tol))
    h = table["hausdorff"].to_numpy(dtype=float)
    ok = np.isfinite(h) & (h > 0)
    slope = (
        float(np.polyfit(-np.log(table["step"].to_numpy(float)[ok]), np.log(h[ok]), 1)[0])
        if np.count_nonzero(ok) >= 2
        else math.nan
    )
    return WadaTest(wada, keys, r, W, covered, haus, nb, r_wada, float(tol), slope, table)


@dataclass(frozen=True)
class BoxCountingDimension:
    """Result of :func:`box_counting_dimension`: dimension D (slope of ln N(s) against ln(1/s)), its error,
    the box sizes (cells) and counts N(s) of boxes that hold the boundary."""

    D: float
    D_err: float
    sizes: np.ndarray
    counts: np.ndarray


def box_counting_dimension(labels, sizes=(2, 4, 8, 16, 32), *, outside: int = -1) -> BoxCountingDimension:
    """box_counting_dimension(labels, sizes) -> BoxCountingDimension(D, D_err, sizes, counts).

    Box-counting dimension of the basin boundary of a 2-D map: N(s), the
    number of s × s boxes that hold cells of more than one valid label, scales
    as s^{−D}; D is the least-squares slope of ln N against ln(1/s) and D_err
    its standard error from the scatter about the line (a fit error, not a
    sampling one).  Boxes with any ``outside`` cell are left out.  The
    resolution bounds what it sees: sizes must be ≥ 2 cells.

    Examples
    --------
    >>> lab = np.zeros((64, 64), int); lab[:, 33:] = 1
    >>> round(box_counting_dimension(lab, (2, 4, 8)).D, 3)
    1.0
    """
    lab = _int_labels(labels, "labels", ndim=2)
    s = np.array(sorted({_positive_int(v, "sizes", 2) for v in np.atleast_1d(sizes)}))
    if s.size < 2:
        raise ConfigError("sizes: need at least 2 box sizes")
    counts = []
    for b in s:
        nr, nc = lab.shape[0] // b, lab.shape[1] // b
        if nr == 0 or nc == 0:
            raise ConfigError(f"sizes: box {b} exceeds the map {lab.shape}")
        blk = lab[: nr * b, : nc * b].reshape(nr, b, nc, b).transpose(0, 2, 1, 3).reshape(nr, nc, -1)
        valid = (blk != outside).all(axis=-1)
        mixed = blk.min(axis=-1) != blk.max(axis=-1)
        counts.append(int(np.count_nonzero(valid & mixed)))
    counts = np.array(counts)
    if np.any(counts == 0):
        raise ConfigError("box_counting_dimension: no boundary at some box size")
    x, y = np.log(1.0 / s), np.log(counts)
    (slope, _), cov = np.polyfit(x, y, 1, cov=True) if s.size > 2 else (np.polyfit(x, y, 1), np.zeros((2, 2)))
    return BoxCountingDimension(float(slope), float(math.sqrt(cov[0, 0])), s, counts)


def commensurate_sides(sides, extent, n: int, *, min_cells: int = 2) -> list:
    """commensurate_sides(sides, extent, n, min_cells=2) -> the box sides (position units) that are a whole number
    (≥ ``min_cells``) of the cells of an n × n map over ``extent`` = (x0, x1, y0, y1), in the order given.

    Examples
    --------
    >>> commensurate_sides([0.01, 0.025, 0.05], (-1, 1, -1, 1), 200)
    [0.05]
    """
    sides = check.numbers(sides, "sides", positive=True)
    _checks.extent(extent)
    _checks.whole(n, "n")
    _checks.whole(min_cells, "min_cells", 0)
    cell = _cell_side(extent, n)
    out = []
    for s in sides:
        c = s / cell
        if abs(c - round(c)) <= 1e-9 * max(1.0, c) and round(c) >= min_cells:
            out.append(float(s))
    return out


def _cell_side(extent, n: int) -> float:
    x0, x1, y0, y1 = (float(v) for v in extent)
    n = _positive_int(n, "n")
    cx, cy = (x1 - x0) / n, (y1 - y0) / n
    if not (cx > 0 and abs(cx - cy) <= 1e-12 * cx):
        raise ConfigError(f"extent {tuple(extent)} with {n} cells per side does not give square cells")
    return cx


def entropy_by_box(labels, extent, sides, *, outside: int = -1, min_valid: float = 1.0) -> pd.DataFrame:
    """entropy_by_box(labels, extent, sides, *, outside=-1) -> DataFrame: S_b and S_bb at fixed physical box sides.

    :func:`basin_entropy` of the square map ``labels`` (n × n cells over
    ``extent`` = (x0, x1, y0, y1), position units) with boxes of side s in
    position units for each s in ``sides``: box_cells = s / cell side, which
    must be a whole number ≥ 1 (see :func:`commensurate_sides`; ValueError
    naming the side otherwise).  A box of 5 cells is 0.025 wide on a 400² map
    of [−1, 1]² and 0.005 on a 2000² one: S_b and S_bb depend on that size
    (S_b ∝ s^α for a fractal boundary), so maps of different resolutions are
    compared at the same s, not the same number of cells.  One row per side:
    grid (n), box_side, box_cells, n_boxes, n_boundary, S_b, S_b_err, S_bb,
    S_bb_err (nats; errors as in :func:`basin_entropy`).

    Examples
    --------
    >>> lab = np.zeros((40, 40), int); lab[:, 20:] = 1
    >>> t = entropy_by_box(lab, (-1, 1, -1, 1), [0.1, 0.2])
    >>> t[["box_cells", "n_boundary"]].values.tolist()
    [[2, 0], [4, 0]]
    """
    lab = _int_labels(labels, "labels", ndim=2)
    if lab.shape[0] != lab.shape[1]:
        raise ConfigError(f"labels must be a square map, got shape {lab.shape}")
    n = lab.shape[0]
    cell = _cell_side(extent, n)
    rows = []
    for s in np.atleast_1d(np.asarray(sides, dtype=float)):
        c = s / cell
        if not (abs(c - round(c)) <= 1e-9 * max(1.0, c) and round(c) >= 1):
            raise ConfigError(f"sides: {s:g} is {c:.4g} cells of the {n}² map, not a whole number")
        r = basin_entropy(lab, int(round(c)), outside=outside, min_valid=min_valid)
        rows.append(
            {
                "grid": n,
                "box_side": float(s),
                "box_cells": int(round(c)),
                "n_boxes": r.n_boxes,
                "n_boundary": r.n_boundary,
                "S_b": r.S_b,
                "S_b_err": r.S_b_err,
                "S_bb": r.S_bb,
                "S_bb_err": r.S_bb_err,
            }
        )
    return pd.DataFrame(
        rows, columns=["grid", "box_side", "box_cells", "n_boxes", "n_boundary", "S_b", "S_b_err", "S_bb", "S_bb_err"]
    )


def every_kth_cell(labels, subgrids) -> list:
    """every_kth_cell(labels, subgrids) -> [(k, sub-map)]: an n × n map read on every k-th cell, k = n / m for each
    m in ``subgrids`` that divides n with k odd and > 1.

    The sub-map's cell centres are cells of the map (its cell k//2, k//2 + k, …), so it holds the same orbits as an
    independent m × m map of the same extent: a coarser grid of the same data, to compare entropies of different
    resolutions at a fixed physical box side (:func:`entropy_by_box`) without a second simulation.  Grids that do
    not qualify (m not dividing n, k even or 1) are left out.

    Examples
    --------
    >>> lab = np.arange(36).reshape(6, 6)
    >>> [(k, sub.tolist()) for k, sub in every_kth_cell(lab, [2, 4, 6])]
    [(3, [[7, 10], [25, 28]])]
    """
    subgrids = [_checks.whole(m, "subgrids") for m in check.numbers(subgrids, "subgrids")]
    lab = np.asarray(labels)
    if isinstance(labels, (str, bytes, dict)) or lab.dtype.kind not in "biuf" or lab.ndim != 2 or lab.size == 0:
        raise ConfigError(f"labels must be a non-empty 2-D array (a map), got {type(labels).__name__}")
    out = []
    for m in subgrids:
        k, r = divmod(lab.shape[0], int(m))
        if k > 1 and r == 0 and k % 2 == 1:
            out.append((k, lab[k // 2 :: k, k // 2 :: k]))
    return out
