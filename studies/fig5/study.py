"""Study fig5: the dissipative ensemble at t* against the conservative c-measure (paper Fig. 5, fig:um_comparison).

Paper (Sec. III.B.2): orbits start at E2 = 0.35 with drag γ = 0.01; at the time
t* at which Eq. (eqn:energy_exp_decay) predicts E(t*) = E0 e^{−μγt*} = E1 = 0.30
(t* ≈ 17) the position (x, y) of each surviving orbit's next crossing of the
section ṙ = 0, φ̇ > 0 is plotted over the conservative c-measure μ_c^{0.30}
(Fig. 1b): (a) all such crossings, (b) only those with energy in
[0.295, 0.305].  Claims: the points "mostly coincide" with μ_c^{E1}, better than
with μ_c^{E2}; restricting the energy (b) removes most of the dispersion;
agreement holds "up to a finite spatial scale, which becomes increasingly small
as the time for the distributions to relax increases".

Stages
------
simulate   one dissipative run per γ in ``gammas`` (raw key ``gamma<γ>``), all
           section crossings in [t*(μ_max), t*(μ_min) + pad] recorded, so that
           t* is fixed at analysis time from fig3's μ; the authors' two runs
           (square ICs, their windows: ``5a_authors``, ``5b_authors``) and the
           same two with momenta in random directions (``*_random``).
analyze    t* from μ (fig3.json); the Fig. 5a/b point sets; the c-measure
           samples at E1 and E2 from study fig1's published points
           (derived/cmeasure_points.parquet: first crossing after fig1's
           recording time t_rec); distances (see
           :mod:`hhscatter.analysis.geometry.distance`): Hellinger and TV on box
           histograms vs box side ε (full samples with bootstrap errors, and
           split-half comparisons at one common sample size m with their
           noise floor, giving the agreement scale ε*), sliced Wasserstein with
           bootstrap errors; every verdict that rests on a distance with a
           paired interval over half-samples of the orbits of every set, the
           references included: 5b − 5a (``verdict_5b``), μ_c^{E1}
           vs μ_c^{E2} (``refs_paired``), panel (d) (``panel_d``).  Writes
           derived tables and fig5.json.
plot       Fig. 5 (a), (b) and the distance panels from the derived tables.

Why Hellinger vs ε is the headline distance: the paper's claim is
scale-resolved; H(ε) against its own split-half noise floor gives the scale
down to which two samples are indistinguishable, and H weighs the thin
low-mass filaments where a fractal c-measure and a blurred one differ
(module docstring of :mod:`hhscatter.analysis.geometry.distance`).  The sliced
Wasserstein distance (units of length) is the scale-free global check that
μ_c^{E1} is closer than μ_c^{E2}.

Two agreement scales are reported for each comparison, both at one common
split-half sample size m (the c-measure sample of fig1 limits m):

* ε*_2σ (:func:`~hhscatter.analysis.geometry.distance.agreement_scale`): the smallest
  box side down to which H_pq is within 2σ of the noise floor — a
  significance statement, which moves to coarser scales as samples grow;
* ε*_δ (:func:`~hhscatter.analysis.geometry.distance.agreement_scale_debiased`): the
  smallest box side down to which the noise-corrected distance
  √(H_pq² − H_noise²) stays ≤ δ (default 0.1) — an estimate of a property of
  the two distributions, comparable across γ and sample sizes.  Panel (d)
  shows this corrected distance vs ε for every γ: the paper's "agreement up to
  a finite spatial scale, which becomes increasingly small as the time for
  the distributions to relax increases" is the downward shift of these curves
  with t*.

Why not the paper's γ = 0.003 (or smaller): with E2 and E1 fixed, t* ∝ 1/γ and
the survivors decay as ≈ e^{−κ t*} with κ ≈ 0.2–0.25 at E ∈ [0.30, 0.35]: at
γ = 0.005 (t* ≈ 33) about 6e-4 of the orbits cross the section after t*
(6e3 of N = 1e7, paper scale only), at γ = 0.003 (t* ≈ 55) about 1e-5.
Relaxation time is therefore varied through γ ∈ {0.03, 0.02, 0.01} (quick)
and {…, 0.005} (paper).
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from hhscatter.analysis.dissipative.decay import time_to_energy
from hhscatter.analysis.geometry import distance as dist
from hhscatter.analysis.stats.measured import Measured
from hhscatter.reproduction import cmeasure_comparison as cc
from hhscatter.reproduction import cmeasure_verdicts as cv
from hhscatter.scene.scene import MOMENTA
from hhscatter.scene.schema import Integer, Number, Numbers, OneOf, Text
from hhscatter.studies import _upstream as up
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/fig5/study.toml."""

    E1: Number
    gammas: Numbers
    gamma_main: Number
    band: Numbers
    mu_min: Number
    mu_max: Number
    section_pad: Number
    mu_key: Text
    t_rec_E1_key: Text
    t_rec_E2_key: Text
    extent: Numbers
    boxes: Numbers
    box_headline: Number
    n_splits: Integer
    n_boot: Integer
    n_proj: Integer
    z: Number
    delta: Number
    noise_max: Number
    n_cap: Integer
    m_min: Integer
    authors_window: Numbers = [17.0, 30.0]  # the authors' Fig 5a: first crossing with 17 < t < 30
    seed: Integer
    verdict_offsets: Integer = 4
    verdict_boot: Integer = 100
    verdict_level: Number = 0.95
    r_cut: Number = 1.0
    # the authors' two runs again with this momentum convention (Scene.momentum): the verdict's sensitivity row
    sensitivity_momentum: OneOf(*MOMENTA[1:])


