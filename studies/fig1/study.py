"""Study fig1 — paper Fig. 1: potential contours and the support of the c-measure.

Stages (``hhscatter study fig1 simulate|analyze|plot [--scale S]``):

``simulate(study, workers=None, progress=True)``
    For each energy E of ``[study].energies`` (0.35, 0.30): a pilot ensemble
    (raw key ``pilot_E0.35``) whose Kaplan–Meier P(t) gives κ and τ0
    (:func:`hhscatter.analysis.survival.escape_rate.escape_rate`, the 4-window rule of
    Fig. 2b), the recording time

        t_rec = ceil(τ0 + rec_efolds/κ)        (sprinkler rule, t_rec ≫ 1/κ),

    and the main ensemble (raw key ``E0.35`` / ``E0.30``): ``n`` orbits uniform
    in the disk r < radius with the section velocities of the initial
    conditions (paper, App. "Initial Conditions"), recording the first crossing
    of the section ṙ = 0, φ̇ > 0 at t ≥ t_rec of every orbit still inside
    (``SectionWindow(t_from=t_rec, first_only=True)``), t_max = t_rec + t_after.

``analyze(study)``
    Derived tables ``cmeasure_points.parquet`` (energy, traj_id, t, x, y, px,
    py, e_cross: the c-measure sample, published for other studies) and ``potential_grid.parquet`` (x, y, V on a
    square grid for Fig. 1a); numbers ``fig1.json`` with, per energy, t_rec,
    the κ and τ0 used, survivors at t_rec and the number of points.

``plot(study)``
    ``fig1.png`` via ``plot_fig1`` of the folder's ``figure.py``.

c-measure sample for other studies (fig5): the conservative c-measure at
E = 0.30 and 0.35 is published as the derived table ``cmeasure_points.parquet``
(columns energy = the run's E, traj_id, t, x, y, px, py and e_cross, the
orbit's energy at the crossing): every row of the ``sections`` table of the
raw runs ``raw/E0.30`` and ``raw/E0.35``; all rows have t ≥ t_rec by
construction (first_only). ``fig1.json`` names the table (``tables``) and
gives t_rec per energy (``cmeasure_sample``).
"""

from __future__ import annotations

import json

import numpy as np

from hhscatter.analysis.stats.verdicts import half_unit
from hhscatter.reproduction.escape_summaries import recording_time
from hhscatter.reproduction.fig1 import energy_record
from hhscatter.run.plan import SCENE_FILE
from hhscatter.scene.schema import Integer, Number, Numbers
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/fig1/study.toml."""

    energies: Numbers  # E of the main runs (c-measure samples)
    pilot_n: Integer  # orbits of the pilot runs (κ, τ0 → t_rec)
    pilot_seed: Integer
    pilot_t_max: Number
    rec_efolds: Number  # t_rec = ceil(τ0 + rec_efolds/κ)
    t_after: Number  # main runs: t_max = t_rec + t_after
    n_contours: Integer  # Fig. 1a contour levels k/(n+1)·0.5
    grid_half_width: Number  # potential grid [-h, h]²
    grid_points: Integer


CMEASURE_TABLE = "cmeasure_points.parquet"  # published: other studies read it (derived/), never the raw runs


def energy_key(energy: float) -> str:
    """energy_key(E) -> raw-run key 'E0.30' of the main run at energy E (two decimals)."""
    return f"E{energy:.2f}"


def _pilot_scene(study, energy):
    return study.scene(
        f"pilot_{energy_key(energy)}",
        energy=float(energy),
        n=study.params.pilot_n,
        seed=study.params.pilot_seed,
        t_max=study.params.pilot_t_max,
        sections=None,
        snapshots=None,
    )


def _pilot_rate(pilot_dir):
    """κ, τ0 (and the full EscapeRateResult) of a pilot run."""
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes
    from hhscatter.data.read import read_lifetimes

    lt = read_lifetimes(pilot_dir, columns=["traj_id", "e0", "gamma", "outcome", "t_end"])
    return escape_rate_from_lifetimes(lt, detect_tail=False)


def _main_scene(study, energy, t_rec):
    return study.scene(
        energy_key(energy),
        energy=float(energy),
        t_max=float(t_rec + study.params.t_after),
        # the first crossing after t_rec is all this run needs: the orbit stops there
        sections={"t_from": float(t_rec), "first_only": True, "stop": True},
        snapshots=None,
    )


def _choices_path(study):
    return study.out / "raw" / "fig1_choices.json"


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None, progress=True) -> None; pilot and main runs per energy.

    The κ, τ0 and t_rec actually used are written to ``raw/fig1_choices.json``.
    """
    from hhscatter.studies import write_json_atomic

    choices = {}
    for energy in study.params.energies:
        pdir = study.run(f"pilot_{energy_key(energy)}", _pilot_scene(study, energy), workers=workers, progress=progress)
        r = _pilot_rate(pdir)
        t_rec = recording_time(r.kappa, r.tau0, study.params.rec_efolds)
        print(
            f"  fig1 E={energy}: pilot κ = {r.kappa:.4f} ± {r.kappa_err:.4f}, τ0 = {r.tau0:.2f} → t_rec = {t_rec:g}",
            flush=True,
        )
        study.run(energy_key(energy), _main_scene(study, energy, t_rec), workers=workers, progress=progress)
        choices[energy_key(energy)] = {
            "energy": float(energy),
            "t_rec": t_rec,
            "kappa": r.kappa,
            "kappa_err": r.kappa_err,
            "tau0": r.tau0,
            "t_stop": r.t_stop,
            "n_pilot": int(r.n_total),
        }
    write_json_atomic(_choices_path(study), choices)


