"""Section points of a dissipative ensemble against the conservative c-measure (paper Fig. 5 = fig:um_comparison).

Orbits started at E2 with drag γ cross the section ṙ = 0, φ̇ > 0 after the time t* at which Eq.
(eqn:energy_exp_decay) predicts E(t*) = E2 e^{−μγt*} = E1; their first crossing after t* (Fig. 5a), and those
in an energy band around E1 (Fig. 5b), are compared with samples of the conservative c-measure μ_c^{E1} and
μ_c^{E2}:

* :func:`crossing_sets` — the Fig. 5a/5b sets of one run and their counts;
* :func:`authors_record` — the summary rows of the authors' own 5a and 5b runs, in their convention;
* :func:`distance_tables` — Hellinger and TV on box histograms against the box side ε with split-half noise
  floors, bootstrap errors and the agreement scales ε*_2σ and ε*_δ, and the sliced Wasserstein distance, at one
  common split-half sample size (:func:`common_sample_size`);
* :func:`paired_differences`, :func:`paired_reference_distances`, :func:`paired_scale_curves` — the distances
  that a verdict rests on, with paired intervals over half-samples of the orbits of every set (references
  included): 5b − 5a, μ_c^{E2} − μ_c^{E1}, and the debiased Hellinger curve of Fig. 5a against ε for several
  relaxation times t* (panel (d)).

Settings shared by these steps are one :class:`ComparisonSettings`. Units: positions in the section's units
(x, y), box sides likewise; distances dimensionless except the sliced Wasserstein distance (units of length);
times in model time units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
import pandas as pd

from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.geometry import paired_distance as pdist

__all__ = [
    "DIFFERENCE_CONSTRUCTIONS",
    "ComparisonSettings",
    "authors_record",
    "cap_rows",
    "common_sample_size",
    "crossing_sets",
    "difference_record",
    "distance_tables",
    "interval_record",
    "paired_differences",
    "paired_reference_distances",
    "paired_scale_curves",
    "reference_record",
    "scale_of_curve",
    "within_radius",
]


@dataclass(frozen=True)
class ComparisonSettings:
    """Settings of the section-point comparisons.

    ``extent`` (x0, x1, y0, y1) of the box grid and ``boxes`` its box sides ε (section units); ``box_headline``
    the ε of the headline numbers; ``n_splits``, ``n_boot``, ``n_proj`` the split-half comparisons, bootstrap
    replicates and projections of the sliced Wasserstein distance; ``z`` the significance of ε*_2σ, ``delta``
    the δ of ε*_δ, ``noise_max`` the largest noise floor of an informative box side; ``n_cap`` the largest point
    set kept (a random subsample), ``m_min`` the smallest split-half size, ``seed`` the seed of every random
    choice; ``verdict_offsets`` k (k² placements of the box grid), ``verdict_boot`` and ``verdict_level`` the
    paired half-samples and the level of their intervals; ``r_cut`` the radius of the authors' plots.
    """

    extent: tuple
    boxes: tuple
    box_headline: float
    n_splits: int
    n_boot: int
    n_proj: int
    z: float
    delta: float
    noise_max: float
    n_cap: int
    m_min: int
    seed: int
    verdict_offsets: int = 4
    verdict_boot: int = 100
    verdict_level: float = 0.95
    r_cut: float = 1.0

    @classmethod
    def from_params(cls, params) -> ComparisonSettings:
        """The settings from any object with these attributes (a study's ``[study]`` parameters).

        Examples
        --------
        >>> from types import SimpleNamespace
        >>> p = SimpleNamespace(extent=[-1, 1, -1, 1], boxes=[0.5, 0.25], box_headline=0.25, n_splits=4, n_boot=10,
        ...     n_proj=8, z=2.0, delta=0.1, noise_max=0.5, n_cap=1000, m_min=10, seed=1, verdict_offsets=2,
        ...     verdict_boot=20, verdict_level=0.9, r_cut=1.0, other="ignored")
        >>> ComparisonSettings.from_params(p).extent
        (-1, 1, -1, 1)
        """
        kw = {f.name: getattr(params, f.name) for f in fields(cls)}
        return cls(**{**kw, "extent": tuple(kw["extent"]), "boxes": tuple(kw["boxes"])})


def cap_rows(df: pd.DataFrame, n_cap: int, seed: int) -> pd.DataFrame:
    """At most ``n_cap`` rows of ``df``: a random subsample (seeded) in the original order, re-indexed.

    Examples
    --------
    >>> df = pd.DataFrame({"traj_id": range(10)})
    >>> len(cap_rows(df, 4, 0)), cap_rows(df, 20, 0)["traj_id"].tolist() == list(range(10))
    (4, True)
    """
    if len(df) <= n_cap:
        return df.reset_index(drop=True)
    idx = np.sort(np.random.default_rng(seed).choice(len(df), n_cap, replace=False))
    return df.iloc[idx].reset_index(drop=True)


def within_radius(df: pd.DataFrame, r_cut: float) -> pd.DataFrame:
    """The rows with r = √(x² + y²) < ``r_cut`` (the authors' plots), re-indexed.

    Examples
    --------
    >>> within_radius(pd.DataFrame({"x": [0.5, 0.9], "y": [0.5, 0.9]}), 1.0)["x"].tolist()
    [0.5]
    """
    return df[np.hypot(df["x"], df["y"]) < r_cut].reset_index(drop=True)


def crossing_sets(sections: pd.DataFrame, t_end, t_star: float, band, n_cap: int, seed: int):
    """(Fig. 5a set, Fig. 5b set, counts) of one dissipative run at relaxation time ``t_star``.

    ``sections``: its crossings (traj_id, t, x, y, energy; those at t ≥ t* suffice); ``t_end``: every orbit's
    end time. 5a is the first crossing at t ≥ t* of each orbit (:func:`~hhscatter.analysis.geometry.distance.first_crossings`),
    capped at ``n_cap`` points (:func:`cap_rows`); 5b those of 5a with energy in ``band`` = (lo, hi). The counts:
    N, n_alive_t_star (orbits still running after t*), n_a_all (5a before the cap), n_a, n_b and the mean energy,
    its spread and the mean time of 5a.

    Examples
    --------
    >>> sec = pd.DataFrame({"traj_id": [0, 0, 1, 2], "t": [1.0, 6.0, 7.0, 8.0], "x": [0.1] * 4, "y": [0.2] * 4,
    ...                     "energy": [0.33, 0.30, 0.31, 0.299]})
    >>> a, b, n = crossing_sets(sec, [9.0, 9.0, 9.0, 3.0], 5.0, (0.295, 0.305), 100, 0)
    >>> a["traj_id"].tolist(), b["traj_id"].tolist(), n["n_alive_t_star"]
    ([0, 1, 2], [0, 2], 3)
    """
    first = dist.first_crossings(sections, t_star)
    a = cap_rows(first, n_cap, seed)
    b = a[(a["energy"] >= band[0]) & (a["energy"] <= band[1])].reset_index(drop=True)
    t_end = np.asarray(t_end)
    counts = {
        "N": len(t_end),
        "n_alive_t_star": int((t_end > t_star).sum()),
        "n_a_all": int(first["traj_id"].size),
        "n_a": len(a),
        "n_b": len(b),
        "mean_E_a": float(a["energy"].mean()) if len(a) else math.nan,
        "std_E_a": float(a["energy"].std()) if len(a) > 1 else math.nan,
        "mean_t_a": float(a["t"].mean()) if len(a) else math.nan,
    }
    return a, b, counts


def common_sample_size(sets: dict, ref, m_min: int):
    """({set: m}, m_common): split-half sample sizes of the comparisons of ``sets`` with the reference ``ref``.

    m = min(|set|, |ref|) // 2 per set; the sets with m ≥ ``m_min`` are kept and the smallest of their m is
    common to all (agreement scales compare across sets only at one sample size). ValueError if none is kept.

    Examples
    --------
    >>> common_sample_size({"a": range(50), "b": range(30), "c": range(4)}, range(40), 5)
    ({'a': 20, 'b': 15}, 15)
    """
    sizes = {k: min(len(v), len(ref)) // 2 for k, v in sets.items()}
    usable = {k: s for k, s in sizes.items() if s >= m_min}
    if not usable:
        raise ValueError(f"no point set has ≥ 2·m_min = {2 * m_min} points; raise n or lower m_min")
    return usable, min(usable.values())


def distance_tables(sets: dict, refs: dict, usable: dict, m_common: int, s: ComparisonSettings):
    """(distance vs box side, summary): every set of ``sets`` against μ_c^{E1} and μ_c^{E2}, and μ_c^{E2}
    against μ_c^{E1}.

    ``sets`` {(γ, set label): DataFrame with x, y}; ``refs`` {"E1", "E2": (n, 2) points}; ``usable`` and
    ``m_common`` from :func:`common_sample_size` (against E1: the common m; against E2: each its own largest).
    Per comparison: Hellinger and TV against ε with split-half noise floors
    (:func:`~hhscatter.analysis.geometry.distance.distance_vs_scale`), their bootstrap errors and the sliced
    Wasserstein distance SW1 with its error and its noise floor at m, the agreement scales ε*_2σ and ε*_δ and
    the debiased Hellinger distance with its interval; the summary at ``box_headline``. Sets of fewer than 4
    points are left out.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> s = ComparisonSettings((-1, 1, -1, 1), (1.0, 0.5), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1)
    >>> sets = {(0.01, "a"): pd.DataFrame(rng.uniform(-1, 1, (60, 2)), columns=["x", "y"])}
    >>> refs = {"E1": rng.uniform(-1, 1, (80, 2)), "E2": rng.uniform(-1, 1, (80, 2))}
    >>> dtab, stab = distance_tables(sets, refs, {(0.01, "a"): 30}, 30, s)
    >>> stab[["set", "ref", "m"]].values.tolist()
    [['a', 'E1', 30], ['a', 'E2', 30], ['cm_E2', 'E1', 40]]
    """
    boxes = np.sort(np.asarray(s.boxes))[::-1]
    seed, n_proj = s.seed, s.n_proj
    rows, summary = [], []
    comps = [(k, ref) for k in sets for ref in ("E1", "E2")] + [(("ref", "E2"), "E1")]
    for key, ref in comps:
        if key == ("ref", "E2"):
            P, label_g, label_s = refs["E2"], math.nan, "cm_E2"
        else:
            P, (label_g, label_s) = dist.points(sets[key]), key
            if len(P) < 4:
                continue
        Q = refs[ref]
        m = m_common if key in usable and ref == "E1" else None
        tab = dist.distance_vs_scale(P, Q, boxes, s.extent, n_splits=s.n_splits, seed=seed, m=m)
        # full-sample Hellinger/TV at every box and SW1, each with its bootstrap std (same resamples)
        _, (hb, sw_err) = dist.bootstrap_distance(
            P,
            Q,
            lambda A, B: (
                dist.box_distances(A, B, boxes, s.extent),
                dist.sliced_wasserstein(A, B, n_proj=n_proj, seed=seed + 1),
            ),
            n_boot=s.n_boot,
            seed=seed + 1,
        )
        tab["hellinger_boot_err"] = hb[:, 0]
        tab["tv_boot_err"] = hb[:, 1]
        tab["common_m"] = m is not None
        sw = dist.sliced_wasserstein(P, Q, n_proj=n_proj, seed=seed)
        # sliced-Wasserstein noise floor at the comparison's sample size m
        sw_noise = dist.split_half_noise(
            P,
            Q,
            lambda A, B: dist.sliced_wasserstein(A, B, n_proj=n_proj, seed=seed),
            m=int(tab["m"].iloc[0]),
            n_splits=max(s.n_splits, 1),
            seed=seed + 2,
        ).mean
        eps_star = dist.agreement_scale(tab, "hellinger", z=s.z, noise_max=s.noise_max)
        eps_deb = dist.agreement_scale_debiased(tab, s.delta, "hellinger", noise_max=s.noise_max)
        tab["hellinger_debiased"], tab["hellinger_debiased_lo"], tab["hellinger_debiased_hi"] = dist.debiased_distance(
            tab, "hellinger"
        )
        tab = tab.assign(gamma=label_g, set=label_s, ref=ref, n_P=len(P), n_Q=len(Q))
        rows.append(tab)
        jh = int(np.argmin(np.abs(tab["box"].to_numpy() - s.box_headline)))
        at = lambda col, tab=tab, jh=jh: float(tab[col].iloc[jh])  # noqa: E731
        summary.append(
            {
                "gamma": label_g,
                "set": label_s,
                "ref": ref,
                "n_P": len(P),
                "n_Q": len(Q),
                "m": int(tab["m"].iloc[0]),
                "common_m": m is not None,
                "sw1": sw,
                "sw1_err": sw_err,
                "sw1_noise_m": sw_noise,
                "box_headline": at("box"),
                "hellinger": at("hellinger"),
                "hellinger_err": at("hellinger_boot_err"),
                "tv": at("tv"),
                "tv_err": at("tv_boot_err"),
                "hellinger_pq": at("hellinger_pq"),
                "hellinger_noise": at("hellinger_noise"),
                "hellinger_debiased": at("hellinger_debiased"),
                "hellinger_debiased_lo": at("hellinger_debiased_lo"),
                "hellinger_debiased_hi": at("hellinger_debiased_hi"),
                "agreement_scale": eps_star,
                "agreement_scale_debiased": eps_deb,
            }
        )
    return pd.concat(rows, ignore_index=True), pd.DataFrame(summary)


def authors_record(sets: dict, refs: dict, convention: str, s: ComparisonSettings) -> dict:
    """The record of a Fig. 5 construction other than ours (the authors' runs): point counts and summary rows.

    ``sets`` {(group, label): DataFrame with x, y}: the sets of that construction, already cut and capped as it
    plots them; ``refs`` {"E1", "E2": (n, 2) c-measure points}; ``convention`` the sentence that states the
    construction. The rows are the summary of :func:`distance_tables` (distances at ``s.box_headline`` to μ_c^{E1}
    and μ_c^{E2}, each set at its common split-half size against E1), without the μ_c^{E2}-against-μ_c^{E1} row;
    None when no set has 2·``s.m_min`` points (:func:`common_sample_size`).

    Returns
    -------
    dict
        convention, n_points ({label: number of points}) and rows (list of dicts or None).

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> s = ComparisonSettings((-1, 1, -1, 1), (1.0, 0.5), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1)
    >>> pts = lambda n: pd.DataFrame(rng.uniform(-1, 1, (n, 2)), columns=["x", "y"])
    >>> refs = {"E1": rng.uniform(-1, 1, (80, 2)), "E2": rng.uniform(-1, 1, (80, 2))}
    >>> rec = authors_record({("authors", "5a"): pts(60), ("authors", "5b"): pts(30)}, refs, "their runs", s)
    >>> rec["n_points"], [(r["set"], r["ref"], r["m"]) for r in rec["rows"]]
    ({'5a': 60, '5b': 30}, [('5a', 'E1', 15), ('5a', 'E2', 30), ('5b', 'E1', 15), ('5b', 'E2', 15)])
    >>> authors_record({("authors", "5a"): pts(6)}, refs, "their runs", s)["rows"] is None
    True
    """
    out = {"convention": convention, "n_points": {k[1]: len(v) for k, v in sets.items()}, "rows": None}
    try:
        usable, m = common_sample_size(sets, refs["E1"], s.m_min)
    except ValueError:
        return out
    _, stab = distance_tables(sets, refs, usable, m, s)
    out["rows"] = stab[stab["set"] != "cm_E2"].reset_index(drop=True).to_dict(orient="records")
    return out


def interval_record(values, level: float) -> dict:
    """{value, interval}: the mean of replicates and their percentile interval at ``level``.

    Examples
    --------
    >>> interval_record([1.0, 2.0, 3.0], 0.5)
    {'value': 2.0, 'interval': [1.5, 2.5]}
    """
    m, lo, hi = pdist.percentile_interval(values, level)
    return {"value": m, "interval": [lo, hi]}


def _unit_set(df: pd.DataFrame, group: str) -> pdist.UnitSet:
    return pdist.UnitSet(dist.points(df), df["traj_id"].to_numpy(), group)


def paired_differences(constructions, s: ComparisonSettings) -> list:
    """Rows of the paired difference Δ = d(B) − d(A) of two sets' distances to a reference, per construction.

    ``constructions``: (key, label, offsets or None, (A, B, R)) with A, B, R DataFrames (traj_id, x, y); the
    distances are debiased Hellinger distances at ``box_headline`` averaged over offsets² placements of the box
    grid (``verdict_offsets`` when None), with a paired interval over half-samples of every set's orbits
    (:func:`~hhscatter.analysis.geometry.paired_distance.paired_hellinger_difference`). A construction whose
    sets are too small gets a row with a ``note`` instead.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> df = lambda n: pd.DataFrame({"traj_id": np.arange(n), "x": rng.uniform(-1, 1, n), "y": rng.uniform(-1, 1, n)})
    >>> s = ComparisonSettings((-1, 1, -1, 1), (0.5,), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1, verdict_offsets=1, verdict_boot=10)
    >>> rows = paired_differences([("x", "two uniform sets", None, (df(400), df(400), df(400)))], s)
    >>> rows[0]["offsets"], rows[0]["delta_interval"][0] < 0 < rows[0]["delta_interval"][1]
    (1, True)
    """
    rows = []
    for key, label, offs, (A, B, R) in constructions:
        try:
            r = pdist.paired_hellinger_difference(
                dist.points(A),
                dist.points(B),
                dist.points(R),
                s.box_headline,
                s.extent,
                units_a=A["traj_id"].to_numpy(),
                units_b=B["traj_id"].to_numpy(),
                units_r=R["traj_id"].to_numpy(),
                offsets=offs or s.verdict_offsets,
                n_boot=s.verdict_boot,
                level=s.verdict_level,
                seed=s.seed,
            )
        except ValueError as e:  # too few points (tiny scale)
            rows.append({"construction": key, "label": label, "note": str(e)})
            continue
        rows.append(
            {
                "construction": key,
                "label": label,
                "offsets": (offs or s.verdict_offsets) ** 2,
                "box": s.box_headline,
                "n_5a": len(A),
                "n_5b": len(B),
                "n_ref": len(R),
                "d_5a": r.d_a,
                "d_5a_interval": list(r.d_a_interval),
                "d_5b": r.d_b,
                "d_5b_interval": list(r.d_b_interval),
                "delta": r.delta,
                "delta_interval": [r.lo, r.hi],
                "offset_spread_of_delta": r.offset_spread,
            }
        )
    return rows


def paired_reference_distances(constructions, s: ComparisonSettings):
    """(rows, curves, box): each set's distances to μ_c^{E1} and μ_c^{E2}, paired, per construction.

    ``constructions``: (key, label, runs {"5a", "5b": DataFrame}, refs {"E1", "E2": DataFrame}), DataFrames with
    traj_id, x, y. The runs' sets share one id space and are half-sampled together, and so are the two
    references (the same orbits at E1 and E2), the two draws independent
    (:func:`~hhscatter.analysis.geometry.paired_distance.paired_hellinger_replicates`). Rows per set at
    ``box_headline``: d_E1, d_E2 and Δ = d_E2 − d_E1 (> 0: closer to μ_c^{E1}) with percentile intervals
    (:func:`interval_record`); curves per construction: every pair's mean distance and band against the box
    side (boxes decreasing); ``box`` the headline box side used. A construction whose sets are too small
    gets a row with a ``note``.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> df = lambda n: pd.DataFrame({"traj_id": np.arange(n), "x": rng.uniform(-1, 1, n), "y": rng.uniform(-1, 1, n)})
    >>> s = ComparisonSettings((-1, 1, -1, 1), (0.5, 1.0), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1, verdict_offsets=1, verdict_boot=10)
    >>> rows, curves, box = paired_reference_distances(
    ...     [("ours", "uniform", {"5a": df(300), "5b": df(300)}, {"E1": df(300), "E2": df(300)})], s)
    >>> [r["set"] for r in rows], box, len(curves["ours"])
    (['5a', '5b'], 0.5, 5)
    """
    boxes = sorted(map(float, s.boxes), reverse=True)
    jh = int(np.argmin(np.abs(np.array(boxes) - s.box_headline)))
    level = s.verdict_level
    rows, panel_c = [], {}
    for key, label, runs, refs in constructions:
        sets = {k: _unit_set(df, "run") for k, df in runs.items()}
        sets.update({r: _unit_set(df, "cm") for r, df in refs.items()})
        pairs = [(k, r) for k in runs for r in ("E1", "E2")] + [("E2", "E1")]
        try:
            curves = pdist.paired_hellinger_replicates(
                sets, pairs, boxes, s.extent, offsets=s.verdict_offsets, n_boot=s.verdict_boot, seed=s.seed
            )
        except ValueError as e:  # too few points (tiny scale)
            rows.append({"construction": key, "label": label, "note": str(e)})
            continue
        reps = curves[:, :, jh]
        q = (1 - level) / 2
        panel_c[key] = [
            {
                "set": x,
                "ref": r,
                "d": curves[:, i].mean(axis=0).tolist(),
                "d_lo": np.quantile(curves[:, i], q, axis=0).tolist(),
                "d_hi": np.quantile(curves[:, i], 1 - q, axis=0).tolist(),
            }
            for i, (x, r) in enumerate(pairs)
        ]
        for k in runs:
            i1, i2 = pairs.index((k, "E1")), pairs.index((k, "E2"))
            rows.append(
                {
                    "construction": key,
                    "label": label,
                    "set": k,
                    "n_set": len(runs[k]),
                    "n_E1": len(refs["E1"]),
                    "n_E2": len(refs["E2"]),
                    "d_E1": interval_record(reps[:, i1], level),
                    "d_E2": interval_record(reps[:, i2], level),
                    "delta": interval_record(reps[:, i2] - reps[:, i1], level),
                }
            )
    return rows, panel_c, boxes[jh]


def scale_of_curve(boxes, d, informative, delta: float) -> float:
    """ε*_δ of one distance curve: the smallest box side down to which d ≤ δ at every informative side.

    ``boxes`` decreasing; inf if d > δ already at the coarsest informative side (or none is informative).

    Examples
    --------
    >>> scale_of_curve([1.0, 0.5, 0.25], [0.05, 0.08, 0.2], [True, True, True], 0.1)
    0.5
    >>> scale_of_curve([1.0, 0.5], [0.2, 0.05], [True, True], 0.1)
    inf
    """
    best = math.inf
    for b, v, ok in zip(boxes, d, informative):
        if not ok:
            continue
        if v > delta:
            break
        best = b
    return best


def _finite(x):
    return float(x) if np.isfinite(x) else None


def paired_scale_curves(sets_a: dict, t_star: dict, dtab: pd.DataFrame, ref: pd.DataFrame, s: ComparisonSettings):
    """Panel (d): Fig. 5a at every γ against μ_c^{E1} on common half-samples, ordered by relaxation time t*.

    ``sets_a`` {γ: 5a set (traj_id, x, y)} of runs that share their initial conditions (one draw of the orbits
    serves every γ); ``t_star`` {γ: t*}; ``dtab`` the table of :func:`distance_tables` (its noise floors say
    which box sides are informative: ≤ ``noise_max``); ``ref`` the μ_c^{E1} sample. Per γ: the debiased
    Hellinger curve against ε with percentile bands and ε*_δ (:func:`scale_of_curve`) of the mean curve with
    its interval over replicates; the share of replicates in which ε*_δ shrinks with t*; the paired differences
    of d at ``box_headline`` between consecutive t*. None with fewer than two sets of ≥ 4 points; a dict with a
    ``note`` when the sets are too small to half-sample.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> df = lambda n: pd.DataFrame({"traj_id": np.arange(n), "x": rng.uniform(-1, 1, n), "y": rng.uniform(-1, 1, n)})
    >>> s = ComparisonSettings((-1, 1, -1, 1), (1.0, 0.5), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1, verdict_offsets=1, verdict_boot=10)
    >>> dtab = pd.DataFrame({"gamma": [0.01, 0.01, 0.02, 0.02], "set": "a", "ref": "E1", "box": [1.0, 0.5] * 2,
    ...                      "hellinger_noise": [0.1, 0.9] * 2})
    >>> rec = paired_scale_curves({0.01: df(300), 0.02: df(300)}, {0.01: 17.0, 0.02: 8.5}, dtab, df(300), s)
    >>> [c["gamma"] for c in rec["curves"]], rec["curves"][0]["informative"]
    ([0.02, 0.01], [True, False])
    """
    level, delta = s.verdict_level, s.delta
    boxes = sorted(map(float, s.boxes), reverse=True)
    gammas = sorted(sets_a, key=lambda g: float(t_star[g]))
    gammas = [g for g in gammas if len(sets_a[g]) >= 4]
    if len(gammas) < 2:
        return None
    # every γ's run starts from the same ICs (one seed): one draw of the orbits serves all γ (paired across t*)
    units = {f"a{g:g}": _unit_set(sets_a[g], "run") for g in gammas}
    units["E1"] = _unit_set(ref, "cm_E1")
    pairs = [(f"a{g:g}", "E1") for g in gammas]
    try:
        reps = pdist.paired_hellinger_replicates(
            units, pairs, boxes, s.extent, offsets=s.verdict_offsets, n_boot=s.verdict_boot, seed=s.seed
        )
    except ValueError as e:  # too few points (tiny scale)
        return {"note": str(e)}
    q = (1 - level) / 2
    jh = int(np.argmin(np.abs(np.array(boxes) - s.box_headline)))
    eps = np.empty((reps.shape[0], len(gammas)))
    curves = []
    for i, g in enumerate(gammas):
        tab = dtab[(dtab["gamma"] == g) & (dtab["set"] == "a") & (dtab["ref"] == "E1")].set_index("box")
        informative = np.array(
            [float(tab.loc[b, "hellinger_noise"]) <= s.noise_max if b in tab.index else False for b in boxes]
        )
        eps[:, i] = [scale_of_curve(boxes, reps[k, i], informative, delta) for k in range(reps.shape[0])]
        e_mean = scale_of_curve(boxes, reps[:, i].mean(axis=0), informative, delta)
        curves.append(
            {
                "gamma": g,
                "t_star": float(t_star[g]),
                "n_a": len(sets_a[g]),
                "d": reps[:, i].mean(axis=0).tolist(),
                "d_lo": np.quantile(reps[:, i], q, axis=0).tolist(),
                "d_hi": np.quantile(reps[:, i], 1 - q, axis=0).tolist(),
                "informative": informative.tolist(),
                "eps_delta": _finite(e_mean),
                "eps_delta_interval": [
                    _finite(np.quantile(eps[:, i], q, method="lower")),
                    _finite(np.quantile(eps[:, i], 1 - q, method="higher")),
                ],
            }
        )
    # ε* = inf (no agreement at any informative scale) sorts last; shrinking: non-increasing with t*, overall smaller
    shrinks = np.all(eps[:, 1:] <= eps[:, :-1], axis=1) & (eps[:, -1] < eps[:, 0])
    steps = [
        {
            "t_from": float(t_star[g0]),
            "t_to": float(t_star[g1]),
            "gamma_from": g0,
            "gamma_to": g1,
            **interval_record(reps[:, i + 1, jh] - reps[:, i, jh], level),
        }
        for i, (g0, g1) in enumerate(zip(gammas[:-1], gammas[1:]))
    ]
    return {
        "boxes": boxes,
        "box_headline": boxes[jh],
        "delta": delta,
        "level": level,
        "n_boot": int(reps.shape[0]),
        "offsets": s.verdict_offsets**2,
        "n_ref": len(ref),
        "curves": curves,
        "eps_shrink_share": float(shrinks.mean()),
        "steps": steps,
        "method": "paired half-sampling over orbits: one draw of the ICs for every γ's run (one seed), one of the "
        "reference's, independent; debiased Hellinger averaged over grid placements; ε*_δ per replicate",
    }


#: the constructions of the 5b − 5a verdict (:func:`difference_record`): key, description, grid offsets k (k²
#: placements of the box grid; None: ``verdict_offsets``)
DIFFERENCE_CONSTRUCTIONS = (
    ("old", "the authors' 5a/5b cut at r < 1, the references not cut (the construction this page used first)", 1),
    ("cut", "r < 1 on every set (5a, 5b, μ_c^0.30)", 1),
    ("cut_offsets", "r < 1 on every set, averaged over grid offsets", None),
    ("cut_offsets_random", "r < 1 on every set, averaged over grid offsets, momenta in random directions", None),
    (
        "ours",
        "our construction (disk ICs; 5a: first crossing after t*, 5b: those in the band; no cut on any set), "
        "averaged over grid offsets",
        None,
    ),
)


def difference_record(reference, ours, authors, authors_random, s: ComparisonSettings, *, E1, momentum) -> dict:
    """The 5b − 5a verdict in every construction of :data:`DIFFERENCE_CONSTRUCTIONS`, as a numbers-JSON record.

    Debiased Hellinger distances to μ_c^{E1} at ``box_headline`` and their paired difference Δ = d(5b) − d(5a),
    half-sampling the orbits of every set, the reference included (:func:`paired_differences`); the sets of one
    comparison are cut alike. ``reference``: the c-measure points at ``E1`` (traj_id, x, y; not capped);
    ``ours``: (5a, 5b) of our construction; ``authors``, ``authors_random``: (5a, 5b) of the authors' runs with
    their tangential momenta and with the momenta ``momentum`` (a scene's momentum convention), already cut at
    r < ``r_cut``. Rows with a note where the sets are too small.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> df = lambda n: pd.DataFrame({"traj_id": np.arange(n), "x": rng.uniform(-1, 1, n), "y": rng.uniform(-1, 1, n)})
    >>> s = ComparisonSettings((-1, 1, -1, 1), (0.5,), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1, verdict_offsets=2, verdict_boot=10)
    >>> rec = difference_record(df(300), (df(300), df(300)), (df(200), df(200)), (df(200), df(200)), s, E1=0.3,
    ...                         momentum="random")
    >>> [(r["construction"], r["offsets"]) for r in rec["rows"]]
    [('old', 1), ('cut', 1), ('cut_offsets', 4), ('cut_offsets_random', 4), ('ours', 4)]
    """
    ref_all = cap_rows(reference, s.n_cap, s.seed)
    ref_cut = cap_rows(within_radius(reference, s.r_cut), s.n_cap, s.seed)
    sets = {
        "old": (*authors, ref_all),
        "cut": (*authors, ref_cut),
        "cut_offsets": (*authors, ref_cut),
        "cut_offsets_random": (*authors_random, ref_cut),
        "ours": (*ours, ref_all),
    }
    rows = paired_differences([(key, label, offs, sets[key]) for key, label, offs in DIFFERENCE_CONSTRUCTIONS], s)
    return {
        "reference": f"μ_c^{E1:g} (fig1's sprinkler points)",
        "level": s.verdict_level,
        "n_boot": s.verdict_boot,
        "method": "paired half-sampling over orbits of every set (reference included); H² debiased with the "
        "complementary halves; averaged over offsets² placements of the box grid",
        "like_for_like": "in every row but 'old' the three sets are cut alike (r < 1 for the authors' sets, "
        "no cut for ours)",
        "momentum_convention": "tangential, ṙ = 0 and φ̇ > 0: the authors' goodICs sets (dx, dy) = (−y, x)/|q|·"
        "√(2(E − V)) (LnBn/DissipativeScattering@0868eff, "
        "src/dissipative_scattering_functions.jl lines 421–422, in goodICs, line 410), "
        "as region 'square' does here",
        "sensitivity_momentum": f"row 'cut_offsets_random': the authors' two runs again with momentum = "
        f"{momentum!r} (directions uniform on the circle, "
        "|p| = √(2(E − V)), the same positions), cut and compared like 'cut_offsets'",
        "rows": rows,
    }


def reference_record(references: dict, ours, authors, s: ComparisonSettings, *, E1, E2) -> dict:
    """Fig. 5a/5b against μ_c^{E1} and μ_c^{E2}, paired, in two constructions, as a numbers-JSON record.

    ``references``: {"E1", "E2": c-measure points (traj_id, x, y), not capped}; ``ours``: (5a, 5b) of our
    construction (no cut); ``authors``: (5a, 5b) of the authors' runs (r < ``r_cut`` on every set, the
    references too). :func:`paired_reference_distances` of both; the record holds its rows and curves (panel
    (c)) with the settings they used.

    Examples
    --------
    >>> rng = np.random.default_rng(0)
    >>> df = lambda n: pd.DataFrame({"traj_id": np.arange(n), "x": rng.uniform(-1, 1, n), "y": rng.uniform(-1, 1, n)})
    >>> s = ComparisonSettings((-1, 1, -1, 1), (0.5, 1.0), 0.5, n_splits=2, n_boot=3, n_proj=4, z=2, delta=0.1,
    ...                        noise_max=0.5, n_cap=10**4, m_min=5, seed=1, verdict_offsets=1, verdict_boot=10)
    >>> rec = reference_record({"E1": df(300), "E2": df(300)}, (df(300), df(300)), (df(300), df(300)), s,
    ...                        E1=0.3, E2=0.35)
    >>> [(r["construction"], r["set"]) for r in rec["rows"]], rec["box"], rec["boxes"]
    ([('ours', '5a'), ('ours', '5b'), ('authors', '5a'), ('authors', '5b')], 0.5, [1.0, 0.5])
    """
    cut = {k: cap_rows(within_radius(v, s.r_cut), s.n_cap, s.seed) for k, v in references.items()}
    uncut = {k: cap_rows(v, s.n_cap, s.seed) for k, v in references.items()}
    # one seed, one id space: 5a and 5b are the same orbits (ours: 5b ⊂ 5a; the authors': two runs of the same
    # ICs), and so are the two references (the same positions at E1 and E2): each pair is drawn together
    constructions = (
        (
            "ours",
            "our construction (disk ICs, γ = gamma_main, 5b = 5a in the band), no cut on any set",
            {"5a": ours[0], "5b": ours[1]},
            uncut,
        ),
        (
            "authors",
            "the authors' 5a and 5b runs, r < 1 on every set (5a, 5b, μ_c^0.30, μ_c^0.35)",
            {"5a": authors[0], "5b": authors[1]},
            cut,
        ),
    )
    rows, panel_c, box = paired_reference_distances(constructions, s)
    return {
        "box": box,
        "offsets": s.verdict_offsets**2,
        "level": s.verdict_level,
        "n_boot": s.verdict_boot,
        "E1": E1,
        "E2": E2,
        "boxes": sorted(map(float, s.boxes), reverse=True),
        "curves": panel_c,
        "method": "paired half-sampling over orbits: one draw of the run's orbits serves 5a, 5b and both "
        "distances, one draw of fig1's orbits both references (one seed: the same positions at E1 and "
        "E2), the two draws independent; debiased Hellinger averaged over grid placements",
        "rows": rows,
    }
