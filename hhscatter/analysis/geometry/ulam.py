"""Ulam's method on a section from one-return samples: transitions, κ and its convergence, measures, comparisons.

The operators themselves are in :mod:`hhscatter.analysis.geometry.transfer`; this module builds them from a
table of one-return samples (one row per sample point: its finest box ``cell``, stratum ``rank``, weight
``w``, whether it returned (``ret``), the return time ``T``, the image point ``x1, y1, e1`` and ``censored``)
and turns their results into the records of an operator study:

* :func:`sample_transitions` — the samples on boxes merged c × c, optionally the first M' per box, optionally
  on (box × energy bin) states;
* :func:`saddle_kappa`, :func:`kappa_record` — κ on the chaotic saddle's class and its record;
* :func:`kappa_convergence` — κ extrapolated to infinitely many samples per box and to box side 0, with the
  statistical and model errors (see its notes);
* :func:`residuals` — κ_Ulam/κ_ref − 1 with both errors and the one verdict;
* :func:`leading_modes`, :func:`measure_points`, :func:`reduced_operator` — spectra, c-measure samples and the
  operator on ρ(E) alone;
* :func:`empirical_survival`, :func:`survival_agreement`, :func:`t_star_energies`, :func:`cost_row` — the
  comparisons with a simulated ensemble and the cost of each route.

Pure functions (tables and arrays in, records out). Units: box sides in position units, times in the
Hamiltonian's time unit, κ in 1/time.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.geometry import transfer as tf

__all__ = [
    "coarse_index",
    "convergence_grid",
    "convergence_record",
    "convergence_summary",
    "cost_row",
    "disk_density",
    "eigenvector_convergence",
    "empirical_survival",
    "grid_shape",
    "hellinger_by_box",
    "hellinger_row",
    "islands_record",
    "kappa_convergence",
    "kappa_record",
    "leading_modes",
    "measure_points",
    "one_return_samples",
    "operator_survival",
    "reduced_operator",
    "residuals",
    "reduced_survival",
    "saddle_kappa",
    "stratified_section_points",
    "sample_transitions",
    "survival_agreement",
    "t_star_energies",
]


def grid_shape(extent, box: float) -> tuple[int, int]:
    """Boxes per side (nx, ny) of side ``box`` covering ``extent`` = (x0, x1, y0, y1).

    Examples
    --------
    >>> grid_shape((-1.03, 1.03, -1.03, 1.03), 0.1)
    (21, 21)
    """
    x0, x1, y0, y1 = extent
    return int(math.ceil((x1 - x0) / box - 1e-9)), int(math.ceil((y1 - y0) / box - 1e-9))


def coarse_index(cell, nx: int, c: int):
    """Index of the c × c merged box holding finest box ``cell`` (row-major, ``nx`` finest boxes per row).

    Examples
    --------
    >>> coarse_index(np.array([0, 1, 4, 5, 15]), 4, 2).tolist()
    [0, 0, 0, 0, 3]
    """
    ix, iy = cell % nx, cell // nx
    ncx = -(-nx // c)
    return (iy // c) * ncx + ix // c


def sample_transitions(tab: pd.DataFrame, extent, box: float, c: int = 1, m_max=None, ebins=None):
    """The one-return samples as :class:`~hhscatter.analysis.geometry.transfer.Transitions` on merged boxes.

    Boxes of side ``box`` (the finest, that of ``tab.cell``) merged c × c; only the first ``m_max`` ranks per
    finest box; censored samples dropped. With ``ebins`` (bin edges in energy; ``tab`` then has a column
    ``ebin``) the states are (box, energy bin): id = bin·n_cells + box. Returns (Transitions, state ids,
    the samples used).
    """
    nx, _ = grid_shape(extent, box)
    mask = ~tab["censored"].to_numpy()
    if m_max is not None:
        mask &= tab["rank"].to_numpy() < m_max
    t = tab[mask]
    src = coarse_index(t["cell"].to_numpy(), nx, c)
    ret = t["ret"].to_numpy()
    cell1, _, _ = tf.box_index(np.where(ret, t["x1"], 0.0), np.where(ret, t["y1"], 0.0), extent, box)
    dst = np.where(ret & (cell1 >= 0), coarse_index(np.maximum(cell1, 0), nx, c), -1)
    if ebins is not None:
        n_cells = int(coarse_index(np.array([nx * nx - 1]), nx, c)[0]) + 1
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
    """κ on the chaotic saddle's class of ``tr``: (κ, κ per return, class info, keep mask, sub-Transitions)."""
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