def contour_levels(n: int, e_max: float = 0.5) -> np.ndarray:
    """contour_levels(n) -> n energies k·e_max/(n+1), k = 1..n, in (0, e_max); n = 20 contains E_c = 1/6 (k = 7)."""
    return e_max * np.arange(1, n + 1) / (n + 1)


def analyze(study):
    """analyze(study) -> None; writes cmeasure_points.parquet, potential_grid.parquet and fig1.json."""
    import pandas as pd

    choices = json.loads(_choices_path(study).read_text())
    per_energy, points = {}, []
    for energy in study.params.energies:
        key = energy_key(energy)
        per_energy[key], pts = _energy_run(study, energy, key, choices[key])
        points.append(pts)
    study.write_table(
        pd.concat(points, ignore_index=True),
        CMEASURE_TABLE,
        description="sprinkler c-measure sample: first section crossing (ṙ=0, φ̇>0) at t ≥ t_rec; "
        "energy = the run's E, e_cross = the orbit's energy at the crossing",
    )
    _write_potential_grid(study)
    study.write_numbers(_numbers(study, per_energy))


def _energy_run(study, energy: float, key: str, ch: dict):
    """One energy's main run: checked against the recorded choice, its numbers and c-measure points; κ compared."""
    from hhscatter.data.read import read_lifetimes, read_sections

    t_rec = float(ch["t_rec"])
    scene = json.loads((study.raw(key) / SCENE_FILE).read_text())["scene"]
    if abs(float(scene["sections"]["t_from"]) - t_rec) > 1e-9:
        raise RuntimeError(
            f"{key}: raw run's t_rec = {scene['sections']['t_from']} is not the recorded "
            f"choice {t_rec}; re-run the simulate stage"
        )
    # the rule with the current analysis code (differs only if escape_rate changed since simulate)
    r = _pilot_rate(study.raw(f"pilot_{key}"))
    t_rec_now = recording_time(r.kappa, r.tau0, study.params.rec_efolds)
    lt = read_lifetimes(study.raw(key), columns=["traj_id", "e0", "gamma", "outcome", "t_end"], categorical=True)
    sec = read_sections(study.raw(key))
    if (sec["t"] < t_rec).any() or sec["traj_id"].duplicated().any():
        raise RuntimeError(f"{key}: sections must hold one crossing per orbit at t ≥ t_rec")
    entry, pts = energy_record(energy, ch, scene["t_max"], lt, sec, t_rec_now, f"raw/{key}")
    # paper Fig. 2b linear law κ = 1.41 (E − E_c), for orientation only
    study.compare(
        f"kappa(E={energy:.2f}) used for t_rec",
        ch["kappa"],
        ch["kappa_err"],
        1.41 * (energy - study.model.critical_energy),
        unit="1/time",
        note="pilot fit vs the paper's linear law κ = 1.41 (E − E_c) of Fig. 2b; its 1σ propagated from the "
        "printed 1.41",
        reference="propagated",
        paper_err=half_unit(1.41) * (energy - study.model.critical_energy),
    )
    return entry, pts


def _write_potential_grid(study) -> None:
    """Fig. 1a's potential V(x, y) on a square grid (derived table potential_grid.parquet)."""
    import pandas as pd

    h = study.params.grid_half_width
    m = study.params.grid_points
    g = np.linspace(-h, h, m)
    X, Y = np.meshgrid(g, g)
    study.write_table(
        pd.DataFrame({"x": X.ravel(), "y": Y.ravel(), "V": study.model.potential(X, Y).ravel()}),
        "potential_grid.parquet",
        description=f"V(x, y) on a {m}×{m} grid, Eq. (eqn:hh_potential)",
    )


def _numbers(study, per_energy: dict) -> dict:
    """fig1.json: the sprinkler rule, per energy its run's numbers, the published tables, contours, E_c, saddles."""
    model = study.model  # E_c and the saddles of the scene's potential (ω, λ)
    return {
        "sprinkler_rule": "t_rec = ceil(tau0 + rec_efolds/kappa), kappa and tau0 from the pilot run's Kaplan-Meier "
        "P(t) (escape_rate: mean of 4 window fits); main run records the first section crossing "
        "at t >= t_rec (SectionWindow first_only=True), t_max = t_rec + t_after",
        "rec_efolds": study.params.rec_efolds,
        "energies": per_energy,
        "tables": {"cmeasure_points": CMEASURE_TABLE, "potential_grid": "potential_grid.parquet"},
        "cmeasure_sample": {
            "how": f"the rows of derived/{CMEASURE_TABLE} with energy = E (published for other studies), i.e. every "
            "row of the 'sections' table of raw run raw/E0.30 (raw/E0.35); all rows have t >= t_rec",
            "raw_keys": {k: v["raw_run"] for k, v in per_energy.items()},
            "t_rec": {k: v["t_rec"] for k, v in per_energy.items()},
            "n_points": {k: v["n_points"] for k, v in per_energy.items()},
        },
        "contour_levels": contour_levels(study.params.n_contours),
        "E_c": model.critical_energy,
        "saddles": model.saddles,
    }


plot = figure_stage("plot_fig1", "potential_grid", CMEASURE_TABLE, NUMBERS, PATH)
