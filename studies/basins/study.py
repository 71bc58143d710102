"""Study ``basins``: exit basins and their fractality under dissipation (beyond the paper; issue 16).

The paper's conclusion expects fractal structure in dissipative scattering
"in suitable limits of E0, γ and t", with a cut-off in the scaling coming
from the mixing of c-measures of different energies. This study measures it
on the standard figures of chaotic scattering (Aguirre, Vallejo & Sanjuán,
PRE 64, 066208 (2001); Daza et al., Sci. Rep. 6, 31416 (2016)):

1. **Basin maps.** Initial conditions on the section ṙ = 0, φ̇ > 0 at E0
   (:func:`hhscatter.ics.section_grid`, tangential velocities) on a regular
   grid over the authors' square [−1, 1]²; each cell coloured by its outcome
   (exit channel 0/1/2, settled, trapped at t_max), from the engine's exact
   event outcomes with r_esc = 1.5 (beyond every exit's Lyapunov orbit, study
   resc). Two magnifications of one boundary region, centred on the most
   mixed cell of the γ = 0 map.
2. **Measures** per (E0, γ) (:mod:`hhscatter.analysis.basins`): basin
   fractions (Wilson), basin entropy S_b and boundary basin entropy S_bb over
   box sizes with the log 2 test, the Wada merging test, and the uncertainty
   exponent α from f(ε), the fraction of initial conditions whose outcome
   changes under a shift ε of x (fresh initial conditions at each ε, down to
   ε = 1e-9: exact event times and tol 1e-15 resolve it); d = 2 − α.
3. **The paper's cut-off.** A broken power law against the single one for
   f(ε) (:func:`~hhscatter.analysis.basins.uncertainty_cutoff`): ε_c(γ) or an
   upper bound; and the lifetimes of the orbits that decide the outcome at
   the smallest ε, against τ2 = ln(E0/E_c)/γ (Eq. (eq:tau2) with μ = 1, the
   late-time exponent of study fig3).

Outcome codes: 0, 1, 2 exit channel (the 120° sector of the escape point);
3 settled; 4 trapped (alive at t_max); −1 forbidden cell (V ≥ E0).
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.config import Integer, Number, Numbers, StudyParams

SETTLED_CODE, TRAPPED_CODE, OUTSIDE = 3, 4, -1
CODES = (0, 1, 2, SETTLED_CODE, TRAPPED_CODE)
CODE_NAMES = ("exit 0", "exit 1", "exit 2", "settled", "trapped")


class Params(StudyParams):
    """``[study]`` of studies/basins/study.toml."""

    energies: Numbers
    gammas: Numbers
    extent: Numbers
    grid: Integer
    zoom_energy: Number
    zoom_gammas: Numbers
    zoom_factors: Numbers
    zoom_grid: Integer
    boxes: Numbers
    box_headline: Integer
    eps: Numbers
    n_uncertainty: Integer
    fit_min_count: Integer = 10
    wada_r: Integer = 3
    wada_min_share: Number = 0.005
    symmetry_radius: Number = 0.9
    scan_energies: Numbers = ()
    scan_grid: Integer = 200
    scan_eps: Numbers = ()
    scan_n_uncertainty: Integer = 4000


# -- keys and grids ----------------------------------------------------------------
def _tag(E, g):
    return f"E{E:.2f}_g{g:g}"


def map_key(E, g):
    return f"map_{_tag(E, g)}"


def zoom_key(E, g, factor):
    return f"zoom{factor:g}_{_tag(E, g)}"


def unc_key(E, g, i):
    return f"unc{i}_{_tag(E, g)}"


def scan_map_key(E):
    return f"scan_map_{_tag(E, 0.0)}"


def scan_unc_key(E, i):
    return f"scan_unc{i}_{_tag(E, 0.0)}"


def _scan(study):
    """(energies, ε) of the γ = 0 energy scan (issue 25, point 5); energies must lie above E_c."""
    energies = [float(E) for E in study.param("scan_energies")]
    eps = np.asarray(study.param("scan_eps"), dtype=float)
    if energies:
        ec = study.model.critical_energy
        if min(energies) <= ec:
            raise ValueError(f"basins [study].scan_energies must lie above E_c = {ec:.6g}")
        if not (eps.size >= 2 and np.all(eps > 0) and np.all(np.diff(eps) < 0)):
            raise ValueError("basins [study].scan_eps must be decreasing positive numbers")
    return energies, eps


def _eps(study):
    eps = np.asarray(study.param("eps"), dtype=float)
    if not (eps.size >= 2 and np.all(eps > 0) and np.all(np.diff(eps) < 0)):
        raise ValueError("basins [study].eps must be decreasing positive numbers")
    return eps


def outcome_codes(lt: pd.DataFrame) -> np.ndarray:
    """outcome_codes(lifetimes) -> int8 codes in traj_id order: exit channel, 3 settled, 4 trapped/stopped."""
    lt = lt.sort_values("traj_id")
    oc = lt["outcome"].astype(str).to_numpy()
    ch = lt["exit_channel"].to_numpy(dtype=float, na_value=-1)
    code = np.full(len(lt), TRAPPED_CODE, dtype=np.int8)
    esc = oc == "escaped"
    code[esc] = ch[esc].astype(np.int8)
    code[oc == "settled"] = SETTLED_CODE
    return code


# -- simulate --------------------------------------------------------------------------
def _run_table(study, key, states, gamma, workers, progress):
    """Run the initial conditions ``states`` (m, 4) through the engine (runner: resume, progress, Dask)."""
    path = study.raw(key + "_ics.parquet")
    path.parent.mkdir(parents=True, exist_ok=True)
    df = pd.DataFrame(states, columns=["x", "y", "px", "py"])
    df.insert(0, "traj_id", np.arange(len(df), dtype=np.int64))
    # rewritten only when different: the scene's hash includes the file's, and resume relies on it
    if not path.exists() or not pd.read_parquet(path).equals(df):
        df.to_parquet(path, index=False)
    scene = study.scene(key, ics=str(path), n=len(df), gamma=float(gamma))
    return study.run(key, scene, workers=workers, progress=progress)


def _map_states(study, E, extent, n):
    from hhscatter.ics import section_grid

    return section_grid(study.model, E, extent, (n, n))


def _uncertainty_states(study, E, i, eps, n=None, seed_offset=0):
    """Fresh reference ICs for ε index i (uniform on the allowed square) and their copies shifted by ε in x."""
    from hhscatter.ics import perturbed_on_section, region_ics

    n = int(study.param("n_uncertainty")) if n is None else int(n)
    seed = int(study.config["scene"]["seed"]) * 100 + seed_offset + i
    ref = region_ics(study.scene("unc", energy=E, region="square", n=n, seed=seed), 0, n)
    moved, ok = perturbed_on_section(study.model, ref, E, dx=float(eps))
    return np.concatenate([ref[ok], moved[ok]])


def zoom_centre(labels, extent, box=5, clearance=0):
    """zoom_centre(labels, extent, box=5, clearance=0) -> (x, y): centre of the most mixed box (highest Gibbs
    entropy; first in row-major order on ties), away from the map's edge and from forbidden cells.

    ``clearance`` (cells): only boxes whose centre lies at least this far (Euclidean, in cells) from every
    forbidden cell and from the map's edge are eligible, so that a zoom window of half-width ``clearance``
    cells around the centre is wholly allowed (issue 25: the unconstrained choice sat at the edge of the
    allowed region, where the zooms showed mostly forbidden cells).
    """
    from scipy import ndimage

    from hhscatter.analysis.basins import basin_entropy

    ent = basin_entropy(labels, box, outside=OUTSIDE)  # box_entropy: the wholly valid boxes, row-major
    nr, nc = labels.shape[0] // box, labels.shape[1] // box
    blocks = labels[:nr * box, :nc * box].reshape(nr, box, nc, box).transpose(0, 2, 1, 3).reshape(nr, nc, -1)
    valid = (blocks != OUTSIDE).all(axis=-1)
    grid = np.full((nr, nc), np.nan)
    grid[valid] = ent.box_entropy
    grid[[0, -1], :] = np.nan
    grid[:, [0, -1]] = np.nan
    if clearance > 0:
        # distance of every cell to the nearest forbidden cell or to the map's edge (padded as forbidden)
        dist = ndimage.distance_transform_edt(np.pad(labels != OUTSIDE, 1))[1:-1, 1:-1]
        centres = dist[box // 2::box, box // 2::box][:nr, :nc]
        grid[centres < clearance] = np.nan
        if np.all(np.isnan(grid)):
            raise ValueError(f"zoom_centre: no mixed box lies {clearance} cells inside the allowed region")
    i, j = np.unravel_index(np.nanargmax(grid), grid.shape)
    x0, x1, y0, y1 = extent
    return (x0 + (j + 0.5) * box * (x1 - x0) / labels.shape[1],
            y0 + (i + 0.5) * box * (y1 - y0) / labels.shape[0])


def _zoom_centre(study, extent, n):
    """The zooms' centre: the most mixed box of the γ = 0 map at zoom_energy whose widest zoom window (the
    smallest factor) lies wholly in the allowed region."""
    Ez = float(study.param("zoom_energy"))
    clearance = math.ceil(math.sqrt(2.0) * n / (2.0 * min(float(f) for f in study.param("zoom_factors"))))
    return zoom_centre(basin_image(study, map_key(Ez, 0.0), Ez, extent, n), extent, clearance=clearance)


def _zoom_extent(extent, centre, factor):
    x0, x1, y0, y1 = extent
    hx, hy = (x1 - x0) / (2 * factor), (y1 - y0) / (2 * factor)
    return (centre[0] - hx, centre[0] + hx, centre[1] - hy, centre[1] + hy)


def basin_image(study, key, E, extent, n):
    """basin_image(study, key, E, extent, n) -> (n, n) int8 outcome codes (−1 forbidden) of a map run."""
    from hhscatter.tables import read_lifetimes

    _, _, allowed, _, cell = _map_states(study, E, extent, n)
    lt = read_lifetimes(study.raw(key), columns=["traj_id", "outcome", "exit_channel"])
    img = np.full(allowed.size, OUTSIDE, dtype=np.int8)
    img[cell] = outcome_codes(lt)
    return img.reshape(allowed.shape)


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: basin maps, zooms and uncertainty runs, each through the runner."""
    extent = tuple(float(v) for v in study.param("extent"))
    n = int(study.param("grid"))
    eps = _eps(study)
    for E in study.param("energies"):
        for g in study.param("gammas"):
            _run_table(study, map_key(E, g), _map_states(study, E, extent, n)[3], g, workers, progress)
            for i, e in enumerate(eps):
                _run_table(study, unc_key(E, g, i), _uncertainty_states(study, E, i, e), g, workers, progress)
    Ez = float(study.param("zoom_energy"))
    centre = _zoom_centre(study, extent, n)
    for g in study.param("zoom_gammas"):
        for f in study.param("zoom_factors"):
            ext = _zoom_extent(extent, centre, f)
            _run_table(study, zoom_key(Ez, g, f), _map_states(study, Ez, ext, int(study.param("zoom_grid")))[3],
                       g, workers, progress)
    scan_E, scan_eps = _scan(study)
    ns = int(study.param("scan_grid"))
    for E in scan_E:
        _run_table(study, scan_map_key(E), _map_states(study, E, extent, ns)[3], 0.0, workers, progress)
        for i, e in enumerate(scan_eps):
            _run_table(study, scan_unc_key(E, i), _uncertainty_states(study, E, i, e, int(study.param(
                "scan_n_uncertainty")), seed_offset=50), 0.0, workers, progress)