def kappa_record(E, res, samples, box):
    """The record of κ at one energy from the results ``res`` of the finest partition.

    ``res`` holds rows (κ per box side, ``vary`` = "box"), boot (bootstrap replicates), kappa, kappa_map,
    info, sub, cost. κ on the finest boxes; the linear discretisation bias from a straight line κ(b) through
    the three finest box sides (κ at b → 0); err = √(σ_boot² + bias²).
    """
    rows = pd.DataFrame([r for r in res["rows"] if r["vary"] == "box"]).sort_values("box")
    fit = rows.head(3)
    slope, k_inf = (
        np.polyfit(fit["box"].to_numpy(), fit["kappa"].to_numpy(), 1) if len(fit) >= 2 else (0.0, res["kappa"])
    )
    boot = res["boot"]
    stat = float(np.std(boot, ddof=1)) if boot.size > 1 else math.nan
    bias = float(k_inf - res["kappa"])
    return {
        "energy": E,
        "kappa": res["kappa"],
        "err": float(math.hypot(stat, bias)),
        "boxes": int(res["sub"].n_states),
        "samples": samples,
        "box": box,
        "kappa_stat_err": stat,
        "discretisation_bias": bias,
        "kappa_extrapolated": float(k_inf),
        "bias_slope": float(slope),
        "kappa_map_per_return": res["kappa_map"],
        "mean_return_time": res["cost"]["mean_return_time"],
        "orbit_time": res["cost"]["orbit_time"],
        "orbits": res["cost"]["orbits"],
        "censored": res["cost"]["censored"],
        **{f"class_{k}": v for k, v in res["info"].items()},
    }


def _fit_convergence(b, M, k, p):
    """Least squares of κ = κ∞ + a·b + β·M^(−p): (κ∞, residual rms, design matrix, coefficients)."""
    X = np.column_stack([np.ones_like(b), b, M ** (-p)])
    coef, *_ = np.linalg.lstsq(X, k, rcond=None)
    res = k - X @ coef
    dof = max(len(k) - 3, 1)
    return float(coef[0]), float(math.sqrt(np.sum(res**2) / dof)), X, coef