PAPER_T_STAR = 17.0
PAPER_MU = 0.91
PAPER_N_PLOTTED = 3e4  # "approximately 3·10^4 are plotted in each case" of N = 1e7
PAPER_N = 1e7


def gamma_key(g: float) -> str:
    """gamma_key(γ) -> raw run key, e.g. 'gamma0.01'."""
    return f"gamma{g:g}"


def _scene_for(study, g):
    E2 = float(study.config["scene"]["energy"])
    E1 = study.params.E1
    t_lo = time_to_energy(E2, E1, study.params.mu_max, g)
    t_hi = time_to_energy(E2, E1, study.params.mu_min, g) + study.params.section_pad
    # nothing is needed from an orbit after the window: it stops there (outcome 'stopped')
    return study.scene(
        gamma_key(g), gamma=float(g), sections={"t_from": float(t_lo), "t_to": float(t_hi), "stop": True}
    )


AUTHORS = {"5a_authors": "Fig. 5a, the authors' convention", "5b_authors": "Fig. 5b, the authors' convention"}
AUTHORS_CONVENTION = (
    "region 'square' (goodICs), γ = gamma_main, r < 1; 5a: first crossing with {w[0]:g} < t < {w[1]:g}; "
    "5b: first crossing with E in {band} at any time"
)


#: the sensitivity runs of the verdict: the authors' runs again, momenta as ``sensitivity_momentum``
SENSITIVITY = {"5a_authors_random": "5a_authors", "5b_authors_random": "5b_authors"}
SENSITIVITY_CONVENTION = (
    AUTHORS_CONVENTION + "; momenta in random directions (momentum = '{m}'), not goodICs' tangential ones"
)


def _conventions(study) -> dict:
    """{construction: its convention string} of the verdict rows (None: ours)."""
    p = study.params
    authors = AUTHORS_CONVENTION.format(w=p.authors_window, band=list(p.band))
    return {
        "old": authors,
        "cut": authors,
        "cut_offsets": authors,
        "ours": None,
        "cut_offsets_random": SENSITIVITY_CONVENTION.format(
            w=p.authors_window, band=list(p.band), m=p.sensitivity_momentum
        ),
    }