# -- analyze ---------------------------------------------------------------------------
def _ve(v, e):
    return {"value": float(v), "err": float(e)}


def _uncertainty(study, E, g, eps):
    """f(ε) rows and the lifetimes of the pairs whose outcome changed, per ε."""
    from hhscatter.analysis.basins import uncertainty_fraction
    from hhscatter.tables import read_lifetimes

    rows = []
    for i, e in enumerate(eps):
        lt = read_lifetimes(study.raw(unc_key(E, g, i)), columns=["traj_id", "outcome", "exit_channel", "t_end"])
        code = outcome_codes(lt)
        m = len(code) // 2
        uf = uncertainty_fraction(code[:m], code[m:])
        t = lt.sort_values("traj_id")["t_end"].to_numpy()
        changed = code[:m] != code[m:]
        t_dec = np.minimum(t[:m], t[m:])[changed]  # until one of the pair leaves
        rows.append({"energy": E, "gamma": g, "eps": e, "f": uf.f, "f_lo": uf.lo, "f_hi": uf.hi, "k": uf.k,
                     "n": uf.n, "t_decide_median": float(np.median(t_dec)) if t_dec.size else math.nan})
    return pd.DataFrame(rows)


def analyze(study):
    """analyze(study) -> None: derived tables (maps, entropies, f(ε)) and basins.json."""
    from hhscatter.analysis.basins import (
        basin_entropy_table,
        basin_fractions,
        uncertainty_cutoff,
        uncertainty_exponent,
        wada_merging,
    )
    from hhscatter.analysis.escape_check import channel_fractions

    extent = tuple(float(v) for v in study.param("extent"))
    n = int(study.param("grid"))
    eps = _eps(study)
    ec = study.model.critical_energy
    boxes = [int(b) for b in study.param("boxes")]
    hb = int(study.param("box_headline"))
    maps, ent_rows, unc_tabs, per = [], [], [], []
    for E in study.param("energies"):
        for g in study.param("gammas"):
            img = basin_image(study, map_key(E, g), E, extent, n)
            maps.append(pd.DataFrame({"energy": E, "gamma": g, "label": img.ravel()}))
            fr = basin_fractions(img, basins=list(CODES), outside=OUTSIDE)
            ent = basin_entropy_table(img, boxes, outside=OUTSIDE).assign(energy=E, gamma=g)
            ent_rows.append(ent)
            present = [c for c, share in zip(CODES, fr.frac) if share >= float(study.param("wada_min_share"))]
            wada = wada_merging(img, basins=present, outside=OUTSIDE, r_wada=int(study.param("wada_r")))
            # the potential is three-fold symmetric, the square [−1, 1]² is not: test the exits' shares on
            # a rotation-invariant part of the map, the allowed cells with r < symmetry_radius
            gx, gy = _map_states(study, E, extent, n)[:2]
            r = np.hypot(*np.meshgrid(gx, gy))
            chans = channel_fractions(img[(img >= 0) & (img <= 2) & (r < float(study.param("symmetry_radius")))])
            unc = _uncertainty(study, E, g, eps)
            unc_tabs.append(unc)
            ok = unc["k"] >= int(study.param("fit_min_count"))
            fit = cut = None
            if ok.sum() >= 3:
                rng = (float(unc.loc[ok, "eps"].min()), float(unc.loc[ok, "eps"].max()))
                fit = uncertainty_exponent(unc["eps"], unc["f"], unc["n"], eps_range=rng)
                if ok.sum() >= 5:
                    cut = uncertainty_cutoff(unc["eps"], unc["f"], unc["n"], eps_range=rng)
            head = ent.set_index("box").loc[hb] if hb in set(ent["box"]) else None
            tau2 = math.log(E / ec) / g if g > 0 else math.inf
            smallest = unc.loc[ok].tail(1)
            per.append({
                "energy": E, "gamma": g,
                "fractions": {name: _ve(f, 0.5 * (hi - lo)) for name, f, lo, hi in
                              zip(CODE_NAMES, fr.frac, fr.lo, fr.hi)},
                "n_cells": int(fr.n),
                "channel_symmetry_p": float(chans.p_value),
                "channel_shares_r_sym": [float(v) for v in chans.frac],
                "S_b": _ve(head.S_b, head.S_b_err) if head is not None else None,
                "S_bb": _ve(head.S_bb, head.S_bb_err) if head is not None else None,
                "log2_fractal": bool(head.log2_fractal) if head is not None else None,
                "box_headline": hb,
                "wada": {"verdict": bool(wada.wada), "basins": [CODE_NAMES[c] for c in present],
                         "W_at_r": float(wada.wada_fraction[min(wada.r_wada, len(wada.wada_fraction) - 1)]),
                         "r": int(wada.r_wada), "hausdorff_slope": float(wada.hausdorff_slope)},
                "alpha": _ve(fit.alpha, fit.alpha_err) if fit else None,
                "d": _ve(fit.d, fit.d_err) if fit else None,
                "alpha_fit_range": list(fit.eps_range) if fit else None,
                "alpha_fit_p": float(fit.p_value) if fit else None,
                "cutoff": ({"detected": bool(cut.detected), "eps_c": float(cut.eps_c),
                            "eps_c_lo": float(cut.eps_c_lo), "eps_c_hi": float(cut.eps_c_hi),
                            "delta_aic": float(cut.delta_aic)} if cut else None),
                "tau2_mu1": tau2,
                "t_decide_median_smallest_eps": (float(smallest["t_decide_median"].iloc[0])
                                                 if len(smallest) else None),
                "smallest_resolved_eps": float(smallest["eps"].iloc[0]) if len(smallest) else None,
            })
    study.write_table(pd.concat(maps, ignore_index=True), "basins_maps.parquet", grid=n, extent=list(extent))
    study.write_table(pd.concat(ent_rows, ignore_index=True), "basins_entropy.parquet")
    study.write_table(pd.concat(unc_tabs, ignore_index=True), "basins_uncertainty.parquet")
    zooms = []
    Ez = float(study.param("zoom_energy"))
    centre = _zoom_centre(study, extent, n)
    for g in study.param("zoom_gammas"):
        for f in study.param("zoom_factors"):
            ext = _zoom_extent(extent, centre, f)
            img = basin_image(study, zoom_key(Ez, g, f), Ez, ext, int(study.param("zoom_grid")))
            zooms.append(pd.DataFrame({"gamma": g, "factor": f, "x0": ext[0], "x1": ext[1], "y0": ext[2],
                                       "y1": ext[3], "label": img.ravel()}))
    study.write_table(pd.concat(zooms, ignore_index=True), "basins_zooms.parquet", grid=int(study.param("zoom_grid")))
    for p in per:
        tag = f"E0={p['energy']:g}, γ={p['gamma']:g}"
        if p["alpha"]:
            study.compare(f"uncertainty exponent α ({tag})", p["alpha"]["value"], p["alpha"]["err"],
                          note=f"f(ε) ∝ ε^α on ε ∈ [{p['alpha_fit_range'][0]:.0e}, {p['alpha_fit_range'][1]:.0e}];"
                               f" d = 2 − α = {p['d']['value']:.3f}")
        if p["S_bb"]:
            study.compare(f"boundary basin entropy S_bb ({tag}, box {hb})", p["S_bb"]["value"], p["S_bb"]["err"],
                          note="S_bb > ln 2 is sufficient for a fractal boundary: "
                               + ("yes" if p["log2_fractal"] else "not shown"))
        if p["cutoff"] is not None and p["gamma"] > 0:
            c = p["cutoff"]
            study.compare(f"cut-off ε_c of the power law f(ε) ({tag})",
                          c["eps_c"] if c["detected"] else None, None,
                          note=(f"detected, 1σ [{c['eps_c_lo']:.2g}, {c['eps_c_hi']:.2g}]" if c["detected"] else
                                f"none seen: ε_c < {c['eps_c_hi']:.2g}") + " (paper: expected for γ > 0)")
    study.write_numbers({
        "codes": dict(zip(CODE_NAMES, CODES)),
        "grid": n, "extent": list(extent), "eps": [float(e) for e in eps],
        "zoom_centre": list(centre), "per_point": per,
        "convention": "square [−1, 1]² on the section ṙ = 0, φ̇ > 0 (forbidden cells blank); r_esc = 1.5",
    })


# -- plot -----------------------------------------------------------------------------------
def plot(study):
    """plot(study) -> None: basins.png from the derived tables."""
    from .figure import plot_basins

    plot_basins(pd.read_parquet(study.derived("basins_maps.parquet")),
                pd.read_parquet(study.derived("basins_zooms.parquet")),
                pd.read_parquet(study.derived("basins_entropy.parquet")),
                pd.read_parquet(study.derived("basins_uncertainty.parquet")),
                study.read_numbers(), study.figure_path, scale=study.scale)
