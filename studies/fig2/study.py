"""Study fig2 — paper Fig. 2: P(t), κ0(E) with its piecewise law, and κ from the c-measure.

``simulate``: per grid energy a pilot fixes t_max (:func:`~hhscatter.analysis.survival.escape_rate.choose_t_max`),
then the κ(E) run (``grid_E…``; the authors' square ICs too at ``square_energies``, ``sq_grid_E…``); the Fig. 2a
runs (``pt_E…``, t_max = ``pt_t_max`` so that the sticky tail shows); the c-measure runs (``cm_E…``): every section
crossing in the window :func:`~hhscatter.reproduction.escape_summaries.cmeasure_windows` makes of the grid run's κ
and τ0, orbits run to ``cm_t_max`` so that censored ones are recognised. The choices go to
``raw/fig2_choices.json``.

``analyze``: κ(E) and its law (``kappa_energy``, ``kappa_fit_curve``), κ(E) under four conventions
(``kappa_conventions``), Fig. 2a (``survival_curves``, ``pt_fit_lines``), κ from the c-measure
(``kappa_cmeasure``, Eq. (eqn:kappa_cmeasure_truetime)); numbers in ``fig2.json`` with the paper comparison.
``plot``: ``fig2.png`` (``figure.py``). Parameters: ``study.toml``.
"""

from __future__ import annotations

import json
import math
import warnings
from types import SimpleNamespace

import numpy as np