def kappa_convergence(
    grid: pd.DataFrame, boot_grid: pd.DataFrame | None = None, *, p_main: float = 0.5, p_alt: float = 1.0
) -> dict:
    """κ of Ulam's method extrapolated to infinitely many samples per box and to box side 0.

    ``grid`` holds κ of one energy on a grid of partitions: columns box (side, position units), samples
    (sample points per box, M) and kappa. Two effects move κ, and both are seen in the study: the box side b
    (coarse boxes smear the hole's edges: κ(b) = κ∞ + a·b to first order) and the samples per box M (the
    flux weights |ṗ_r|/v are heavy-tailed — 1/v at V = E — and the Perron root of a matrix estimated from M
    samples per row is biased, falling as M grows). The model κ(b, M) = κ∞ + a·b + β·M^(−p) is fitted by
    least squares with p = ``p_main`` (½, the decay of the bias of a ratio estimator with heavy-tailed
    weights that the study's grids show) and, as the model systematic, with p = ``p_alt`` (1, the decay of a
    finite-variance ratio estimator's bias): κ∞ is the first fit, its model error the difference of the two.

    ``boot_grid`` (optional) holds bootstrap replicates on the same grid (columns rep, box, samples, kappa):
    each replicate is extrapolated with the same design and their spread is the statistical error of κ∞.

    Returns {kappa_inf, stat_err, model_err, err (the two in quadrature), kappa_inf_alt, slope_box,
    coef_samples, p, p_alt, residual_rms, n_points}.

    Examples
    --------
    >>> b, M = np.meshgrid([0.01, 0.02, 0.04], [4.0, 16.0, 64.0])
    >>> g = pd.DataFrame({"box": b.ravel(), "samples": M.ravel() * (b.ravel() / 0.01) ** 2})
    >>> g["kappa"] = 0.2 + 0.3 * g.box + 0.05 / np.sqrt(g.samples)
    >>> round(kappa_convergence(g)["kappa_inf"], 10)
    0.2
    """
    g = grid.dropna(subset=["kappa"])
    if len(g) < 4 or g["box"].nunique() < 2 or g["samples"].nunique() < 2:
        raise ValueError("kappa_convergence: need ≥ 4 partitions with ≥ 2 box sides and ≥ 2 sample counts")
    b, M, k = (g[c].to_numpy(dtype=float) for c in ("box", "samples", "kappa"))
    k_inf, rms, X, coef = _fit_convergence(b, M, k, p_main)
    k_alt, _, _, _ = _fit_convergence(b, M, k, p_alt)
    stat = math.nan
    if boot_grid is not None and len(boot_grid):
        reps = []
        for _, part in boot_grid.groupby("rep"):
            pt = part.set_index(["box", "samples"]).reindex(list(zip(b, M)))["kappa"].to_numpy(dtype=float)
            if np.all(np.isfinite(pt)):
                reps.append(np.linalg.lstsq(X, pt, rcond=None)[0][0])
        if len(reps) > 1:
            stat = float(np.std(reps, ddof=1))
    model = abs(k_alt - k_inf)
    err = math.hypot(stat, model) if math.isfinite(stat) else math.nan
    return {
        "kappa_inf": k_inf,
        "stat_err": stat,
        "model_err": model,
        "err": err,
        "kappa_inf_alt": k_alt,
        "slope_box": float(coef[1]),
        "coef_samples": float(coef[2]),
        "p": p_main,
        "p_alt": p_alt,
        "residual_rms": rms,
        "n_points": int(len(g)),
    }


def residuals(value, err, ref, ref_err) -> dict:
    """κ/κ_ref − 1 with both errors, and z = (κ − κ_ref)/√(σ² + σ_ref²).

    Examples
    --------
    >>> r = residuals(0.102, 0.003, 0.1, 0.004)
    >>> round(r["residual"], 6), round(r["residual_err"], 6), round(r["z"], 6)
    (0.02, 0.050642, 0.4)
    """
    value, err, ref, ref_err = (float(v) for v in (value, err, ref, ref_err))
    res = value / ref - 1.0
    # the ratio's error from both: σ_r/r in quadrature, r = κ/κ_ref
    res_err = (value / ref) * math.hypot(err / value, ref_err / ref)
    sig = math.hypot(err, ref_err)
    return {"residual": res, "residual_err": res_err, "z": (value - ref) / sig if sig > 0 else math.inf}


def leading_modes(sub, trapped_sub, k: int = 4):
    """The ``k`` leading eigenvalues of P on the saddle's class and each mode's mass on the boxes
    ``trapped_sub`` (bool over sub's states): [{eigenvalue, eigenvalue_arg, mass_on_trapped_boxes}]."""
    import scipy.linalg  # deferred: scipy loads on first use
    from scipy.sparse.linalg import eigs  # deferred: scipy loads on first use

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
    """
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
    bin·n_cells + box. Returns (Transitions over bins, per-bin κ_a)."""
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
    te = np.sort(np.asarray(t_end)[np.asarray(leaving)])
    return 1.0 - np.searchsorted(te, grid, side="right") / len(t_end)


def survival_agreement(grid, dt, t_star, P_sim, P_op, P_red, N):
    """P(t) of operator and reduced operator against the simulation: values at fixed times and the rms/max
    |ln(P/P_sim)| where P_sim·N ≥ 30 (also the time up to which that holds)."""
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
                "sim": float(P_sim[i]),
                "sim_err": float(sig[i]),
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
    """Mean and spread of the energy at the first crossing after t*: operator (weighted) and simulation."""
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


