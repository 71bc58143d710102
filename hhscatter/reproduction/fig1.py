"""The paper's Fig. 1 (fig:contour_two_manifolds) in tables: the record of one energy's c-measure run and its points.

A c-measure run at energy E is a conservative ensemble whose orbits still inside at the recording time t_rec
record their first crossing of the section ṙ = 0, φ̇ > 0 (the sprinkler construction); t_rec = ⌈τ0 + n/κ⌉ comes
from a pilot ensemble's κ and τ0. Nothing here reads a file: the run's lifetimes and sections come in as
DataFrames. Units: t in time units, κ in 1/time, energies in energy units.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from hhscatter.analysis.stats.measured import Measured
from hhscatter.analysis.survival.escape_rate import escape_rate_from_lifetimes

__all__ = ["POINT_COLUMNS", "energy_record"]

#: the columns of the published c-measure points (energy, then the crossing's phase point, then e_cross)
POINT_COLUMNS = ["energy", "traj_id", "t", "x", "y", "px", "py", "e_cross"]


def energy_record(
    energy: float,
    choice: dict,
    t_max: float,
    lifetimes: pd.DataFrame,
    sections: pd.DataFrame,
    t_rec_now: float,
    raw_run: str,
):
    """energy_record(energy, choice, t_max, lifetimes, sections, t_rec_now, raw_run) -> (record, points).

    Parameters
    ----------
    energy : float
        The run's energy E.
    choice : dict
        The pilot's recorded choice: t_rec, kappa, kappa_err, tau0, t_stop (end of the pilot's fit window),
        n_pilot.
    t_max : float
        The run's integration time.
    lifetimes : DataFrame
        The run's lifetimes (traj_id, outcome, t_end and, for the escape rate, e0, gamma).
    sections : DataFrame
        Its section crossings (traj_id, t, x, y, px, py, energy): one per orbit still inside at t_rec.
    t_rec_now : float
        t_rec by the recording rule with the pilot's κ, τ0 as the code computes them now (differs from the
        choice only if the estimator changed since the runs were made).
    raw_run : str
        The run's name in the record.

    Returns
    -------
    (dict, DataFrame)
        The record (t_rec, the κ and τ0 used, t_rec·κ, survivors at t_rec, points, κ of the run itself from
        its own lifetimes, the largest deviation of a crossing's energy from E) and the points
        (:data:`POINT_COLUMNS`; e_cross is the orbit's energy at the crossing).

    Examples
    --------
    >>> t_end = np.random.default_rng(1).exponential(1 / 0.05, 4000)  # escape rate κ = 0.05
    >>> lt = pd.DataFrame({"traj_id": range(4000), "e0": 0.3, "gamma": 0.0, "outcome": "escaped", "t_end": t_end})
    >>> sec = pd.DataFrame({"traj_id": [2, 3], "t": [21.0, 22.5], "x": 0.1, "y": 0.2, "px": 0.3, "py": 0.4,
    ...                     "energy": [0.3 + 1e-12, 0.3]})
    >>> choice = {"t_rec": 20.0, "kappa": 0.05, "kappa_err": 0.005, "tau0": 2.0, "t_stop": 60.0, "n_pilot": 100}
    >>> rec, pts = energy_record(0.3, choice, 80.0, lt, sec, 20.0, "raw/E0.30")
    >>> rec["n_survivors_at_t_rec"] == int((t_end > 20.0).sum()), rec["n_points"], rec["t_rec_times_kappa"]
    (True, 2, 1.0)
    >>> bool(abs(rec["kappa_main_run"]["value"] - 0.05) < 3 * rec["kappa_main_run"]["err"]), list(pts.columns) == POINT_COLUMNS
    (True, True)
    """
    t_rec = float(choice["t_rec"])
    alive = int(np.count_nonzero(lifetimes["t_end"].to_numpy() > t_rec))
    own = escape_rate_from_lifetimes(lifetimes, detect_tail=False)
    e_dev = float(np.max(np.abs(sections["energy"].to_numpy() - energy))) if len(sections) else 0.0
    record = {
        "energy": energy,
        "t_rec": t_rec,
        "t_max": float(t_max),
        "kappa_used": Measured(choice["kappa"], choice["kappa_err"]).to_dict(),
        "tau0_used": choice["tau0"],
        "fit_window_pilot": [choice["tau0"], choice["t_stop"]],
        "t_rec_times_kappa": t_rec * choice["kappa"],
        "t_rec_rule_with_current_code": t_rec_now,
        "n_pilot": int(choice["n_pilot"]),
        "n_orbits": len(lifetimes),
        "n_survivors_at_t_rec": alive,
        "n_points": len(sections),
        "kappa_main_run": Measured(own.kappa, own.kappa_err).to_dict(),
        "max_energy_deviation": e_dev,
        "raw_run": raw_run,
    }
    points = sections[["traj_id", "t", "x", "y", "px", "py"]].copy()
    points.insert(0, "energy", energy)
    points["e_cross"] = sections["energy"].to_numpy()  # the orbit's energy at the crossing (E up to rounding)
    return record, points
