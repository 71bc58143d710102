"""Study ``resc``: is the escape criterion r > r_esc sound? (paper App. "Escape Condition").

The paper deems a conservative orbit escaped at its first outward crossing of
r_esc "slightly larger than 1" and states that all values tried gave the same
observations.  This study measures, at E = 0.25, 0.30, 0.35:

1. κ for r_esc ∈ {1.03, 1.1, 1.5, 2.0} on the *same* initial conditions
   (paired), every cell by the same rules.  One common window per energy:
   the median of the four cells' exponential-regime windows found by
   :func:`~hhscatter.analysis.survival.windows.choose_windows` (the paper's rule),
   started no earlier than the time where the r_ref curve has fallen to
   ``p_start`` = 0.1 (the prompt-escape transient, whose hazard peak at
   t ≈ 5 and ringing would otherwise be shifted in and out of the window by
   the flight time).  Reported per cell: κ by the constant-hazard MLE
   (:func:`~hhscatter.analysis.survival.escape_rate.escape_rate_mle`) on that window;
   κ by the paper's mean of 4 least-squares fits with the cell's own windows
   (Fig. 2b caption); and the shift κ(r) − κ(r_ref) from the slope of the
   paired log-survival ratio
   (:func:`~hhscatter.analysis.survival.paired.survival_ratio_slope`), the
   main estimator (the MLE difference is kept as a cross-check: it is
   dominated by the window's first e-fold and so sensitive to the
   period-scale modulation of the hazard).  Delays: the mean flight time
   from r_ref to r on identical trajectories and the delay of P(t).
2. Returns: orbits followed past their escape (the engine's ``follow``
   scene option, table ``crossings``); the fraction
   that comes back inside r < 1 after crossing r_esc outward (Wilson
   intervals) and how fast those escape again; the radial extent of the
   Lyapunov orbit (the exact boundary of Ω) at each energy.
3. Exit channels: fraction of escapes per channel with Wilson intervals
   against the 1/3 of the three-fold symmetry, for all escapes and for
   early (t ≤ τ0) and late (t > τ0) ones.

Outputs (``studies/resc/out/<scale>/``): derived/kappa.parquet,
derived/returns.parquet, derived/channels.parquet, derived/lyapunov.parquet,
resc.json, resc.png.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.reproduction.escape_criterion import (
    channel_rows,
    common_window,
    criterion_numbers,
    follow_returns,
    kappa_row,
    lyapunov_table,
    paired_runs,
    returns_row,
)
from hhscatter.scene.schema import Integer, Number, Numbers
from hhscatter.studies.params import StudyParams
from hhscatter.studies.plot_stage import PATH, SCALE, Param, figure_stage


class Params(StudyParams):
    """``[study]`` of studies/resc/study.toml."""

    energies: Numbers
    r_esc: Numbers
    r_ref: Number
    r_in: Number = 1.0
    r_far: Number = 10.0
    n_follow: Integer
    z: Number = 1.0
    p_start: Number = 0.1
    n_groups: Integer = 16
    reesc_fast: Number = 10.0
    lyapunov_energies: Numbers = []


# -- keys -------------------------------------------------------------------
def _key(E, r):
    return f"E{E:.2f}_r{r:g}"


def _follow_key(E):
    return f"follow_E{E:.2f}"


def _grid(study):
    return list(study.params.energies), list(study.params.r_esc)


def _follow_radii(study):
    _, radii = _grid(study)
    return tuple(sorted({study.params.r_in, *radii}))


# -- simulate ---------------------------------------------------------------
def _follow_scene(study, E):
    """The first n_follow orbits of the (E, r_ref) ensemble, followed past their escape (scene option
    ``follow``): every crossing of the follow radii, until r_far or t_max."""
    from hhscatter.scene.scene import Follow

    r_ref = study.params.r_ref
    base = study.scene(_key(E, r_ref), energy=E, r_esc=r_ref)
    return study.scene(
        _follow_key(E),
        energy=E,
        r_esc=r_ref,
        n=min(study.params.n_follow, base.n),
        r_far=study.params.r_far,
        follow=Follow(_follow_radii(study)),
    )


def simulate(study, workers=None, progress=True):
    """simulate(study, workers=None) -> None: the (E, r_esc) engine runs and the follow runs."""
    energies, radii = _grid(study)
    for E in energies:
        for r in radii:
            study.run(_key(E, r), study.scene(_key(E, r), energy=E, r_esc=r), workers=workers, progress=progress)
        study.run(_follow_key(E), _follow_scene(study, E), workers=workers, progress=progress)


# -- analyze ----------------------------------------------------------------
def _lifetimes(study, E, r):
    """(traj_id, t_end, observed, exit_channel) arrays of run (E, r), sorted by traj_id (channel −1: none).

    Read as Arrow columns into numpy (no pandas frame, no Python object per orbit): 1e7 orbits per run at
    paper scale, 4 runs per energy held at once.
    """
    from hhscatter.analysis.survival.fits import observed_from_outcome
    from hhscatter.data.read import read_by_orbit

    c = read_by_orbit(study.raw(_key(E, r)), ["outcome", "t_end", "exit_channel"])
    obs = observed_from_outcome(c["outcome"])
    ch = np.where(obs, c["exit_channel"], -1).astype(np.int8)
    return c["traj_id"], c["t_end"], obs, ch


def analyze(study):
    """analyze(study) -> None: derived tables and resc.json (see the module docstring).

    Steps per energy: the paired runs (:func:`~hhscatter.reproduction.escape_criterion.paired_runs`), the common
    κ window, the follow runs' returns (:func:`~hhscatter.reproduction.escape_criterion.follow_returns`), then per r_esc the κ row, the returns row and the exit channels; then the numbers
    and the comparison (:mod:`hhscatter.reproduction.escape_criterion`).
    """
    energies, radii = _grid(study)
    r_ref = study.params.r_ref
    if r_ref not in radii:
        raise ValueError(f"[study] r_ref = {r_ref} must be one of r_esc = {radii}")
    p = study.params
    lyap = lyapunov_table([*p.lyapunov_energies, *energies], study.model)
    lyap_at = {row.energy: row for row in lyap.itertuples()}

    k_rows, ret_rows, ch_rows = [], [], []
    for E in energies:
        arrs, chans = paired_runs(lambda r, E=E: _lifetimes(study, E, r), radii, r_ref, E)
        grid, own, win = common_window(arrs, radii, r_ref, p.p_start)
        ends, rs, recross = _follow_returns(study, E, radii)
        for r in radii:
            k_row, ps = kappa_row(E, r, r_ref, arrs, own, win, rs, ends.t_end.to_numpy(), n_groups=p.n_groups)
            k_rows.append(k_row)
            ret_rows.append(
                returns_row(E, r, rs[r], recross[r], win, ps.kappa_ref, lyap_at[E], ends, z=p.z, fast=p.reesc_fast)
            )
            ch_rows.extend(channel_rows(E, r, chans[r], arrs[r][0], win, z=p.z))
        del arrs, chans, own, ends, rs, recross  # 4 runs of 1e7 orbits: free them before the next energy's
    kap = pd.DataFrame(k_rows)
    ret = pd.DataFrame(ret_rows)
    chan = pd.DataFrame(ch_rows)
    study.write_table(kap, "kappa.parquet")
    study.write_table(ret, "returns.parquet")
    study.write_table(chan, "channels.parquet")
    study.write_table(lyap, "lyapunov.parquet")
    numbers, rows = criterion_numbers(energies, radii, r_ref, kap, ret, chan, lyap, r_in=p.r_in, fast=p.reesc_fast)
    for row in rows:
        study.compare(**row)
    study.write_numbers(numbers)


def _follow_returns(study, E, radii):
    """The follow run at energy E read and its returns measured (:func:`follow_returns`)."""
    from hhscatter.data.read import read_crossings, read_lifetimes

    fdir = study.raw(_follow_key(E))
    cross = read_crossings(fdir)
    ends = read_lifetimes(fdir, columns=["traj_id", "outcome", "t_end", "e0", "e_end"])
    return follow_returns(cross, ends, radii, study.params.r_in)


# -- plot -------------------------------------------------------------------
plot = figure_stage(
    "plot_resc",
    kappa="kappa",
    returns="returns",
    channels="channels",
    lyapunov="lyapunov",
    path=PATH,
    r_ref=Param("r_ref"),
    scale=SCALE,
)