def cost_row(E, pt, rec, kappa0, target):
    """Orbit-time of each route for κ at the relative error ``target``.

    ``pt``: the P(t) route's result {kappa, kappa_err, orbits, orbit_time}; ``rec``: the operator's κ record
    at E (or None); ``kappa0``: {E: (κ0, err)} of the reference. The P(t) route scales as 1/√N; the
    operator's is a lower bound: its bias ∝ box side (cost ∝ 1/b² at fixed samples per box) and its
    statistics ∝ 1/√(samples) — optimistic, since finer boxes raise the per-sample noise.
    """
    rel = float(pt["kappa_err"] / pt["kappa"])
    ot = float(pt["orbit_time"])
    k0 = kappa0.get(E, (math.nan, math.nan))
    row = {
        "energy": E,
        "pt_kappa": float(pt["kappa"]),
        "pt_err": float(pt["kappa_err"]),
        "pt_rel": rel,
        "pt_orbits": int(pt["orbits"]),
        "pt_orbit_time": ot,
        "pt_orbit_time_1pct": ot * (rel / target) ** 2,
        "fig2_kappa": k0[0],
        "fig2_err": k0[1],
    }
    if rec is not None:
        k = rec["kappa"]
        st_rel = rec["kappa_stat_err"] / k
        b_rel = abs(rec["discretisation_bias"]) / k
        share = target / math.sqrt(2)  # half of the budget (in quadrature) to each part
        f_bias = max(1.0, (b_rel / share) ** 2)
        f_stat = max(1.0, (st_rel / share) ** 2)
        row.update(
            {
                "op_kappa": k,
                "op_err": rec["err"],
                "op_rel": rec["err"] / k,
                "op_stat_rel": st_rel,
                "op_bias_rel": b_rel,
                "op_orbit_time": rec["orbit_time"],
                "op_orbit_time_1pct": rec["orbit_time"] * max(f_bias, f_stat),
                "pt_rel_at_op_cost": rel * math.sqrt(ot / rec["orbit_time"]),
            }
        )
    return row


def convergence_record(E, grid, boot_grid, kappa_finest, refs) -> dict:
    """The record of κ's convergence at energy E: :func:`kappa_convergence` of ``grid`` (with ``boot_grid``)
    and, for each reference in ``refs`` ({name: (κ_ref, err) or None}), :func:`residuals` of κ∞ against it
    (keys residual_<name>, residual_<name>_err, z_<name>). A grid too small for the fit gives kappa_inf None
    and the reason in ``note``."""
    rec = {"energy": float(E), "kappa_finest": float(kappa_finest)}
    try:
        c = kappa_convergence(grid, boot_grid)
    except ValueError as exc:
        rec.update(kappa_inf=None, err=None, note=str(exc))
        return rec
    rec.update(c)
    for name, ref in refs.items():
        if ref is None or c["err"] is None or not math.isfinite(c["err"]):
            continue
        r = residuals(c["kappa_inf"], c["err"], ref[0], ref[1])
        rec.update(
            {
                f"{name}": ref[0],
                f"{name}_err": ref[1],
                f"residual_{name}": r["residual"],
                f"residual_{name}_err": r["residual_err"],
                f"z_{name}": r["z"],
            }
        )
        rf = residuals(kappa_finest, 0.0, ref[0], ref[1])  # the finest partition's offset, for the page
        rec[f"residual_finest_{name}"] = rf["residual"]
    return rec


def hellinger_by_box(P, Q, boxes, extent, n_splits, seed, head):
    """Debiased Hellinger distance between point sets P and Q over box sizes
    (:func:`~hhscatter.analysis.geometry.distance.distance_vs_scale`): (table with hellinger_debiased, lo, hi;
    index of the box nearest ``head``)."""
    tab = dist.distance_vs_scale(P, Q, boxes, extent, n_splits=n_splits, seed=seed)
    d, lo, hi = dist.debiased_distance(tab, "hellinger")
    j = int(np.argmin(np.abs(tab["box"].to_numpy() - head)))
    return tab.assign(hellinger_debiased=d, lo=lo, hi=hi), j


