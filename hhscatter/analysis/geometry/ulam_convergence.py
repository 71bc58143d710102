"""κ of Ulam's method at one energy: every partition, the extrapolation to both limits, residuals, records.

Built on :mod:`hhscatter.analysis.geometry.ulam` (the samples as transitions, κ on the saddle's class):

* :func:`energy_results` — κ at every box side and sample count of one energy's one-return samples, the
  extrapolation grid with its bootstrap replicates, the bootstrap of the finest partition and the cost;
* :func:`kappa_convergence` — κ extrapolated to infinitely many samples per box and to box side 0, with the
  statistical and model errors (see its notes); :func:`convergence_grid` the grid it is fitted on;
* :func:`residuals`, :func:`convergence_record` — κ_Ulam/κ_ref − 1 with both errors against each reference,
  per energy;
* :func:`measure_on_cut_boxes` — where the c-measure lives against the partition: its share on the boxes cut
  by the section's boundary (V = E or r = r_esc), where the flux weights |ṗ_r|/v are heavy-tailed;

Units: box sides in position units, times in the Hamiltonian's time unit, κ in 1/time.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import _checks
from hhscatter.analysis.geometry import transfer as tf
from hhscatter.analysis.geometry.ulam import _partitions, saddle_kappa, sample_transitions
from hhscatter.analysis.stats import _arguments as check
from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.stats.verdicts import verdict
from hhscatter.errors import ConfigError

__all__ = [
    "convergence_grid",
    "convergence_record",
    "energy_results",
    "kappa_convergence",
    "measure_on_cut_boxes",
    "residuals",
]


def _grid_table(grid, name: str, more=()):
    return check.table(grid, name, ("box", "samples", "kappa") + tuple(more), min_rows=0)


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
    (sample points per box, M) and kappa. Two effects move κ: the box side b
    (coarse boxes smear the hole's edges: κ(b) = κ∞ + a·b to first order) and the samples per box M (the
    flux weights |ṗ_r|/v are heavy-tailed — 1/v at V = E — and the Perron root of a matrix estimated from M
    samples per row is biased, falling as M grows). The model κ(b, M) = κ∞ + a·b + β·M^(−p) is fitted by
    least squares with p = ``p_main`` (½, the decay of the bias of a ratio estimator with heavy-tailed
    weights) and, as the model systematic, with p = ``p_alt`` (1, the decay of a
    finite-variance ratio estimator's bias): κ∞ is the first fit, its model error the difference of the two.

    ``boot_grid`` (optional) holds bootstrap replicates on the same grid (columns rep, box, samples, kappa):
    each replicate is extrapolated with the same design (on the partitions where it has a κ: a replicate's
    Poisson weights can leave a partition with few samples per box without an open class) and their spread is
    the statistical error of κ∞.

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
    _grid_table(grid, "grid")
    if boot_grid is not None:
        _grid_table(boot_grid, "boot_grid", ("rep",))
    check.number(p_main, "p_main", positive=True)
    check.number(p_alt, "p_alt", positive=True)
    g = grid.dropna(subset=["kappa"])
    if len(g) < 4 or g["box"].nunique() < 2 or g["samples"].nunique() < 2:
        raise ConfigError("kappa_convergence: need ≥ 4 partitions with ≥ 2 box sides and ≥ 2 sample counts")
    b, M, k = (g[c].to_numpy(dtype=float) for c in ("box", "samples", "kappa"))
    k_inf, rms, X, coef = _fit_convergence(b, M, k, p_main)
    k_alt, _, _, _ = _fit_convergence(b, M, k, p_alt)
    stat = math.nan
    if boot_grid is not None and len(boot_grid):
        reps = []
        for _, part in boot_grid.groupby("rep"):
            pt = part.set_index(["box", "samples"]).reindex(list(zip(b, M)))["kappa"].to_numpy(dtype=float)
            ok = np.isfinite(pt)  # a replicate that leaves a partition without an open class: fit the rest
            if ok.sum() >= 4 and np.unique(b[ok]).size >= 2 and np.unique(M[ok]).size >= 2:
                reps.append(np.linalg.lstsq(X[ok], pt[ok], rcond=None)[0][0])
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
    check.number(value, "value")
    check.number(err, "err", minimum=0.0)
    if check.number(ref, "ref") == 0:
        raise ConfigError("ref must not be 0 (the residual is κ/κ_ref − 1)")
    check.number(ref_err, "ref_err", minimum=0.0)
    value, err, ref, ref_err = (float(v) for v in (value, err, ref, ref_err))
    res = value / ref - 1.0
    res_err = (Measured(value, err) / Measured(ref, ref_err)).err  # the error of r = κ/κ_ref
    sig = math.hypot(err, ref_err)
    return {"residual": res, "residual_err": res_err, "z": (value - ref) / sig if sig > 0 else math.inf}


def convergence_record(E, grid, boot_grid, kappa_finest, refs) -> dict:
    """The record of κ's convergence at energy E: :func:`kappa_convergence` of ``grid`` (with ``boot_grid``)
    and, for each reference in ``refs`` ({name: (κ_ref, err) or None}), :func:`residuals` of κ∞ against it
    (keys residual_<name>, residual_<name>_err, z_<name> and verdict_<name>, the one verdict rule of
    :func:`hhscatter.analysis.stats.verdicts.verdict`). A grid too small for the fit gives kappa_inf None and the
    reason in ``note``.

    Examples
    --------
    κ = 0.2 + 0.3 b + 0.05/√M on a grid of box sides b and samples per box M (κ∞ = 0.2), three bootstrap
    replicates shifted by −0.002, 0, +0.002 (statistical error 0.002), against a reference 0.2 ± 0.004:

    >>> b, M = np.meshgrid([0.01, 0.02, 0.04], [4.0, 16.0, 64.0])
    >>> g = pd.DataFrame({"box": b.ravel(), "samples": M.ravel() * (b.ravel() / 0.01) ** 2})
    >>> g["kappa"] = 0.2 + 0.3 * g.box + 0.05 / np.sqrt(g.samples)
    >>> boot = pd.concat([g.assign(rep=r, kappa=g.kappa + d) for r, d in enumerate([-0.002, 0.0, 0.002])])
    >>> rec = convergence_record(0.2, g, boot, float(g.kappa.iloc[0]), {"ref": (0.2, 0.004)})
    >>> round(rec["kappa_inf"], 6), round(rec["stat_err"], 6), rec["verdict_ref"]
    (0.2, 0.002, 'agrees (z = +0.0)')
    """
    check.number(E, "E")
    _grid_table(grid, "grid")
    if boot_grid is not None:
        _grid_table(boot_grid, "boot_grid", ("rep",))
    check.number(kappa_finest, "kappa_finest")
    _checks.mapping(refs, "refs")
    for name, ref in refs.items():
        _checks.reference(ref, f"refs[{name!r}]")
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
        rec[f"verdict_{name}"] = verdict(c["kappa_inf"], c["err"], ref[0], ref[1]).text()
        rf = residuals(kappa_finest, 0.0, ref[0], ref[1])  # the finest partition's offset, for the page
        rec[f"residual_finest_{name}"] = rf["residual"]
    return rec


def convergence_grid(tab, extent, box, coarsen, subsets, samples, n_boot, rng):
    """κ of one energy on the grid of box sides × sample counts, and its Poisson-bootstrap replicates.

    The partitions: the finest boxes (side ``box``) merged c × c for c in ``coarsen`` × the first M' ranks of
    each finest box for M' in ``subsets`` (``samples`` = all of them); M'·c² samples per merged box. Each of the
    ``n_boot`` replicates multiplies every sample's weight by one Poisson(1) count, the same at every
    partition, so that a replicate's grid can be extrapolated like the estimate's
    (:func:`kappa_convergence`). Returns (grid: box, samples, kappa; replicates: rep, box, samples, kappa —
    NaN where a replicate leaves no open class).

    Examples
    --------
    A map that sends every returning point to a uniform random point of the unit square (half escape, T = 1):
    κ is near ln 2 = 0.69 at every box side and sample count.

    >>> rng = np.random.default_rng(0)
    >>> n = 4000
    >>> tab = pd.DataFrame({"cell": np.arange(n) % 16, "rank": np.arange(n) // 16, "w": 1.0, "censored": False,
    ...                     "ret": rng.random(n) < 0.5, "T": 1.0, "x1": rng.random(n), "y1": rng.random(n)})
    >>> grid, reps = convergence_grid(tab, (0, 1, 0, 1), 0.25, [1, 2], [125, 250], 250, 3, 0)
    >>> grid.round(2).values.tolist(), len(reps)
    ([[0.25, 125.0, 0.68], [0.25, 250.0, 0.68], [0.5, 500.0, 0.69], [0.5, 1000.0, 0.68]], 12)
    """
    _partitions(tab, extent, box, coarsen, subsets)
    _checks.whole(samples, "samples")
    _checks.whole(n_boot, "n_boot", 0)
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


def energy_results(tab, extent, box, coarsen, subsets, samples, n_boot, n_boot_grid, seed, energy) -> dict:
    """Every κ of one energy's one-return samples ``tab`` (:func:`~hhscatter.analysis.geometry.ulam.one_return_samples`).

    Rows of κ per partition: the finest boxes (side ``box``) merged c × c for c in ``coarsen`` (``vary`` =
    "box", all ``samples`` per finest box) and the first M' samples per finest box for M' in ``subsets``
    (``vary`` = "samples"); the extrapolation grid of the three finest sides × ``subsets`` with ``n_boot_grid``
    bootstrap replicates (:func:`convergence_grid`, seeded by [seed, E·10⁶, 17]); ``n_boot`` Poisson-bootstrap
    replicates of κ on the finest partition (seed + E·1000); the saddle's class, its three largest classes and
    the cost (orbit-time, orbits, censored, mean return time). Returns a dict with keys tab, t, rows, boot,
    kappa, kappa_map, info, keep, ids, sub, tr, cost, grid, boot_grid, largest_classes.

    Examples
    --------
    16 boxes, each sending a quarter of its samples out, a quarter back into itself and half to the next box
    (T = 2): κ = ln(4/3)/2 at every partition.

    >>> cell, rank = np.repeat(np.arange(16), 16), np.tile(np.arange(16), 16)
    >>> nxt = np.where(rank % 4 == 1, cell, (cell + 1) % 16)
    >>> tab = pd.DataFrame({"cell": cell, "rank": rank, "w": 1.0, "censored": False, "ret": rank % 4 > 0,
    ...     "T": 2.0, "t_end": 2.0, "x1": -0.75 + 0.5 * (nxt % 4), "y1": -0.75 + 0.5 * (nxt // 4), "e1": 0.3})
    >>> res = energy_results(tab, (-1, 1, -1, 1), 0.5, [1, 2], [4, 16], 16, 3, 2, 1, 0.3)
    >>> bool(abs(res["kappa"] - math.log(4 / 3) / 2) < 1e-9), len(res["rows"]), len(res["grid"])
    (True, 4, 4)
    """
    _partitions(tab, extent, box, coarsen, subsets, t_end=True)
    _checks.whole(samples, "samples")
    _checks.whole(n_boot, "n_boot", 0)
    _checks.whole(n_boot_grid, "n_boot_grid", 0)
    check.count(seed, "seed", 0)
    check.number(energy, "energy")
    rows = []
    for c in coarsen:
        tr, _, _ = sample_transitions(tab, extent, box, c=int(c))
        kap, kmap, info, _, _ = saddle_kappa(tr)
        rows.append(
            {"energy": energy, "box": box * int(c), "samples": int(samples * c * c), "kappa": kap}
            | {"kappa_map": kmap, "vary": "box", **info}
        )
    for m in subsets:
        tr, _, _ = sample_transitions(tab, extent, box, m_max=int(m))
        kap, kmap, info, _, _ = saddle_kappa(tr)
        rows.append(
            {"energy": energy, "box": box, "samples": int(m), "kappa": kap, "kappa_map": kmap, "vary": "samples"} | info
        )
    grid, boot_grid = convergence_grid(
        tab, extent, box, list(coarsen)[:3], subsets, samples, n_boot_grid, [seed, int(round(energy * 1e6)), 17]
    )
    tr, ids, t = sample_transitions(tab, extent, box)
    boot = tf.bootstrap_kappa(tr, n_boot, rng=seed + int(energy * 1000))
    kap, kmap, info, keep, sub = saddle_kappa(tr)
    ok = ~tab["censored"]
    back = tab["ret"].to_numpy(dtype=bool)
    cost = {
        "orbit_time": float(tab["t_end"].sum()),
        "orbits": int(len(tab)),
        "censored": int((~ok).sum()),
        "mean_return_time": float(np.average(tab.loc[back, "T"], weights=tab.loc[back, "w"])),
    }
    return {
        "tab": tab,
        "t": t,
        "rows": rows,
        "boot": boot,
        "kappa": kap,
        "kappa_map": kmap,
        "info": info,
        "keep": keep,
        "ids": ids,
        "sub": sub,
        "tr": tr,
        "cost": cost,
        "grid": grid,
        "boot_grid": boot_grid,
        "largest_classes": [dict(c.__dict__) for c in tf.communicating_classes(tr)[1][:3]],
    }


def measure_on_cut_boxes(res, samples: int) -> dict:
    """Where the c-measure lives against the partition, from :func:`energy_results` ``res`` (finest boxes).

    A finest box holding fewer than ``samples`` points is cut by the section's boundary (V = E or r = r_esc):
    there the flux weight |ṗ_r|/v grows as 1/v and a box's row of M(κ) rests on few heavy points. Returns
    {cut_share: share of the saddle class's boxes that are cut, cut_nu: share of the c-measure ν (left
    Perron vector of M(κ) at the root) on them, cut_weight: share of the samples' flux weight on them,
    cut_top_weight: mean share of a cut box's flux weight carried by its heaviest sample, full_top_weight: the
    same for the full boxes}.

    Examples
    --------
    The 16 boxes of :func:`energy_results` with box 0 cut to 4 of its 16 points:

    >>> cell, rank = np.repeat(np.arange(16), 16), np.tile(np.arange(16), 16)
    >>> nxt = np.where(rank % 4 == 1, cell, (cell + 1) % 16)
    >>> tab = pd.DataFrame({"cell": cell, "rank": rank, "w": 1.0, "censored": False, "ret": rank % 4 > 0,
    ...     "T": 2.0, "t_end": 2.0, "x1": -0.75 + 0.5 * (nxt % 4), "y1": -0.75 + 0.5 * (nxt // 4), "e1": 0.3})
    >>> tab = tab[(tab.cell > 0) | (tab["rank"] < 4)]
    >>> r = measure_on_cut_boxes(energy_results(tab, (-1, 1, -1, 1), 0.5, [1], [16], 16, 2, 2, 1, 0.3), 16)
    >>> r["cut_share"], round(r["cut_nu"], 6), r["cut_top_weight"], r["full_top_weight"]
    (0.0625, 0.0625, 0.25, 0.0625)
    """
    _checks.mapping(res, "res", ("tab", "keep", "ids", "tr", "kappa"))
    _checks.whole(samples, "samples")
    tab, keep, ids = res["tab"], np.asarray(res["keep"], dtype=bool), np.asarray(res["ids"])
    count = tab.groupby("cell").size().reindex(ids, fill_value=0).to_numpy()
    cut = count < int(samples)
    nu, _ = tf.saddle_measure(res["tr"], res["kappa"], keep)
    cut_cells = ids[cut]
    on_cut = np.isin(tab["cell"].to_numpy(), cut_cells)
    w = tab["w"].to_numpy(dtype=float)
    top = tab.assign(_c=on_cut).groupby("cell").agg(top=("w", "max"), tot=("w", "sum"), c=("_c", "first"))
    share = top["top"] / top["tot"]
    return {
        "cut_share": float(cut[keep].mean()) if keep.any() else math.nan,
        "cut_nu": float(nu[cut].sum() / nu.sum()) if nu.sum() > 0 else math.nan,
        "cut_weight": float(w[on_cut].sum() / w.sum()),
        "cut_top_weight": float(share[top["c"]].mean()) if top["c"].any() else math.nan,
        "full_top_weight": float(share[~top["c"]].mean()) if (~top["c"]).any() else math.nan,
    }
