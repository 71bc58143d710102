"""Ulam's method on a section from one-return samples: transitions, κ and its convergence, measures, comparisons.

The operators themselves are in :mod:`hhscatter.analysis.geometry.transfer`; this module builds them from a
table of one-return samples (one row per sample point: its finest box ``cell``, stratum ``rank``, weight
``w``, whether it returned (``ret``), the return time ``T``, the image point ``x1, y1, e1`` and ``censored``)
and turns their results into records:

* :func:`sample_transitions` — the samples on boxes merged c × c, optionally the first M' per box, optionally
  on (box × energy bin) states;
* :func:`saddle_kappa` — κ on the chaotic saddle's class (its records, convergence and extrapolation:
  :mod:`hhscatter.analysis.geometry.ulam_convergence`);
* :func:`leading_modes`, :func:`measure_points`, :func:`reduced_operator` — spectra, c-measure samples and the
  operator on ρ(E) alone;
* :func:`empirical_survival`, :func:`survival_agreement`, :func:`t_star_energies` — the comparisons with a
  simulated ensemble.

Pure functions (tables and arrays in, records out). Units: box sides in position units, times in the
Hamiltonian's time unit, κ in 1/time.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.geometry import transfer as tf
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.intervals import fraction_with_bound
from hhscatter.errors import ConfigError

__all__ = [
    "t_star_distance",
    "dissipative_record",
    "dissipative_operator",
    "coarse_index",
    "disk_density",
    "eigenvector_convergence",
    "empirical_survival",
    "grid_shape",
    "hellinger_by_box",
    "hellinger_row",
    "islands_record",
    "leading_modes",
    "measure_points",
    "one_return_samples",
    "operator_survival",
    "reduced_operator",
    "reduced_survival",
    "saddle_kappa",
    "stratified_section_points",
    "sample_transitions",
    "survival_agreement",
    "t_star_energies",
]

#: the columns of a table of one-return samples (:func:`one_return_samples`)
_SAMPLE_COLUMNS = ("cell", "rank", "w", "censored", "ret", "T", "x1", "y1")


def _sample_table(tab, name: str, ebins: bool = False, *, t_end: bool = False):
    more = (("ebin", "e1") if ebins else ()) + (("t_end",) if t_end else ())
    return check.table(tab, name, _SAMPLE_COLUMNS + more)


def _partitions(tab, extent, box, coarsen=None, subsets=None, *, ebins: bool = False, t_end: bool = False):
    """The arguments that say which partitions of the one-return samples ``tab`` are built: the section's
    ``extent``, the finest box side ``box`` and, when given, the merging factors ``coarsen`` and the sample counts
    ``subsets``."""
    _sample_table(tab, "tab", ebins, t_end=t_end)
    _checks.extent(extent)
    check.number(box, "box", positive=True)
    if coarsen is not None:
        _checks.wholes(coarsen, "coarsen")
    if subsets is not None:
        _checks.wholes(subsets, "subsets")


def _transition_table(t, tr):
    check.table(t, "t", ("t_end", "x1", "y1", "e1"), min_rows=0)
    if len(t) != tr.src.size:
        raise ConfigError(f"t must have one row per sample of tr ({len(t)} vs {tr.src.size})")


def _state_ids(ids, tr) -> np.ndarray:
    """``ids`` as an int array, one id (≥ 0) per state of ``tr``."""
    if check.numbers(ids, "ids", min_size=0, minimum=0).size != tr.n_states:
        raise ConfigError(f"ids must have one id per state of tr ({np.size(ids)} vs {tr.n_states})")
    return _whole_ids(ids)


def _whole_ids(ids) -> np.ndarray:
    """``ids`` (numbers ≥ 0, checked) as an int array; ConfigError if one is not whole."""
    a = np.asarray(ids, dtype=float).ravel()
    if not np.all(a == np.round(a)):
        raise ConfigError(f"ids must hold whole numbers (state ids), got {ids!r}")
    return a.astype(np.int64)


def grid_shape(extent, box: float) -> tuple[int, int]:
    """Boxes per side (nx, ny) of side ``box`` covering ``extent`` = (x0, x1, y0, y1).

    Examples
    --------
    >>> grid_shape((-1.03, 1.03, -1.03, 1.03), 0.1)
    (21, 21)
    """
    _checks.extent(extent)
    check.number(box, "box", positive=True)
    x0, x1, y0, y1 = extent
    return int(math.ceil((x1 - x0) / box - 1e-9)), int(math.ceil((y1 - y0) / box - 1e-9))


def coarse_index(cell, nx: int, c: int):
    """Index of the c × c merged box holding finest box ``cell`` (row-major, ``nx`` finest boxes per row).

    Examples
    --------
    >>> coarse_index(np.array([0, 1, 4, 5, 15]), 4, 2).tolist()
    [0, 0, 0, 0, 3]
    """
    cell_ = check.numbers(cell, "cell", min_size=0, minimum=0)
    if not np.all(cell_ == np.round(cell_)):
        raise ConfigError("cell must hold box indices (integers ≥ 0)")
    _checks.whole(nx, "nx")
    _checks.whole(c, "c")
    ix, iy = cell % nx, cell // nx
    ncx = -(-nx // c)
    return (iy // c) * ncx + ix // c


def sample_transitions(tab: pd.DataFrame, extent, box: float, c: int = 1, m_max=None, ebins=None):
    """The one-return samples as :class:`~hhscatter.analysis.geometry.transfer.Transitions` on merged boxes.

    Boxes of side ``box`` (the finest, that of ``tab.cell``) merged c × c; only the first ``m_max`` ranks per
    finest box; censored samples dropped. With ``ebins`` (bin edges in energy; ``tab`` then has a column
    ``ebin``) the states are (box, energy bin): id = bin·n_cells + box. Returns (Transitions, state ids,
    the samples used).

    Examples
    --------
    Four samples in the two boxes of side ½ along y = 0 … ½: one of each box returns into the other, one escapes.

    >>> nan = float("nan")
    >>> tab = pd.DataFrame({"cell": [0, 0, 1, 1], "rank": [0, 1, 0, 1], "w": 1.0, "censored": False,
    ...                     "ret": [True, False, True, False], "T": [1.0, nan, 2.0, nan],
    ...                     "x1": [0.75, nan, 0.25, nan], "y1": [0.25, nan, 0.25, nan]})
    >>> tr, ids, used = sample_transitions(tab, (0, 1, 0, 1), 0.5)
    >>> ids.tolist(), tr.src.tolist(), tr.dst.tolist()
    ([0, 1], [0, 0, 1, 1], [1, -1, 0, -1])
    >>> sample_transitions(tab, (0, 1, 0, 1), 0.5, c=2)[0].dst.tolist()  # one merged box
    [0, -1, 0, -1]
    """
    _partitions(tab, extent, box, ebins=ebins is not None)
    _checks.whole(c, "c")
    if m_max is not None:
        _checks.whole(m_max, "m_max")
    if ebins is not None:
        check.numbers(ebins, "ebins", min_size=2)
    nx, ny = grid_shape(extent, box)
    mask = ~tab["censored"].to_numpy()
    if m_max is not None:
        mask &= tab["rank"].to_numpy() < m_max
    t = tab[mask]
    src = coarse_index(t["cell"].to_numpy(), nx, c)
    ret = t["ret"].to_numpy()
    cell1, _, _ = tf.box_index(np.where(ret, t["x1"], 0.0), np.where(ret, t["y1"], 0.0), extent, box)
    dst = np.where(ret & (cell1 >= 0), coarse_index(np.maximum(cell1, 0), nx, c), -1)
    if ebins is not None:
        n_cells = int(coarse_index(np.array([nx * ny - 1]), nx, c)[0]) + 1
        edges = ebins
        b1 = np.clip(np.searchsorted(edges, np.where(ret, t["e1"], edges[0]), side="right") - 1, 0, len(edges) - 2)
        src = t["ebin"].to_numpy() * n_cells + src
        dst = np.where(dst >= 0, b1 * n_cells + dst, -1)
    ids, inv = np.unique(np.concatenate([src, dst[dst >= 0]]), return_inverse=True)
    s_new = inv[: src.size]
    d_new = np.full(dst.size, -1)
    d_new[dst >= 0] = inv[src.size :]
    return tf.Transitions(s_new, d_new, np.where(ret, t["T"], 1.0), ids.size, t["w"].to_numpy()), ids, t


def saddle_kappa(tr):
    """κ on the chaotic saddle's class of ``tr``: (κ, κ per return, class info, keep mask, sub-Transitions).

    Examples
    --------
    The two boxes of :func:`sample_transitions`: half return, after T = 1 and T = 2, so κ = ln 4 / 3 = 0.4621
    per unit time and ln 2 = 0.6931 per return.

    >>> tr = tf.Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> kappa, per_return, info, keep, sub = saddle_kappa(tr)
    >>> round(kappa, 4), round(per_return, 4), info["saddle_states"], info["closed_classes"]
    (0.4621, 0.6931, 2, 0)
    """
    tf._transitions(tr)
    keep, classes = tf.saddle_class(tr)
    sub = tr.subset(keep)
    kappa = tf.true_time_kappa(sub)
    closed = [c for c in classes if c.closed]
    W = sum(c.weight for c in classes)
    info = {
        "states": int(tr.n_states),
        "saddle_states": int(keep.sum()),
        "classes": len(classes),
        "closed_classes": len(closed),
        "closed_states": int(sum(c.size for c in closed)),
        "closed_weight_share": float(sum(c.weight for c in closed) / W) if W > 0 else 0.0,
    }
    return kappa, tf.map_escape_rate(sub), info, keep, sub


def leading_modes(sub, trapped_sub, k: int = 4):
    """The ``k`` leading eigenvalues of P on the saddle's class and each mode's mass on the boxes
    ``trapped_sub`` (bool over sub's states: the censored boxes, whose KAM probe is still inside at its t_max):
    [{eigenvalue, eigenvalue_arg, mass_on_trapped_boxes}] (the key names the censored boxes as records always have).

    Examples
    --------
    P = [[½, ½], [¼, ¼]] (box 1 loses half its samples): eigenvalues ¾ and 0, left vectors (1, 1) and (1, −2).

    >>> sub = tf.Transitions([0, 0, 1, 1, 1, 1], [0, 1, 0, 1, -1, -1], np.ones(6), n_states=2)
    >>> modes = leading_modes(sub, [False, True], k=2)
    >>> [(round(m["eigenvalue"], 4), round(m["mass_on_trapped_boxes"], 4)) for m in modes]
    [(0.75, 0.5), (0.0, 0.6667)]
    """
    import scipy.linalg  # deferred: scipy loads on first use
    from scipy.sparse.linalg import eigs  # deferred: scipy loads on first use

    tf._transitions(sub, "sub")
    check.mask(trapped_sub, "trapped_sub", sub.n_states)
    _checks.whole(k, "k")
    P = tf.transfer_matrix(sub)
    if sub.n_states <= tf.DENSE_MAX:
        vals, vecs = scipy.linalg.eig(P.toarray().T)
    else:
        # a fixed start (ARPACK's own is random): the same eigenvalues in every run, not ≤ 1e-11 apart
        vals, vecs = eigs(
            P.T.tocsr(),
            k=min(k, sub.n_states - 2),
            which="LM",
            tol=1e-10,
            v0=np.full(sub.n_states, 1.0 / np.sqrt(sub.n_states)),
        )
    # by modulus, a conjugate pair (equal moduli up to rounding) with the positive argument first
    order = np.lexsort((-np.angle(vals), -np.round(np.abs(vals), 10)))
    modes = []
    for j in order[:k]:
        v = np.abs(vecs[:, j])
        v = v / v.sum()
        modes.append(
            {
                "eigenvalue": float(abs(vals[j])),
                "eigenvalue_arg": float(np.angle(vals[j])),
                "mass_on_trapped_boxes": float(v[trapped_sub].sum()),
            }
        )
    return modes


def measure_points(res, kind, n, rng):
    """n points drawn from the operator's measure on the section, carried one exact return forward.

    The samples' image points, weighted by ν (``kind`` = "flux"), by the sprinkler weight ("sprinkler": the
    first crossing after a late time) or by the map's c-measure ("map": left vector of P). ``res`` holds t
    (the samples), tr, keep and kappa of :func:`saddle_kappa`'s partition.

    Examples
    --------
    The two boxes of :func:`sample_transitions`: the map's c-measure weighs both images alike; the flux measure
    ν = (0.557, 0.443) (ν = ν M(κ) at κ = ln 4 / 3) gives box 1's image, after T = 2, ν_1 e^{2κ}/2 = 0.557.

    >>> nan = float("nan")
    >>> tab = pd.DataFrame({"cell": [0, 0, 1, 1], "rank": [0, 1, 0, 1], "w": 1.0, "censored": False,
    ...                     "ret": [True, False, True, False], "T": [1.0, nan, 2.0, nan],
    ...                     "x1": [0.75, nan, 0.25, nan], "y1": [0.25, nan, 0.25, nan]})
    >>> tr, ids, t = sample_transitions(tab, (0, 1, 0, 1), 0.5)
    >>> kappa, _, _, keep, _ = saddle_kappa(tr)
    >>> res = {"t": t, "tr": tr, "keep": keep, "kappa": kappa}
    >>> rng = np.random.default_rng(0)
    >>> [round(float(np.mean(measure_points(res, k, 20000, rng)[:, 0] == 0.25)), 2) for k in ("map", "flux")]
    [0.5, 0.56]
    """
    _checks.mapping(res, "res", ("t", "tr", "keep", "kappa"))
    if not isinstance(kind, str) or kind not in ("map", "sprinkler", "flux"):
        raise ConfigError(f"kind must be 'map', 'sprinkler' or 'flux', got {kind!r}")
    _checks.whole(n, "n")
    _checks.generator(rng)
    t, tr = res["t"], res["tr"]
    # the left Perron vectors of the *whole* matrix: the saddle's class and the boxes downstream of it (orbits
    # on their way out, which cross the section too); upstream boxes get 0
    rw = tr.row_weight
    if kind == "map":
        p, _ = tf.saddle_measure(tr, 0.0, res["keep"])
        w = np.where(tr.dst >= 0, p[tr.src] * tr.w / rw[tr.src], 0.0)
    else:
        nu, _ = tf.saddle_measure(tr, res["kappa"], res["keep"])
        if kind == "sprinkler":
            w = tf.sprinkler_weights(tr, nu, res["kappa"])
        else:
            w = np.where(tr.dst >= 0, nu[tr.src] * tr.w / rw[tr.src] * np.exp(res["kappa"] * tr.T), 0.0)
    idx = rng.choice(w.size, size=n, p=w / w.sum())
    return np.column_stack([t["x1"].to_numpy()[idx], t["y1"].to_numpy()[idx]])


def reduced_operator(tr, ids, n_cells, n_bins):
    """The operator on ρ(E) alone: each energy bin's section distribution frozen to its c-measure ν_a (left
    vector of the bin's own box operator at its root κ_a). ``tr`` on (box × bin) states with ids
    bin·n_cells + box. Returns (Transitions over bins, per-bin κ_a).

    Examples
    --------
    One energy bin over the two boxes of :func:`saddle_kappa`: the bin's operator, with the boxes frozen to its
    c-measure, has the same root κ = ln 4 / 3 = 0.4621.

    >>> tr = tf.Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> tr_bins, kappas = reduced_operator(tr, [0, 1], n_cells=2, n_bins=1)
    >>> round(kappas[0], 4), round(tf.true_time_kappa(tr_bins), 4)
    (0.4621, 0.4621)
    """
    tf._transitions(tr)
    ids = _state_ids(ids, tr)
    _checks.whole(n_cells, "n_cells")
    _checks.whole(n_bins, "n_bins")
    box_of = ids % n_cells
    bin_of = ids // n_cells
    w_red = np.zeros(tr.src.size)
    kappas = []
    for a in range(n_bins):
        sel = bin_of[tr.src] == a
        if not sel.any():
            kappas.append(math.nan)
            continue
        src_box = box_of[tr.src[sel]]
        dst_box = np.where(tr.dst[sel] >= 0, box_of[np.maximum(tr.dst[sel], 0)], -1)
        u, inv = np.unique(np.concatenate([src_box, dst_box[dst_box >= 0]]), return_inverse=True)
        d = np.full(dst_box.size, -1)
        d[dst_box >= 0] = inv[src_box.size :]
        tra = tf.Transitions(inv[: src_box.size], d, tr.T[sel], u.size, tr.w[sel])
        try:
            keep, _ = tf.saddle_class(tra)
            ka = tf.true_time_kappa(tra.subset(keep))
            nu, _ = tf.saddle_measure(tra, ka, keep)  # the class and the boxes downstream of it
        except ValueError:  # no leak at all in this bin (cannot happen with drag; kept honest)
            ka, nu = math.nan, np.full(u.size, 1.0 / u.size)
        kappas.append(ka)
        rw = tra.row_weight
        w_red[sel] = nu[tra.src] * tra.w / np.where(rw[tra.src] > 0, rw[tra.src], 1.0)
    dst_bin = np.where(tr.dst >= 0, bin_of[np.maximum(tr.dst, 0)], -1)
    return tf.Transitions(bin_of[tr.src], dst_bin, tr.T, n_bins, w_red), kappas


def empirical_survival(t_end, leaving, grid):
    """Share of orbits not gone (escaped/settled) by each grid time; censored orbits count as alive.

    Examples
    --------
    >>> empirical_survival([1.0, 2.0, 5.0], [True, True, False], [0.0, 1.5, 3.0]).tolist()
    [1.0, 0.6666666666666667, 0.33333333333333337]
    """
    n = check.numbers(t_end, "t_end").size
    check.mask(leaving, "leaving", n)
    check.numbers(grid, "grid", min_size=0)
    te = np.sort(np.asarray(t_end)[np.asarray(leaving)])
    return 1.0 - np.searchsorted(te, grid, side="right") / len(t_end)


def survival_agreement(grid, dt, t_star, P_sim, P_op, P_red, N):
    """P(t) of operator and reduced operator against the simulation: values at fixed times and the rms/max
    |ln(P/P_sim)| where P_sim·N ≥ 30 (also the time up to which that holds). A simulated P of 0 (no orbit of N
    left) is written with its one-sided 95 % upper bound ``sim_upper`` and no error
    (:func:`~hhscatter.analysis.stats.intervals.fraction_with_bound`).

    Examples
    --------
    A simulated P = e^{−t/10} of 1000 orbits against an operator 10 % too fast: |ln(P_op/P_sim)| = 0.01 t, at most
    0.1 at t = 10.

    >>> grid = np.arange(11.0)
    >>> r = survival_agreement(grid, 1.0, 5.0, np.exp(-grid / 10), np.exp(-grid / 9.09), np.exp(-grid / 10), 1000)
    >>> round(r["lnP_max_operator"], 3), round(r["lnP_max_reduced"], 3), r["compared_until"]
    (0.1, 0.0, 10.0)
    """
    grid_ = check.numbers(grid, "grid", minimum=0.0)
    check.number(dt, "dt", positive=True)
    check.number(t_star, "t_star")
    for name, P in (("P_sim", P_sim), ("P_op", P_op), ("P_red", P_red)):
        if check.numbers(P, name, minimum=0.0).size != grid_.size:
            raise ConfigError(f"{name} must have one value per time of grid ({np.size(P)} vs {grid_.size})")
    _checks.whole(N, "N")
    grid, P_sim, P_op, P_red = (np.asarray(a, dtype=float).ravel() for a in (grid, P_sim, P_op, P_red))
    ok = P_sim * N >= 30
    lr = np.log(np.where(ok, P_op, 1.0) / np.where(ok, P_sim, 1.0))
    lr2 = np.log(np.where(ok, np.maximum(P_red, 1e-300), 1.0) / np.where(ok, P_sim, 1.0))
    t_ok = grid[ok]
    sig = np.sqrt(np.maximum(P_sim * (1 - P_sim), 0.0) / N)
    at = [5.0, 10.0, t_star, 25.0, 40.0, 60.0, 80.0, 100.0, 150.0]
    at = [a for a in at if a <= grid[-1]]
    ix = [int(round(a / dt)) for a in at]
    return {
        "P_at": [
            {
                "t": a,
                **(
                    fraction_with_bound(round(P_sim[i] * N), N).record("sim")  # none left: its 95 % bound, not 0 ± 0
                    if P_sim[i] * N < 0.5
                    else {"sim": float(P_sim[i]), "sim_err": float(sig[i])}
                ),
                "operator": float(P_op[i]),
                "reduced": float(P_red[i]),
            }
            for a, i in zip(at, ix)
        ],
        "lnP_rms_operator": float(np.sqrt(np.mean(lr[ok] ** 2))) if ok.any() else math.nan,
        "lnP_rms_reduced": float(np.sqrt(np.mean(lr2[ok] ** 2))) if ok.any() else math.nan,
        "lnP_max_operator": float(np.max(np.abs(lr[ok]))) if ok.any() else math.nan,
        "lnP_max_reduced": float(np.max(np.abs(lr2[ok]))) if ok.any() else math.nan,
        "compared_until": float(t_ok[-1]) if ok.any() else math.nan,
    }


def t_star_energies(pred, sim_pts):
    """Mean and spread of the energy at the first crossing after t*: operator (weighted) and simulation.

    Examples
    --------
    Operator points at E = 0.1 and 0.2 weighted 1 : 3 (mean 0.175, spread 0.1·√(¼·¾) = 0.0433):

    >>> pred = pd.DataFrame({"w": [1.0, 3.0], "energy": [0.1, 0.2]})
    >>> r = t_star_energies(pred, pd.DataFrame({"energy": [0.15, 0.2]}))
    >>> round(r["t_star_mean_energy"]["operator"], 4), round(r["t_star_std_energy"]["operator"], 4)
    (0.175, 0.0433)
    >>> round(r["t_star_mean_energy"]["sim"], 4), r["t_star_points_sim"]
    (0.175, 2)
    """
    check.table(pred, "pred", ("w", "energy"))
    if not np.sum(pred["w"]) > 0:
        raise ConfigError("pred: the weights w must not all be 0")
    check.table(sim_pts, "sim_pts", ("energy",), min_rows=0)
    wE = pred["w"] / pred["w"].sum()
    mE_pred = float(np.sum(wE * pred["energy"]))
    sE_pred = float(np.sqrt(np.sum(wE * (pred["energy"] - mE_pred) ** 2)))
    return {
        "t_star_points_sim": int(len(sim_pts)),
        "t_star_mean_energy": {
            "operator": mE_pred,
            "sim": float(sim_pts["energy"].mean()) if len(sim_pts) else math.nan,
            "sim_err": float(sim_pts["energy"].std() / math.sqrt(max(len(sim_pts), 1))),
        },
        "t_star_std_energy": {
            "operator": sE_pred,
            "sim": float(sim_pts["energy"].std()) if len(sim_pts) > 1 else math.nan,
        },
    }


def hellinger_by_box(P, Q, boxes, extent, n_splits, seed, head):
    """Debiased Hellinger distance between point sets P and Q over box sizes
    (:func:`~hhscatter.analysis.geometry.distance.distance_vs_scale`): (table with hellinger_debiased, lo, hi;
    index of the box nearest ``head``).

    Examples
    --------
    The checkerboard of :func:`~hhscatter.analysis.geometry.distance.distance_vs_scale` (H = 0.541 at ε = 0.1):

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((2000, 2)), rng.random((4000, 2))
    >>> Q = Q[np.floor(Q / 0.1).sum(axis=1) % 2 == 0]
    >>> tab, j = hellinger_by_box(P, Q, [0.5, 0.2, 0.1], (0, 1, 0, 1), n_splits=8, seed=0, head=0.1)
    >>> j, tab["hellinger_debiased"].round(2).tolist()
    (2, [0.01, 0.02, 0.54])
    """
    check.count(n_splits, "n_splits", 1)
    check.number(head, "head", positive=True)
    tab = dist.distance_vs_scale(P, Q, boxes, extent, n_splits=n_splits, seed=seed)
    d, lo, hi = dist.debiased_distance(tab, "hellinger")
    j = int(np.argmin(np.abs(tab["box"].to_numpy() - head)))
    return tab.assign(hellinger_debiased=d, lo=lo, hi=hi), j


def disk_density(radius, extent, box, ids, n_cells, top_bin, n_grid=600):
    """A density uniform in the disk r < ``radius`` on the section, on the (box × energy bin) states ``ids``
    (id = bin·n_cells + box) of the top energy bin: (n0 normalised, share of the disk on no state).

    Examples
    --------
    The unit disk on four boxes of side 1 around the origin, a quarter in each; without box 3 among the states,
    its quarter is lost:

    >>> n0, lost = disk_density(1.0, (-1, 1, -1, 1), 1.0, np.array([0, 1, 2, 3]), 4, 0)
    >>> np.round(n0, 4).tolist(), round(lost, 4)
    ([0.25, 0.25, 0.25, 0.25], 0.0)
    >>> n0, lost = disk_density(1.0, (-1, 1, -1, 1), 1.0, np.array([0, 1, 2]), 4, 0)
    >>> np.round(n0, 4).tolist(), round(lost, 4)
    ([0.3333, 0.3333, 0.3333], 0.25)
    """
    check.number(radius, "radius", positive=True)
    _checks.extent(extent)
    check.number(box, "box", positive=True)
    ids = _whole_ids(check.numbers(ids, "ids", minimum=0))
    _checks.whole(n_cells, "n_cells")
    _checks.whole(top_bin, "top_bin", 0)
    _checks.whole(n_grid, "n_grid")
    g = (np.arange(n_grid) + 0.5) / n_grid * 2 * radius - radius
    X, Y = np.meshgrid(g, g)
    inside = np.hypot(X, Y) < radius
    cell, _, _ = tf.box_index(X[inside], Y[inside], extent, box)
    state = top_bin * n_cells + cell
    pos = np.searchsorted(ids, state)
    ok = (pos < ids.size) & (ids[np.minimum(pos, ids.size - 1)] == state)
    n0 = np.bincount(pos[ok], minlength=ids.size).astype(float)
    if not n0.sum() > 0:
        raise ConfigError(f"radius: the disk r < {radius} lies on no state of energy bin {top_bin} (ids)")
    return n0 / n0.sum(), float(1 - ok.mean())


def operator_survival(tr, t, n0, dt, steps, k_star, max_lag):
    """The time-binned operator from the initial density ``n0``: (P(t) on steps+1 times, the image points of the
    first crossing after step ``k_star`` with their weights (x, y, energy, w > 0)).

    Examples
    --------
    The two boxes of :func:`~hhscatter.analysis.geometry.transfer.lag_kernels` (dt = 1), all orbits in box 0:
    P = 1, 1, ½, ½, ¼; the orbits alive at step 2 next cross at box 1's image point (0.25, 0.25).

    >>> tr = tf.Transitions([0, 0, 1, 1], [1, -1, 0, -1], [1.0, 1.0, 2.0, 2.0], n_states=2)
    >>> t = pd.DataFrame({"t_end": [1.0, 2.0, 2.0, 3.0], "x1": [0.75, 0, 0.25, 0], "y1": [0.25, 0, 0.25, 0], "e1": 0.1})
    >>> P, pred = operator_survival(tr, t, [1.0, 0.0], 1.0, 4, 2, 10)
    >>> P.round(6).tolist(), pred.to_dict("records")
    ([1.0, 1.0, 0.5, 0.5, 0.25], [{'x': 0.25, 'y': 0.25, 'energy': 0.1, 'w': 0.25}])
    """
    tf._transitions(tr)
    _transition_table(t, tr)
    K, H, L = tf.lag_kernels(tr, t["t_end"].to_numpy(), dt, max_lag=max_lag)
    cross = tf.propagate(n0, K, L, steps)
    wfc = tf.first_crossing_weights(cross, tr, dt, k_star)
    pred = pd.DataFrame({"x": t["x1"].to_numpy(), "y": t["y1"].to_numpy(), "energy": t["e1"].to_numpy(), "w": wfc})
    return tf.survival_from_crossings(cross, H), pred[pred["w"] > 0].reset_index(drop=True)


def stratified_section_points(model, energy, extent, box, k, r_esc, rng, *, e_width=0.0) -> pd.DataFrame:
    """Sample points of Ulam's boxes on the section: k × k jittered strata in every box of side ``box``.

    Boxes of side ``box`` tile ``extent`` = (x0, x1, y0, y1); the points are kept where V < E and
    0 < r < ``r_esc`` (on the section inside Ω). Columns: cell (finest box index, row-major), rank (a random
    order of the box's strata: the first M' ranks are the subset of M' samples), x, y, energy (E, or uniform in
    [E − e_width/2, E + e_width/2]) and w, the flux density |ṗ_r|/v of the return map's invariant measure
    (:func:`~hhscatter.analysis.geometry.transfer.section_flux_density`).

    Examples
    --------
    The harmonic well V = r²/2 (Hénon–Heiles with λ → 0) at E = 1 inside r_esc = 1: 2 × 2 strata in each of the 16
    boxes of side ½, kept inside the unit disk (about 64·π/4 = 50 of them); the weight is |v²/r − r|/v with v² = 2 − r²
    (:func:`~hhscatter.analysis.geometry.transfer.section_flux_density`).

    >>> from hhscatter.model import HenonHeiles
    >>> rng = np.random.default_rng(0)
    >>> pts = stratified_section_points(HenonHeiles(lam=1e-12), 1.0, (-1, 1, -1, 1), 0.5, 2, 1.0, rng)
    >>> r = np.hypot(pts.x, pts.y)
    >>> len(pts), bool(r.max() < 1), bool(np.allclose(pts.w, (2 - 2 * r**2) / (r * np.sqrt(2 - r**2))))
    (49, True, True)
    """
    _checks.potential(model)
    check.number(energy, "energy")
    _checks.extent(extent)
    check.number(box, "box", positive=True)
    _checks.whole(k, "k")
    check.number(r_esc, "r_esc", positive=True)
    _checks.generator(rng)
    check.number(e_width, "e_width", minimum=0.0)
    nx, ny = grid_shape(extent, box)
    x0, _, y0, _ = extent
    sub = (np.arange(k) + 0.0) / k
    cx, cy = np.meshgrid(np.arange(nx), np.arange(ny))
    cell = (cy * nx + cx).ravel()
    sx, sy = np.meshgrid(sub, sub)
    n_cells, m = cell.size, k * k
    u = rng.random((n_cells, m, 2)) / k
    x = x0 + box * ((cell % nx)[:, None] + sx.ravel()[None, :] + u[..., 0])
    y = y0 + box * ((cell // nx)[:, None] + sy.ravel()[None, :] + u[..., 1])
    rank = np.argsort(rng.random((n_cells, m)), axis=1).argsort(axis=1)
    E = np.full(x.shape, float(energy))
    if e_width > 0:
        E = E + e_width * (rng.random(x.shape) - 0.5)
    x, y, E, rank = x.ravel(), y.ravel(), E.ravel(), rank.ravel()
    cells = np.repeat(cell, m)
    r = np.hypot(x, y)
    ok = (model.potential(x, y) < E) & (r > 0) & (r < r_esc)
    x, y, E, rank, cells = x[ok], y[ok], E[ok], rank[ok], cells[ok]
    w = tf.section_flux_density(model, x, y, E)
    return pd.DataFrame({"cell": cells, "rank": rank, "x": x, "y": y, "energy": E, "w": w})


def reduced_survival(tr, t, ids, n_cells, n_bins, dt, max_lag, steps):
    """P(t) of the operator on ρ(E) alone (:func:`reduced_operator`), started in the top energy bin, on
    steps+1 times of step ``dt``; and the per-bin κ_a.

    Examples
    --------
    One energy bin whose boxes lose half their orbits at every return (T = 1): P(k) = 2^{−k}.

    >>> tr = tf.Transitions([0, 0, 1, 1], [1, -1, 0, -1], np.ones(4), n_states=2)
    >>> t = pd.DataFrame({"t_end": np.ones(4), "x1": 0.0, "y1": 0.0, "e1": 0.0})
    >>> P, kappas = reduced_survival(tr, t, [0, 1], 2, 1, 1.0, 10, 3)
    >>> P.round(6).tolist(), round(kappas[0], 4)
    ([1.0, 0.5, 0.25, 0.125], 0.6931)
    """
    tf._transitions(tr)
    _transition_table(t, tr)
    _state_ids(ids, tr)
    _checks.whole(n_cells, "n_cells")
    _checks.whole(n_bins, "n_bins")
    tr_red, kappa_bins = reduced_operator(tr, ids, n_cells, n_bins)
    K2, H2, L2 = tf.lag_kernels(tr_red, t["t_end"].to_numpy(), dt, max_lag=max_lag)
    n0r = np.zeros(n_bins)
    n0r[-1] = 1.0
    return tf.survival_from_crossings(tf.propagate(n0r, K2, L2, steps), H2), kappa_bins


def one_return_samples(df, lt, sec, what="run"):
    """The sample points ``df`` (in traj_id order) with their fate from the run's lifetimes ``lt`` (traj_id order;
    outcome, t_end) and section crossings ``sec`` (traj_id, t, x, y, energy): ``ret`` (crossed again), ``T``
    (time of the crossing), ``t_end`` (time of the next event), ``x1, y1, e1`` (the crossing), ``censored``.
    ValueError (naming ``what``) if the run does not match the samples.

    Examples
    --------
    Three sample points: the first crossed the section again at t = 2.5 (the run stopped it there), the second
    escaped at t = 4, the third was still inside at the end (censored):

    >>> df = pd.DataFrame({"cell": [0, 1, 2]})
    >>> lt = pd.DataFrame({"outcome": ["stopped", "escaped", "censored"], "t_end": [2.5, 4.0, 10.0]})
    >>> sec = pd.DataFrame({"traj_id": [0], "t": [2.5], "x": [0.1], "y": [0.2], "energy": [0.15]})
    >>> out = one_return_samples(df, lt, sec)
    >>> out[["ret", "T", "x1", "censored"]].to_dict("list")
    {'ret': [True, False, False], 'T': [2.5, nan, nan], 'x1': [0.1, nan, nan], 'censored': [False, False, True]}
    """
    check.table(df, "df", min_rows=0)
    check.table(lt, "lt", ("outcome", "t_end"), min_rows=0)
    check.table(sec, "sec", ("traj_id", "t", "x", "y", "energy"), min_rows=0)
    if not isinstance(what, str):
        raise ConfigError(f"what must be a name (a string), got {what!r}")
    if len(lt) != len(df):
        raise ConfigError(f"{what}: {len(lt)} orbits in the run, {len(df)} samples: re-run `simulate`")
    out = df.reset_index(drop=True).copy()
    oc = lt["outcome"].astype(str).to_numpy()
    out["t_end"] = lt["t_end"].to_numpy()
    out["censored"] = oc == "censored"
    out["ret"] = False
    out["T"], out["x1"], out["y1"], out["e1"] = np.nan, np.nan, np.nan, np.nan
    idx = sec["traj_id"].to_numpy()
    out.loc[idx, "ret"] = True
    out.loc[idx, "T"] = sec["t"].to_numpy()
    out.loc[idx, "x1"], out.loc[idx, "y1"], out.loc[idx, "e1"] = (
        sec["x"].to_numpy(),
        sec["y"].to_numpy(),
        sec["energy"].to_numpy(),
    )
    if not np.all(oc[idx] == "stopped"):
        raise ConfigError(f"{what}: a sample with a section crossing did not stop there")
    return out


def eigenvector_convergence(tab, extent, box, coarsen, subsets, Q, boxes, n_splits, seed, head):
    """The debiased Hellinger distance (at the box nearest ``head``) between the operator's sprinkler measure and
    the reference points ``Q``, for boxes merged c × c and the first M' samples per finest box: records
    {box, samples_per_box, kappa, eps, hellinger_debiased, lo, hi}.

    Examples
    --------
    A map that sends every returning point to a uniform random point of the unit square (half escape, T = 1): the
    sprinkler measure is uniform, so it agrees with a uniform reference sample at every partition, and κ is near
    ln 2 = 0.69.

    >>> rng = np.random.default_rng(0)
    >>> n = 4000
    >>> ret = rng.random(n) < 0.5
    >>> tab = pd.DataFrame({"cell": np.arange(n) % 16, "rank": np.arange(n) // 16, "w": 1.0, "censored": False,
    ...                     "ret": ret, "T": 1.0, "x1": rng.random(n), "y1": rng.random(n)})
    >>> Q = rng.random((2000, 2))  # the reference points
    >>> recs = eigenvector_convergence(tab, (0, 1, 0, 1), 0.25, [1, 2], [250], Q, [0.5, 0.25], 4, 0, 0.25)
    >>> [(r["box"], r["samples_per_box"], round(r["kappa"], 2), round(r["hellinger_debiased"], 2)) for r in recs]
    [(0.25, 250, 0.68, 0.02), (0.5, 1000, 0.68, 0.03)]
    """
    _partitions(tab, extent, box, coarsen, subsets)
    _checks.points(Q, "Q")
    check.numbers(boxes, "boxes", positive=True)
    check.count(n_splits, "n_splits", 1)
    check.count(seed, "seed", 0)
    check.number(head, "head", positive=True)
    out = []
    for c in coarsen:
        for m in subsets:
            tr, _, t = sample_transitions(tab, extent, box, c=c, m_max=m)
            kap, _, _, keep, sub = saddle_kappa(tr)
            res = {"sub": sub, "t": t, "keep": keep, "tr": tr, "kappa": kap}
            P = measure_points(res, "sprinkler", len(Q), np.random.default_rng(seed + 6))
            d, j = hellinger_by_box(P, Q, boxes, extent, n_splits, seed, head)
            out.append(
                {
                    "box": box * c,
                    "samples_per_box": m * c * c,
                    "kappa": kap,
                    "eps": float(d["box"].iloc[j]),
                    "hellinger_debiased": float(d.hellinger_debiased.iloc[j]),
                    "lo": float(d.lo.iloc[j]),
                    "hi": float(d.hi.iloc[j]),
                }
            )
    return out


def hellinger_row(tab, j):
    """The record of a :func:`hellinger_by_box` table at its row ``j``: box, hellinger_debiased (lo, hi),
    hellinger_pq, hellinger_noise and the debiased agreement scale at 0.1.

    Examples
    --------
    The checkerboard of :func:`~hhscatter.analysis.geometry.distance.distance_vs_scale`: H = 0.541 at ε = 0.1, within
    0.1 down to ε = 0.2.

    >>> rng = np.random.default_rng(0)
    >>> P, Q = rng.random((2000, 2)), rng.random((4000, 2))
    >>> Q = Q[np.floor(Q / 0.1).sum(axis=1) % 2 == 0]
    >>> r = hellinger_row(*hellinger_by_box(P, Q, [0.5, 0.2, 0.1], (0, 1, 0, 1), 8, 0, 0.1))
    >>> r["box"], round(r["hellinger_debiased"], 2), r["agreement_scale_debiased"]
    (0.1, 0.54, 0.2)
    """
    check.table(tab, "tab", ("box", "hellinger_debiased", "lo", "hi", "hellinger_pq", "hellinger_noise"))
    if _checks.whole(j, "j", 0) >= len(tab):
        raise ConfigError(f"j must be a row of tab (< {len(tab)}), got {j!r}")
    return {
        "box": float(tab["box"].iloc[j]),
        "hellinger_debiased": float(tab.hellinger_debiased.iloc[j]),
        "hellinger_debiased_lo": float(tab.lo.iloc[j]),
        "hellinger_debiased_hi": float(tab.hi.iloc[j]),
        "hellinger_pq": float(tab["hellinger_pq"].iloc[j]),
        "hellinger_noise": float(tab["hellinger_noise"].iloc[j]),
        "agreement_scale_debiased": dist.agreement_scale_debiased(tab, 0.1, "hellinger"),
    }


def islands_record(trapped_cells, tr, ids, keep, sub):
    """Mixed phase space: the censored boxes ``trapped_cells`` (finest boxes whose KAM probe is still inside at its
    t_max, not classified further) against the operator on
    the states ``ids`` of ``tr`` (saddle class ``keep``, ``sub``): their number, their share of the saddle's
    class, the leading modes' mass on them (:func:`leading_modes`) and κ without them (the keys ``trapped_boxes``,
    ``trapped_share_of_saddle_class``, ``kappa_without_trapped_boxes`` name the censored boxes, as records always
    have).

    Examples
    --------
    Boxes 0 and 1 form the saddle (κ = ln 2); box 2 maps onto itself (a KAM island, its probe censored): none of the
    saddle's class is censored, and κ without the island is the same.

    >>> tr = tf.Transitions([0, 0, 1, 1, 2], [1, -1, 0, -1, 2], np.ones(5), n_states=3)
    >>> kappa, _, _, keep, sub = saddle_kappa(tr)
    >>> r = islands_record([2], tr, [0, 1, 2], keep, sub)
    >>> r["trapped_boxes"], r["trapped_share_of_saddle_class"], round(r["kappa_without_trapped_boxes"], 4)
    (1, 0.0, 0.6931)
    """
    tf._transitions(tr)
    tf._transitions(sub, "sub")
    _state_ids(ids, tr)
    check.mask(keep, "keep", tr.n_states)
    check.numbers(trapped_cells, "trapped_cells", min_size=0, minimum=0)
    trapped = np.isin(ids, trapped_cells)
    trapped_sub = trapped[keep]
    out = {
        "trapped_boxes": int(np.size(trapped_cells)),
        "trapped_share_of_saddle_class": float(trapped_sub.mean()) if trapped_sub.size else 0.0,
        "modes_P": leading_modes(sub, trapped_sub),
    }
    if np.size(trapped_cells):
        try:
            out["kappa_without_trapped_boxes"] = saddle_kappa(tr.subset(~trapped))[0]
        except ValueError:
            out["kappa_without_trapped_boxes"] = math.nan
    return out


def dissipative_operator(tab, extent, box, edges, *, dt, t_horizon, t_star, max_return_time, radius) -> dict:
    """The operator on (box × energy bin) from the one-return samples ``tab`` of a run with drag.

    States: boxes of side ``box`` × the energy bins ``edges`` (``tab`` has a column ``ebin``). The initial
    density is uniform in the disk r < ``radius`` in the top bin (:func:`disk_density`); it is carried
    forward in steps ``dt`` up to ``t_horizon`` (returns longer than ``max_return_time`` arrive then):
    P(t) of the full operator and of the operator on ρ(E) alone (:func:`reduced_survival`), and the weighted
    image points of the first crossing after ``t_star`` (:func:`operator_survival`). Returns {tab, tr, ids,
    t, n_cells, lost (share of the disk on no state), max_lag, steps, grid (times), P, P_reduced,
    kappa_bins, pred}.

    Examples
    --------
    Two energy bins over four boxes of side 1: every (box, bin) state loses half its samples at each return
    (T = 1) and the returns land in the lower bin, so P(k) = 2^{−k}, for the operator and for its reduction to
    ρ(E) alike; the uniform disk r < 1 starts in the top bin.

    >>> i = np.arange(64)
    >>> ret = (i // 8) % 2 == 0
    >>> rng = np.random.default_rng(0)
    >>> tab = pd.DataFrame({"cell": i % 4, "rank": i // 8, "w": 1.0, "censored": False, "ret": ret, "T": 1.0,
    ...                     "x1": rng.uniform(-1, 1, 64), "y1": rng.uniform(-1, 1, 64), "e1": 0.05,
    ...                     "ebin": (i // 4) % 2, "t_end": 1.0})
    >>> op = dissipative_operator(tab, (-1, 1, -1, 1), 1.0, [0.0, 0.1, 0.2], dt=1.0, t_horizon=3.0, t_star=2.0,
    ...                           max_return_time=5.0, radius=1.0)
    >>> op["P"].round(6).tolist(), op["P_reduced"].round(6).tolist(), op["lost"]
    ([1.0, 0.5, 0.25, 0.125], [1.0, 0.5, 0.25, 0.125], 0.0)
    """
    _partitions(tab, extent, box, ebins=True)
    check.numbers(edges, "edges", min_size=2)
    check.number(dt, "dt", positive=True)
    for name, v in (("t_horizon", t_horizon), ("t_star", t_star), ("max_return_time", max_return_time)):
        check.number(v, name, positive=True)
    check.number(radius, "radius", positive=True)
    n_bins = len(edges) - 1
    steps, k_star, max_lag = (int(round(v / dt)) for v in (t_horizon, t_star, max_return_time))
    tr, ids, t = sample_transitions(tab, extent, box, ebins=edges)
    nx, ny = grid_shape(extent, box)
    n_cells = nx * ny
    n0, lost = disk_density(radius, extent, box, ids, n_cells, n_bins - 1)
    P_op, pred = operator_survival(tr, t, n0, dt, steps, k_star, max_lag)
    P_red, kappa_bins = reduced_survival(tr, t, ids, n_cells, n_bins, dt, max_lag, steps)
    return {
        "tab": tab,
        "tr": tr,
        "ids": ids,
        "t": t,
        "n_cells": n_cells,
        "lost": lost,
        "max_lag": max_lag,
        "steps": steps,
        "grid": np.arange(steps + 1) * dt,
        "P": P_op,
        "P_reduced": P_red,
        "kappa_bins": kappa_bins,
        "pred": pred,
    }


def t_star_distance(pred, sim_points, boxes, extent, n_splits, seed, head):
    """Debiased Hellinger distance over box sizes (:func:`hellinger_by_box`) between the operator's points of
    the first crossing after t* (``pred``: x, y, w; drawn by weight, as many as ``sim_points``, seeded by
    seed + 9) and the simulated ones (an (n, 2) array): (table, index of the box nearest ``head``).

    Examples
    --------
    Operator points uniform on the unit square but weighted only on the black squares of a checkerboard of side
    0.1 against a uniform sample: they agree at ε ≥ 0.2 and differ at 0.1 (H = 0.541).

    >>> rng = np.random.default_rng(0)
    >>> X = rng.random((8000, 2))
    >>> pred = pd.DataFrame({"x": X[:, 0], "y": X[:, 1], "w": (np.floor(X / 0.1).sum(axis=1) % 2 == 0) * 1.0})
    >>> tab, j = t_star_distance(pred, rng.random((2000, 2)), [0.5, 0.2, 0.1], (0, 1, 0, 1), 8, 0, 0.1)
    >>> j, tab["hellinger_debiased"].round(2).tolist()
    (2, [0.02, 0.04, 0.54])
    """
    check.table(pred, "pred", ("x", "y", "w"))
    if not np.sum(pred["w"]) > 0:
        raise ConfigError("pred: the weights w must not all be 0")
    _checks.points(sim_points, "sim_points")
    rng = np.random.default_rng(seed + 9)
    draw = pred.iloc[rng.choice(len(pred), size=max(len(sim_points), 4), p=pred["w"] / pred["w"].sum())]
    return hellinger_by_box(draw[["x", "y"]].to_numpy(), sim_points, boxes, extent, n_splits, seed, head)


def dissipative_record(op, edges, P_sim, N, sim_pts, sim_orbit_time, dtab, j, *, energy, gamma, dt, t_star) -> dict:
    """The numbers of the dissipative comparison: the operator ``op`` (:func:`dissipative_operator`) on the
    energy bins ``edges`` against the simulated ensemble of ``N`` orbits (P_sim on op's grid, its first
    crossings after t* ``sim_pts`` with x, y, energy, its orbit-time): :func:`survival_agreement`,
    :func:`t_star_energies` and the t* distance table ``dtab`` at row ``j`` (:func:`t_star_distance`), with
    (energy, gamma) of the ensemble, the step ``dt`` and ``t_star``.

    Examples
    --------
    The operator of :func:`dissipative_operator` (P = 2^{−k}) against a simulated P that matches it, with the
    first crossings after t* compared on boxes of side ½ and 1:

    >>> i = np.arange(64)
    >>> rng = np.random.default_rng(0)
    >>> tab = pd.DataFrame({"cell": i % 4, "rank": i // 8, "w": 1.0, "censored": False, "ret": (i // 8) % 2 == 0,
    ...                     "T": 1.0, "x1": rng.uniform(-1, 1, 64), "y1": rng.uniform(-1, 1, 64), "e1": 0.05,
    ...                     "ebin": (i // 4) % 2, "t_end": 1.0})
    >>> edges = [0.0, 0.1, 0.2]
    >>> op = dissipative_operator(tab, (-1, 1, -1, 1), 1.0, edges, dt=1.0, t_horizon=3.0, t_star=2.0,
    ...                           max_return_time=5.0, radius=1.0)
    >>> sim = pd.DataFrame({"x": rng.uniform(-1, 1, 200), "y": rng.uniform(-1, 1, 200), "energy": 0.05})
    >>> dtab, j = t_star_distance(op["pred"], sim[["x", "y"]].to_numpy(), [1.0, 0.5], (-1, 1, -1, 1), 4, 0, 1.0)
    >>> r = dissipative_record(op, edges, 0.5 ** np.arange(4), 1000, sim, 100.0, dtab, j, energy=0.2, gamma=0.01,
    ...                        dt=1.0, t_star=2.0)
    >>> round(r["lnP_max_operator"], 6), r["t_star_mean_energy"]["operator"], r["states"]  # 4 boxes × 2 bins
    (0.0, 0.05, 8)
    """
    _checks.mapping(op, "op", ("grid", "P", "P_reduced", "pred", "tr", "lost", "kappa_bins", "steps"))
    check.numbers(edges, "edges", min_size=2)
    check.numbers(P_sim, "P_sim", minimum=0.0)
    _checks.whole(N, "N")
    check.table(sim_pts, "sim_pts", ("energy",), min_rows=0)
    check.number(sim_orbit_time, "sim_orbit_time", minimum=0.0)
    check.table(dtab, "dtab")
    _checks.whole(j, "j", 0)
    for name, v in (("energy", energy), ("gamma", gamma), ("dt", dt), ("t_star", t_star)):
        check.number(v, name)
    return {
        "energy": energy,
        "gamma": gamma,
        "t_star": t_star,
        "dt": dt,
        "energy_bins": [float(e) for e in edges],
        "states": int(op["tr"].n_states),
        "samples": int(len(op["tab"])),
        "initial_mass_lost": op["lost"],
        "returns_capped_share": tf.capped_share(op["tr"], dt, op["max_lag"]),
        "max_return_time": op["max_lag"] * dt,
        "operator_orbit_time": float(op["tab"]["t_end"].sum()),
        "sim_orbits": int(N),
        "sim_orbit_time": float(sim_orbit_time),
        **survival_agreement(op["grid"], dt, t_star, P_sim, op["P"], op["P_reduced"], N),
        **t_star_energies(op["pred"], sim_pts),
        "t_star_hellinger_debiased": {
            "box": float(dtab["box"].iloc[j]),
            "value": float(dtab.hellinger_debiased.iloc[j]),
            "lo": float(dtab.lo.iloc[j]),
            "hi": float(dtab.hi.iloc[j]),
            "noise": float(dtab["hellinger_noise"].iloc[j]),
        },
        "kappa_bins": [
            {"energy": float(0.5 * (edges[a] + edges[a + 1])), "kappa": kb} for a, kb in enumerate(op["kappa_bins"])
        ],
    }