def disk_density(radius, extent, box, ids, n_cells, top_bin, n_grid=600):
    """A density uniform in the disk r < ``radius`` on the section, on the (box × energy bin) states ``ids``
    (id = bin·n_cells + box) of the top energy bin: (n0 normalised, share of the disk on no state)."""
    g = (np.arange(n_grid) + 0.5) / n_grid * 2 * radius - radius
    X, Y = np.meshgrid(g, g)
    inside = np.hypot(X, Y) < radius
    cell, _, _ = tf.box_index(X[inside], Y[inside], extent, box)
    state = top_bin * n_cells + cell
    pos = np.searchsorted(ids, state)
    ok = (pos < ids.size) & (ids[np.minimum(pos, ids.size - 1)] == state)
    n0 = np.bincount(pos[ok], minlength=ids.size).astype(float)
    return n0 / n0.sum(), float(1 - ok.mean())


def operator_survival(tr, t, n0, dt, steps, k_star, max_lag):
    """The time-binned operator from the initial density ``n0``: (P(t) on steps+1 times, the image points of the
    first crossing after step ``k_star`` with their weights (x, y, energy, w > 0))."""
    K, H, L = tf.lag_kernels(tr, t["t_end"].to_numpy(), dt, max_lag=max_lag)
    cross = tf.propagate(n0, K, L, steps)
    wfc = tf.first_crossing_weights(cross, tr, dt, k_star)
    pred = pd.DataFrame({"x": t["x1"].to_numpy(), "y": t["y1"].to_numpy(), "energy": t["e1"].to_numpy(), "w": wfc})
    return tf.survival_from_crossings(cross, H), pred[pred["w"] > 0].reset_index(drop=True)


def convergence_grid(tab, extent, box, coarsen, subsets, samples, n_boot, rng):
    """κ of one energy on the grid of box sides × sample counts, and its Poisson-bootstrap replicates.

    The partitions: the finest boxes (side ``box``) merged c × c for c in ``coarsen`` × the first M' ranks of
    each finest box for M' in ``subsets`` (``samples`` = all of them); M'·c² samples per merged box. Each of the
    ``n_boot`` replicates multiplies every sample's weight by one Poisson(1) count, the same at every
    partition, so that a replicate's grid can be extrapolated like the estimate's
    (:func:`kappa_convergence`). Returns (grid: box, samples, kappa; replicates: rep, box, samples, kappa —
    NaN where a replicate leaves no open class).
    """
    parts = [(int(c), int(m)) for c in coarsen for m in subsets]
    trs = {(c, m): sample_transitions(tab, extent, box, c=c, m_max=None if m == samples else m)[0] for c, m in parts}
    grid = pd.DataFrame([{"box": box * c, "samples": m * c * c, "kappa": saddle_kappa(trs[c, m])[0]} for c, m in parts])
    gen = np.random.default_rng(rng)
    rank = tab["rank"].to_numpy()[~tab["censored"].to_numpy()]  # the samples sample_transitions keeps, in order
    reps = []
    for r in range(int(n_boot)):
        pois = gen.poisson(1.0, rank.size)
        for c, m in parts:
            tr = trs[c, m]
            rep = tf.Transitions(tr.src, tr.dst, tr.T, tr.n_states, tr.w * (pois if m == samples else pois[rank < m]))
            try:
                kap = saddle_kappa(rep)[0]
            except ValueError:
                kap = math.nan
            reps.append({"rep": r, "box": box * c, "samples": m * c * c, "kappa": kap})
    return grid, pd.DataFrame(reps, columns=["rep", "box", "samples", "kappa"])