from hhscatter.analysis.survival.kappa_energy import kappa_law_summary
from hhscatter.reproduction.escape_summaries import (
    cmeasure_windows,
    kappa_cmeasure_z,
    kappa_law_curves,
    rate_row,
    rate_summary,
    sticky_tail_summary,
    survival_tables,
)
from hhscatter.reproduction.fig2 import (
    FIG2_RULES,
    PAPER_FIG2,
    cmeasure_comparisons,
    cmeasure_run_rows,
    convention_analysis,
    law_comparisons,
    pt_comparisons,
)
from hhscatter.run.plan import SCENE_FILE
from hhscatter.scene.schema import Integer, Integers, Number, Numbers
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import NUMBERS, PATH, Table, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/fig2/study.toml (rules in its header comment)."""

    grid_energies: Numbers
    grid_n: Integer
    pilot_n: Integer
    pilot_seed: Integer
    pilot_t_max: Number
    min_survivors: Number
    margin_efolds: Number
    t_max_min: Number
    t_max_cap: Number
    pt_energies: Numbers
    pt_n: Integers
    pt_seed: Integer
    pt_t_max: Number
    tail_min_survivors: Number
    cm_energies: Numbers
    cm_n: Integer
    cm_seed: Integer
    cm_t_max: Number
    cm_rec_efolds: Number
    cm_sample_efolds: Number
    cm_margin: Number
    cm_start_shifts: Numbers = [0.0]
    n_boot: Integer
    fit_seed: Integer
    # -- κ(E) near E_c under several conventions (the authors' square ICs, windows fixed by P levels) --
    grid_n_by_energy: Integers = None  # orbits per grid energy (same order as grid_energies); None: grid_n for all
    square_energies: Numbers = []  # grid energies also run with the authors' square ICs (raw sq_grid_E…)
    p_levels: Numbers = [0.5, 0.01]  # [p_hi, p_lo] of the P-level windows
    max_plateau_bias: Number = 0.1  # κ ill-defined when the censored fraction is > this share of P at the window end
    stable_rel_tol: Number = 0.1  # κ(E) stable: (max − min)/mean over the defined conventions ≤ this


LIFETIME_COLUMNS = ["traj_id", "e0", "gamma", "outcome", "t_end"]


def grid_key(energy: float) -> str:
    """The raw key of the κ(E) run at E, e.g. 'grid_E0.175'."""
    return f"grid_E{energy:.3f}"


def pt_key(energy: float) -> str:
    """The raw key of the Fig. 2a run at E, e.g. 'pt_E0.23'."""
    return f"pt_E{energy:.2f}"


def sq_key(energy: float) -> str:
    """The raw key of the square-IC κ(E) run at E, e.g. 'sq_grid_E0.175'."""
    return f"sq_{grid_key(energy)}"


def grid_n(study, energy: float) -> int:
    """The orbits of the κ(E) run at E: [study].grid_n_by_energy if given, else grid_n."""
    per = study.params.grid_n_by_energy
    if per is None:
        return study.params.grid_n
    grid = list(study.params.grid_energies)
    if len(per) != len(grid):
        raise ValueError(f"[study].grid_n_by_energy has {len(per)} entries, grid_energies {len(grid)}")
    return int(per[int(np.argmin(np.abs(np.asarray(grid) - energy)))])


def cm_key(energy: float) -> str:
    """The raw key of the c-measure section run at E, e.g. 'cm_E0.30'."""
    return f"cm_E{energy:.2f}"


def _lifetimes(path):
    from hhscatter.data.read import read_lifetimes

    return read_lifetimes(path, columns=LIFETIME_COLUMNS, categorical=True)  # 1e7 orbits: no str per orbit


def _t_max_choice(study, pilot_dir, n):
    from hhscatter.analysis.survival.escape_rate import choose_t_max
    from hhscatter.analysis.survival.fits import lifetimes_to_arrays

    t_end, obs = lifetimes_to_arrays(_lifetimes(pilot_dir))
    p = study.params
    return choose_t_max(
        t_end,
        obs,
        n,
        min_survivors=p.min_survivors,
        margin_efolds=p.margin_efolds,
        t_min=p.t_max_min,
        t_cap=p.t_max_cap,
    )


def _grid_rate(study, energy, lifetimes=None):
    """EscapeRateResult of the κ(E) run at E (its lifetimes read here unless given)."""
    from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes

    lt = _lifetimes(study.raw(grid_key(energy))) if lifetimes is None else lifetimes
    return escape_rate_from_lifetimes(lt, detect_tail=False, min_survivors=study.params.min_survivors)


def _cm_windows(study, energy):
    """κ of the grid run at E and the c-measure window it gives (t_rec, t_sample_end, t_record_end)."""
    r, p = _grid_rate(study, energy), study.params
    return r, cmeasure_windows(
        r.kappa, r.tau0, p.cm_rec_efolds, p.cm_sample_efolds, p.cm_margin, max(p.cm_start_shifts)
    )


def _choices_path(study):
    return study.out / "raw" / "fig2_choices.json"


def simulate(study, workers=None, progress=True):
    """Run the pilots, the κ(E) grid, Fig. 2a and the c-measure runs; the t_max and windows chosen go to
    ``raw/fig2_choices.json``."""
    from dataclasses import asdict

    from hhscatter.studies import write_json_atomic

    choices = {"t_max": {}, "cmeasure": {}}
    grid = list(study.params.grid_energies)
    off = [e for e in study.params.square_energies if not np.isclose(grid, e).any()]
    if off:
        raise ValueError(f"[study].square_energies must be among grid_energies; {off} are not")
    missing = [e for e in study.params.cm_energies if not np.isclose(grid, e).any()]
    if missing:
        raise ValueError(
            f"[study].cm_energies must be among grid_energies (t_rec comes from their κ); {missing} are not"
        )
    for energy in grid:
        pilot = study.scene(
            f"pilot_E{energy:.3f}",
            energy=energy,
            n=study.params.pilot_n,
            seed=study.params.pilot_seed,
            t_max=study.params.pilot_t_max,
        )
        pdir = study.run(f"pilot_E{energy:.3f}", pilot, workers=workers, progress=progress)
        n = grid_n(study, energy)
        choice = _t_max_choice(study, pdir, n)
        choices["t_max"][grid_key(energy)] = asdict(choice)
        scene = study.scene(grid_key(energy), energy=energy, n=n, t_max=choice.t_max)
        study.run(grid_key(energy), scene, workers=workers, progress=progress)
        if any(np.isclose(energy, e) for e in study.params.square_energies):
            # the authors' square ICs (goodICs), same n, seed and t_max: censored orbits run to t_max
            sq = study.scene(sq_key(energy), energy=energy, n=n, t_max=choice.t_max, region="square")
            study.run(sq_key(energy), sq, workers=workers, progress=progress)
    for energy, n in zip(study.params.pt_energies, study.params.pt_n):
        scene = study.scene(
            pt_key(energy), energy=float(energy), n=int(n), seed=study.params.pt_seed, t_max=study.params.pt_t_max
        )
        study.run(pt_key(energy), scene, workers=workers, progress=progress)
    for energy in study.params.cm_energies:
        energy = float(energy)
        r, (t_rec, t_samp, t_rec_end) = _cm_windows(study, energy)
        choices["cmeasure"][cm_key(energy)] = {
            "energy": energy,
            "kappa": r.kappa,
            "tau0": r.tau0,
            "t_rec": t_rec,
            "t_sample_end": t_samp,
            "t_record_end": t_rec_end,
        }
        print(
            f"  fig2 c-measure E={energy}: κ = {r.kappa:.4f}, τ0 = {r.tau0:.2f} → t_rec = {t_rec:g}, "
            f"recording to {t_rec_end:.2f}",
            flush=True,
        )
        scene = study.scene(
            cm_key(energy),
            energy=energy,
            n=study.params.cm_n,
            seed=study.params.cm_seed,
            t_max=study.params.cm_t_max,
            sections={"t_from": t_rec, "t_to": t_rec_end, "first_only": False},
        )
        study.run(cm_key(energy), scene, workers=workers, progress=progress)
    write_json_atomic(_choices_path(study), choices)


def _scene_of(path):
    return json.loads((path / SCENE_FILE).read_text())["scene"]


def _analyze_grid(study):
    import pandas as pd

    from hhscatter.analysis.survival.kappa_energy import fit_kappa_energy

    E_C = study.model.critical_energy
    rows, runs = [], {}
    tmax_choices = json.loads(_choices_path(study).read_text())["t_max"]
    for energy in study.params.grid_energies:
        energy = float(energy)
        path = study.raw(grid_key(energy))
        tch = tmax_choices[grid_key(energy)]
        lt = _lifetimes(path)
        r = _grid_rate(study, energy, lt)
        runs[energy] = (lt, r)  # read and fitted once: the conventions and the c-measure use them again
        t_max = float(_scene_of(path)["t_max"])
        rows.append(
            {
                "energy": energy,
                "x": energy - E_C,
                **rate_row(r),
                "n": len(lt),
                "t_max": t_max,
                "t_max_reason": tch["reason"],
                "kappa_pilot": tch["kappa_pilot"] if tch["kappa_pilot"] is not None else math.nan,
                "n_censored": int((lt["outcome"] == "censored").sum()),
                "window_reaches_t_max": bool(r.t_stop >= t_max - r.window_choice.width),
            }
        )
    df = pd.DataFrame(rows)
    study.write_table(
        df, "kappa_energy.parquet", description="κ0(E): mean of 4 least-squares fits of log P(t) (escape_rate), Fig. 2b"
    )
    seed = study.params.fit_seed
    n_boot = study.params.n_boot
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fit = fit_kappa_energy(
            df["energy"], df["kappa"], df["kappa_err"], E_C, continuous=True, n_boot=n_boot, rng=seed
        )
        sep = fit_kappa_energy(
            df["energy"], df["kappa"], df["kappa_err"], E_C, continuous=False, n_boot=n_boot, rng=seed
        )
    return df, fit, sep, runs


def _analyze_pt(study):
    """Fig. 2a: P(t) per energy of pt_energies: fits, curves and fitted lines (derived tables), numbers, comparison."""
    import pandas as pd

    E_C = study.model.critical_energy
    curves, lines, numbers = [], [], {}
    for energy in study.params.pt_energies:
        t_end, obs, t_max, r, tail = _pt_fits(study, pt_key(energy))
        curve, line = survival_tables(energy, t_end, obs, r)
        curves.append(curve)
        lines.append(line)
        entry = rate_summary(t_end.size, t_max, r, tail.n_trapped)
        if tail.tail is not None:
            line, more = sticky_tail_summary(energy, t_end, obs, t_max, tail)
            lines.append(line)
            entry.update(more)
        else:
            entry.update(tail_detected=False)
        numbers[pt_key(energy)] = entry
        _record(study, pt_comparisons(energy, r, tail, E_C))
    study.write_table(
        pd.concat(curves, ignore_index=True),
        "survival_curves.parquet",
        description="Kaplan–Meier P(t) (all orbits) and P_esc(t) (orbits leaving before t_max), Fig. 2a",
    )
    study.write_table(
        pd.concat(lines, ignore_index=True),
        "pt_fit_lines.parquet",
        description="fitted exponential f0 e^{-κt} and power law f* t^{-z} of Fig. 2a",
    )
    return numbers


def _pt_fits(study, key: str):
    """Read one P(t) run (t_end and the observed mask only) and fit it: κ on plateau windows, the sticky tail."""
    import pyarrow as pa

    from hhscatter.analysis.survival.escape_rate import escape_rate, escaping_tail
    from hhscatter.data.read import survival_arrays

    # the lean route (t_end and the observed mask only, 9 bytes per orbit): these runs have 1e7 orbits
    t_end, obs = survival_arrays(study.raw(key))
    pa.default_memory_pool().release_unused()
    t_max = float(_scene_of(study.raw(key))["t_max"])
    r = escape_rate(t_end, obs, detect_tail=False, min_survivors=study.params.min_survivors)
    tail = escaping_tail(t_end, obs, r.tau0, r.fits[0], min_survivors=study.params.tail_min_survivors)
    return t_end, obs, t_max, r, tail


def _analyze_cmeasure(study, grid_runs):
    """κ from the c-measure per energy of cm_energies and start shift, beside κ from P(t): table, comparison."""
    E_C = study.model.critical_energy
    choices = json.loads(_choices_path(study).read_text())["cmeasure"]
    rows = []
    for energy in study.params.cm_energies:
        rows += _cmeasure_rows(study, energy, choices[cm_key(energy)], grid_runs, E_C)
    import pandas as pd

    df = kappa_cmeasure_z(pd.DataFrame(rows))
    study.write_table(
        df,
        "kappa_cmeasure.parquet",
        description="κ from the c-measure, Eq. (eqn:kappa_cmeasure_truetime), vs κ from P(t)",
    )
    df.to_csv(study.derived("kappa_cmeasure.csv"), index=False, float_format="%.6g")  # the same, for reading
    rows, entries = cmeasure_comparisons(df)
    _record(study, rows)
    return {cm_key(energy): entry for energy, entry in entries.items()}


def _cmeasure_rows(study, energy: float, ch: dict, grid_runs, E_C: float) -> list:
    """κ from the c-measure of one energy's run per start shift
    (:func:`~hhscatter.reproduction.fig2.cmeasure_run_rows` on its tables)."""
    from hhscatter.data.read import read_lifetimes, read_sections

    key = cm_key(energy)
    win = _scene_of(study.raw(key))["sections"]
    lt = read_lifetimes(study.raw(key), columns=["traj_id", "outcome", "t_end"], categorical=True)
    sec = read_sections(study.raw(key), columns=["traj_id", "t"])
    p = study.params
    return cmeasure_run_rows(
        sec,
        lt,
        ch,
        win,
        {e: r for e, (_, r) in grid_runs.items()},
        label=key,
        shifts=p.cm_start_shifts,
        energy=energy,
        E_c=E_C,
        min_survivors=p.min_survivors,
        n_boot=p.n_boot,
        seed=p.fit_seed,
    )


def _record(study, rows) -> None:
    """Record comparison rows (the keyword arguments of ``study.compare``)."""
    for row in rows:
        study.compare(**row)


def _analyze_conventions(study, grid_runs):
    """κ(E) under the 4 conventions of FIG2_CONVENTIONS
    (:func:`~hhscatter.reproduction.fig2.convention_analysis`) of the Fig. 2b runs and the square-IC runs; writes
    the table. Returns (table, stability, numbers)."""
    p = study.params
    runs = {}
    for energy in p.grid_energies:
        runs[energy] = {"disk": grid_runs[energy]}  # the Fig. 2b run, already read and fitted
        if any(np.isclose(energy, e) for e in p.square_energies):
            runs[energy]["square"] = (_lifetimes(study.raw(sq_key(energy))), None)
    table, stab, numbers = convention_analysis(
        runs,
        E_c=study.model.critical_energy,
        p_levels=p.p_levels,
        max_bias=p.max_plateau_bias,
        rel_tol=p.stable_rel_tol,
        n_boot=p.n_boot,
        seed=p.fit_seed,
        min_survivors=p.min_survivors,
    )
    study.write_table(
        table,
        "kappa_conventions.parquet",
        description="κ0(E) per convention: IC region (disk, square) × windows (plateau, P levels); "
        "defined = False where the plateau of censored orbits makes κ ill-defined",
    )
    return table, stab, numbers


def analyze(study):
    """Write the derived tables and fig2.json (see the module docstring)."""
    E_C = study.model.critical_energy
    grid_df, fit, sep, grid_runs = _analyze_grid(study)
    laws = {"continuous": fit, "separate": sep, "paper": SimpleNamespace(**PAPER_FIG2)}
    study.write_table(
        kappa_law_curves(laws, float(grid_df["x"].max()), E_C),
        "kappa_fit_curve.parquet",
        description="fitted κ(E) laws of Fig. 2b on a grid of x = E − E_c, and the paper's",
    )
    fj, sj = kappa_law_summary(fit), kappa_law_summary(sep)
    conv_table, _, conv = _analyze_conventions(study, grid_runs)
    ill = conv_table[~conv_table["defined"]]
    _record(study, law_comparisons(fj, sj, conv["law"], ill))
    pt = _analyze_pt(study)
    cm = _analyze_cmeasure(study, grid_runs)
    study.write_numbers(
        {
            "rules": FIG2_RULES,
            "E_c": E_C,
            "kappa_fit": fj,
            "kappa_fit_separate": sj,
            "paper": PAPER_FIG2,
            "kappa_energy": grid_df.to_dict(orient="records"),
            "kappa_conventions": conv,
            "Pt": pt,
            "cmeasure": cm,
        }
    )


plot = figure_stage(
    "plot_fig2",
    "survival_curves",
    "pt_fit_lines",
    "kappa_energy",
    "kappa_fit_curve",
    "kappa_cmeasure",
    NUMBERS,
    PATH,
    conv_table=Table("kappa_conventions", optional=True),
)