def _authors_scene(study, key):
    """The authors' Fig. 5 runs (their code: goodICs, i.e. region 'square', at E2, γ = gamma_main): 5a is the
    first crossing with t in ``authors_window``; 5b the first crossing whose energy is in ``band``, at any
    time. The r < 1 cut is applied in the analysis. Each orbit stops once it has its crossing. A key of
    :data:`SENSITIVITY` is the same run with momenta as ``sensitivity_momentum`` (the same positions)."""
    g = study.params.gamma_main
    if key in SENSITIVITY:
        return _authors_scene(study, SENSITIVITY[key]).replace(
            momentum=study.params.sensitivity_momentum, name=f"{study.name}/{key}"
        )
    if key == "5a_authors":
        t0, t1 = study.params.authors_window
        sec = {"t_from": t0, "t_to": t1, "first_only": True, "stop": True}
    else:
        lo, hi = study.params.band
        sec = {"e_min": lo, "e_max": hi, "first_only": True, "stop": True}
    return study.scene(key, gamma=g, region="square", sections=sec)


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None; one raw run per γ (sections in the t* window), the two runs
    of the authors' Fig. 5 convention (square ICs, their windows), and the same two with the other momentum
    convention (:data:`SENSITIVITY`)."""
    for g in study.params.gammas:
        study.run(gamma_key(g), _scene_for(study, g), workers=workers, progress=progress)
    for key in (*AUTHORS, *SENSITIVITY):
        study.run(key, _authors_scene(study, key), workers=workers, progress=progress)


def _authors_sets(study, keys):
    """{('authors', key): points}: the first crossing of each orbit of the authors' runs ``keys``, kept where
    r < r_cut (their plots), capped at n_cap points."""
    from hhscatter.data.read import read_sections

    n_cap, seed = study.params.n_cap, study.params.seed
    out = {}
    for key in keys:
        sec = read_sections(study.raw(key), columns=["traj_id", "t", "x", "y", "energy"])
        out[("authors", key)] = cc.cap_rows(cc.within_radius(sec, study.params.r_cut), n_cap, seed)
    return out


# ---------------------------------------------------------------------------
# analysis
# ---------------------------------------------------------------------------
def _cmeasure_points(study, inputs, E1, E2):
    """Conservative c-measure samples at E1 and E2 (first crossing after t_rec), from the study [needs].cmeasure:
    its published table of points (fig1: derived/cmeasure_points.parquet) and its t_rec (numbers JSON)."""
    other = study.upstream("cmeasure")
    doc = up.numbers(study, other)
    cm, name = up.published_table(study, other, "cmeasure_points", doc)
    out, t_rec = {}, {}
    for label, E in (("E1", E1), ("E2", E2)):
        tpath = getattr(study.params, f"t_rec_{label}_key")
        t_rec[label] = float(up.lookup(doc, tpath, what=f"{other}.json")[0])
        sec = cm[np.isclose(cm["energy"], E, rtol=0.0, atol=1e-12)]
        sec = sec[["traj_id", "t", "x", "y", "e_cross"]].rename(columns={"e_cross": "energy"})
        # the table holds the first crossing at t ≥ t_rec of each orbit; selecting it again is a no-op then
        pts = dist.first_crossings(sec, t_rec[label])
        if len(pts) < 2:
            raise up.UpstreamError(
                f"{other}'s {name}: only {len(pts)} points at E = {E:g} after t_rec = {t_rec[label]}"
            )
        out[label] = pts
        inputs[f"cmeasure_{label}"] = {
            "source": f"{other}: derived/{name} (energy = {E:g}), t_rec from {other}.json:{tpath}",
            "t_rec": t_rec[label],
            "n_points": len(pts),
            "mean_energy": float(pts["energy"].mean()),
        }
    return out, t_rec


def analyze(study):
    """analyze(study) -> None; writes derived tables (points, distances) and fig5.json.

    Steps: μ from the study [needs].mu (:func:`_mu`), the c-measure samples (:func:`_cmeasure_points`), the
    Fig. 5a/b point sets per γ (:func:`_point_sets`), the distances at one common split-half sample size
    (:mod:`hhscatter.reproduction.cmeasure_comparison`), the paired verdicts and the paper comparison
    (:mod:`hhscatter.reproduction.cmeasure_verdicts`).
    """
    inputs = {}
    E2 = float(study.config["scene"]["energy"])
    E1 = study.params.E1
    gammas = list(study.params.gammas)
    g_main = study.params.gamma_main
    if g_main not in gammas:
        raise ValueError(f"[study] gamma_main = {g_main} must be one of gammas = {gammas}")
    mu, mu_err = _mu(study, inputs)
    cm, t_rec = _cmeasure_points(study, inputs, E1, E2)
    settings = cc.ComparisonSettings.from_params(study.params)
    extent = settings.extent
    cm_full = cm
    cm = {k: cc.cap_rows(v, settings.n_cap, settings.seed) for k, v in cm.items()}
    refs = {"E1": dist.points(cm["E1"]), "E2": dist.points(cm["E2"])}
    sets, pg, point_tables = _point_sets(study, gammas, E1, E2, mu, mu_err)
    usable, m_common = cc.common_sample_size(sets, refs["E1"], settings.m_min)
    dtab, stab = cc.distance_tables(sets, refs, usable, m_common, settings)

    study.write_table(pd.concat(point_tables, ignore_index=True), "points.parquet")
    cm_tab = pd.concat([cm["E1"].assign(E=E1), cm["E2"].assign(E=E2)], ignore_index=True)
    study.write_table(
        cm_tab[["E", "traj_id", "t", "x", "y", "energy"]],
        "cmeasure_points.parquet",
        t_rec_E1=t_rec["E1"],
        t_rec_E2=t_rec["E2"],
    )
    study.write_table(dtab, "distance_vs_scale.parquet", extent=list(extent), m_common=m_common)
    study.write_table(stab, "distance_summary.parquet")
    study.write_table(pg, "per_gamma.parquet")

    delta = study.params.delta
    paper = {"t_star": PAPER_T_STAR, "fraction": PAPER_N_PLOTTED / PAPER_N}
    mu_kw = {"mu": mu, "mu_err": mu_err, "mu_source": inputs["mu"]["source"]}
    rows, verdicts = cv.closer_comparisons(pg, stab, g_main, **mu_kw, E1=E1, paper=paper)
    # the authors' runs, cut at r < r_cut like their plots (the sensitivity runs too)
    auth = _authors_sets(study, (*AUTHORS, *SENSITIVITY))
    # their own Fig. 5 convention (square ICs; 5a: first crossing with 17 < t < 30; 5b: first crossing in the
    # energy band at any time; r < 1): its summary rows are None when the sets are too small (tiny scale)
    authors = cc.authors_record(
        {("authors", k): auth[("authors", k)] for k in AUTHORS},
        refs,
        AUTHORS_CONVENTION.format(w=study.params.authors_window, band=list(study.params.band)),
        settings,
    )
    main_sets = (sets[(g_main, "a")], sets[(g_main, "b")])
    auth_runs = (auth[("authors", "5a_authors")], auth[("authors", "5b_authors")])
    auth_random = (auth[("authors", "5a_authors_random")], auth[("authors", "5b_authors_random")])
    verdict = cc.difference_record(
        cm_full["E1"], main_sets, auth_runs, auth_random, settings, E1=E1, momentum=study.params.sensitivity_momentum
    )
    rows += cv.difference_comparisons(verdict, _conventions(study))
    refs_paired = cc.reference_record(cm_full, main_sets, auth_runs, settings, E1=E1, E2=E2)
    rows += cv.reference_comparisons(refs_paired, _conventions(study)["cut"])
    t_star = pg.set_index("gamma")["t_star"]
    panel_d = cc.paired_scale_curves({g: sets[(g, "a")] for g in pg["gamma"]}, t_star, dtab, cm["E1"], settings)
    rows += cv.scale_comparisons(panel_d)
    for row in rows:
        study.compare(**row)
    cv.qualify_our_5b(study.comparisons, dict((k, lab) for k, lab, _ in cc.DIFFERENCE_CONSTRUCTIONS)["cut_offsets"])
    study.write_numbers(
        {
            "inputs": inputs,
            "dev_fallback": up.any_fallback(inputs),
            "mu": Measured(mu, mu_err).to_dict(),
            "E1": E1,
            "E2": E2,
            "band": list(study.params.band),
            "gamma_main": g_main,
            "t_star": {gamma_key(r.gamma): Measured(r.t_star, r.t_star_err).to_dict() for r in pg.itertuples()},
            "per_gamma": pg.to_dict(orient="records"),
            "m_common": m_common,
            "delta": delta,
            "distances": stab.to_dict(orient="records"),
            "closer_to_E1": verdicts,
            "authors_convention": authors,
            "verdict_5b": verdict,
            "refs_paired": refs_paired,
            "panel_d": panel_d,
        }
    )


def _mu(study, inputs):
    """(μ, σ_μ) of Eq. (eqn:energy_exp_decay) from the study [needs].mu; it must lie in the window of μ the
    section recording was made for."""
    mu, mu_err = up.value_or_fallback(study, study.upstream("mu"), study.params.mu_key, PAPER_MU, inputs, "mu")
    mu = float(mu)
    mu_err = float(mu_err) if mu_err is not None else math.nan
    if not study.params.mu_min <= mu <= study.params.mu_max:
        raise ValueError(
            f"μ = {mu} lies outside the recorded window [mu_min, mu_max] = "
            f"[{study.params.mu_min}, {study.params.mu_max}]: widen it in study.toml and re-simulate"
        )
    return mu, mu_err


def _point_sets(study, gammas, E1, E2, mu, mu_err):
    """({(γ, 'a'|'b'): points}, per-γ DataFrame, point tables): the first crossing after t* of each surviving
    orbit (Fig. 5a) and those in the energy band (Fig. 5b), capped at n_cap points
    (:func:`~hhscatter.reproduction.cmeasure_comparison.crossing_sets`)."""
    import pyarrow.dataset as pads

    from hhscatter.data.read import read_lifetimes, read_sections

    band = tuple(study.params.band)
    n_cap, seed = study.params.n_cap, study.params.seed
    sets, per_gamma, point_tables = {}, [], []
    for g in gammas:
        raw = study.raw(gamma_key(g))
        t_star = time_to_energy(E2, E1, mu, g)
        t_star_err = t_star * mu_err / mu if math.isfinite(mu_err) else math.nan
        lt = read_lifetimes(raw, columns=["traj_id", "t_end"])
        # only crossings at or after t* can be a first crossing after t* (pushed down to the reader: at N = 1e7
        # the whole recorded window [t*(μ_max), t*(μ_min) + pad] is ~1e7 rows)
        sec = read_sections(raw, columns=["traj_id", "t", "x", "y", "energy"], filters=pads.field("t") >= t_star)
        win = _scene_for(study, g).sections
        if not win.t_from <= t_star <= win.t_to:
            raise ValueError(f"t* = {t_star:.3f} outside the recorded section window [{win.t_from}, {win.t_to}]")
        a, b, counts = cc.crossing_sets(sec, lt["t_end"].to_numpy(), t_star, band, n_cap, seed)
        sets[(g, "a")], sets[(g, "b")] = a, b
        per_gamma.append({"gamma": g, "t_star": t_star, "t_star_err": t_star_err, **counts})
        for sel, df in (("a", a), ("b", b)):
            point_tables.append(df.assign(gamma=g, set=sel)[["gamma", "set", "traj_id", "t", "x", "y", "energy"]])
    pg = pd.DataFrame(per_gamma)

    return sets, pg, point_tables


# ---------------------------------------------------------------------------
# plot
# ---------------------------------------------------------------------------
plot = figure_stage("plot_fig5", "points", "cmeasure_points", "distance_vs_scale", "distance_summary", NUMBERS, PATH)