def stratified_section_points(model, energy, extent, box, k, r_esc, rng, *, e_width=0.0) -> pd.DataFrame:
    """Sample points of Ulam's boxes on the section: k × k jittered strata in every box of side ``box``.

    Boxes of side ``box`` tile ``extent`` = (x0, x1, y0, y1); the points are kept where V < E and
    0 < r < ``r_esc`` (on the section inside Ω). Columns: cell (finest box index, row-major), rank (a random
    order of the box's strata: the first M' ranks are the subset of M' samples), x, y, energy (E, or uniform in
    [E − e_width/2, E + e_width/2]) and w, the flux density |ṗ_r|/v of the return map's invariant measure
    (:func:`~hhscatter.analysis.geometry.transfer.section_flux_density`).
    """
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
    steps+1 times of step ``dt``; and the per-bin κ_a."""
    tr_red, kappa_bins = reduced_operator(tr, ids, n_cells, n_bins)
    K2, H2, L2 = tf.lag_kernels(tr_red, t["t_end"].to_numpy(), dt, max_lag=max_lag)
    n0r = np.zeros(n_bins)
    n0r[-1] = 1.0
    return tf.survival_from_crossings(tf.propagate(n0r, K2, L2, steps), H2), kappa_bins


def one_return_samples(df, lt, sec, what="run"):
    """The sample points ``df`` (in traj_id order) with their fate from the run's lifetimes ``lt`` (traj_id order;
    outcome, t_end) and section crossings ``sec`` (traj_id, t, x, y, energy): ``ret`` (crossed again), ``T``
    (time of the crossing), ``t_end`` (time of the next event), ``x1, y1, e1`` (the crossing), ``censored``.
    ValueError (naming ``what``) if the run does not match the samples."""
    if len(lt) != len(df):
        raise ValueError(f"{what}: {len(lt)} orbits in the run, {len(df)} samples: re-run `simulate`")
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
        raise ValueError(f"{what}: a sample with a section crossing did not stop there")
    return out


def eigenvector_convergence(tab, extent, box, coarsen, subsets, Q, boxes, n_splits, seed, head):
    """The debiased Hellinger distance (at the box nearest ``head``) between the operator's sprinkler measure and
    the reference points ``Q``, for boxes merged c × c and the first M' samples per finest box: records
    {box, samples_per_box, kappa, eps, hellinger_debiased, lo, hi}."""
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
    hellinger_pq, hellinger_noise and the debiased agreement scale at 0.1."""
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
    """Mixed phase space: the finest boxes ``trapped_cells`` (a KAM probe still inside) against the operator on
    the states ``ids`` of ``tr`` (saddle class ``keep``, ``sub``): their number, their share of the saddle's
    class, the leading modes' mass on them (:func:`leading_modes`) and κ without them."""
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


def convergence_summary(records, *, z_agree: float = 2.0) -> dict:
    """How the extrapolated κ∞ of :func:`convergence_record` compares with the references, in words and numbers.

    For each reference (kappa0, kappa_cm): the energies where |z| ≤ ``z_agree`` (both errors), the largest
    |κ∞/κ_ref − 1| and the mean residual; ``statement`` says it in one sentence per reference.

    Examples
    --------
    >>> recs = [{"energy": 0.3, "kappa_inf": 0.2, "z_kappa0": 0.5, "residual_kappa0": 0.01}]
    >>> convergence_summary(recs)["kappa0"]["agree"]
    [0.3]
    """
    out, words = {}, []
    names = {"kappa0": "fig2's κ0 from P(t)", "kappa_cm": "fig2's κ from long-run crossings"}
    for ref, label in names.items():
        rs = [r for r in records if r.get("kappa_inf") is not None and r.get(f"z_{ref}") is not None]
        if not rs:
            continue
        agree = [r["energy"] for r in rs if abs(r[f"z_{ref}"]) <= z_agree]
        res = np.array([r[f"residual_{ref}"] for r in rs])
        out[ref] = {
            "energies": [r["energy"] for r in rs],
            "agree": agree,
            "max_abs_residual": float(np.max(np.abs(res))),
            "mean_residual": float(res.mean()),
        }
        words.append(
            f"against {label}, κ∞ agrees within {z_agree:g}σ (both errors) at {len(agree)} of {len(rs)} "
            f"energies; |κ∞/κ_ref − 1| ≤ {100 * np.max(np.abs(res)):.2g} %, mean {100 * res.mean():+.2g} %"
        )
    out["statement"] = "; ".join(words) if words else "no reference to compare with"
    return out
