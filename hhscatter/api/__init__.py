"""The notebook API: one function per concept, per grid point, each result with ``.to_frame()`` and ``.plot(ax=)``.

P(t) and κ of a lifetimes DataFrame, one result per grid point, and plots on your axes;
:func:`kappa_cmeasure` and :func:`run_scene` start from a run directory.

These functions take the DataFrame of :func:`hhscatter.read_lifetimes` (or of
pandas, DuckDB, polars … with the same columns) and analyse each ensemble
separately; the :mod:`survival` and :mod:`escape_rate` modules below them
work on arrays of one ensemble.

An *ensemble* (a grid point) is one (energy, γ): the nominal E0 in the
``energy`` column of a grid run, never the per-orbit ``e0``, which differs
from orbit to orbit in the last bits. A frame without ``energy`` (a plain run,
or several plain runs concatenated) is split by clustering ``e0`` with a
relative tolerance of 1e-9; a frame whose ``e0`` varies continuously (a run
from an initial-condition table) is one ensemble per γ, with energy NaN.

* :func:`survival` → :class:`SurvivalCurves`: Kaplan–Meier P(t) per point;
* :func:`escape_rates` → :class:`EscapeRates`: κ ± error, τ0, the fit windows,
  the MLE cross-check and τ* per point (paper Sec. II, Eq. (eqn:kappa_hyperbolic)). κ is the
  escape rate of the *conservative* system: for a dissipative point (γ > 0)
  P(t) is not exponential (paper Sec. III), so no κ is fitted there; its row
  has NaN and a note, and a warning names those points;
* :func:`plot_survival`, :func:`plot_escape_rates` draw on ``ax`` (default: a
  new figure from pyplot) and return it. They never change the matplotlib
  backend, so inline figures in Jupyter keep working.

Both result objects have ``.to_frame()`` (a tidy pandas DataFrame) and
``.plot(ax=None)``.

One module per concept, every public name importable from ``hhscatter.api``:

* ``points`` — the grid points of a lifetimes frame (:func:`split_points`);
* ``rates`` — survival and escape rates (:func:`survival`, :func:`escape_rates`, :func:`stream_survival`);
* ``cmeasure`` — the c-measure (:func:`kappa_cmeasure`, :func:`kappa_cmeasure_tables`, :func:`cmeasure_points`,
  :func:`cmeasure_distances`);
* ``dissipative`` — transition times and energy decay (:func:`transition_times`, :func:`energy_decay`);
* ``basins`` — exit-basin maps and their measures (:func:`basin_measures`);
* ``plotting`` — :func:`plot_survival`, :func:`plot_escape_rates`;
* ``runs`` — what a run directory holds (:func:`run_scene`);
* ``checks`` — the argument checks every function above makes before any work (a wrong table, run, number or
  result is refused with a :class:`~hhscatter.errors.ConfigError` naming the argument).
"""

from hhscatter.api.basins import OUTSIDE_BASIN as OUTSIDE_BASIN  # the basin codes (module constants, not in __all__)
from hhscatter.api.basins import SETTLED_BASIN as SETTLED_BASIN
from hhscatter.api.basins import TRAPPED_BASIN as TRAPPED_BASIN
from hhscatter.api.basins import BasinMeasures, basin_measures
from hhscatter.api.cmeasure import (
    CMeasureDistances,
    CMeasurePoints,
    CMeasureRates,
    cmeasure_distances,
    cmeasure_points,
    kappa_cmeasure,
    kappa_cmeasure_tables,
)
from hhscatter.api.dissipative import EnergyDecay, TransitionTimes, energy_decay, transition_times
from hhscatter.api.plotting import plot_escape_rates, plot_survival
from hhscatter.api.points import E0_RTOL as E0_RTOL  # the e0 clustering tolerance
from hhscatter.api.points import split_points
from hhscatter.api.rates import DISSIPATIVE_NOTE as DISSIPATIVE_NOTE  # the note of a dissipative point without κ
from hhscatter.api.rates import EscapeRates, SurvivalCurves, escape_rates, stream_survival, survival
from hhscatter.api.runs import run_scene

__all__ = [
    "BasinMeasures",
    "CMeasureDistances",
    "CMeasurePoints",
    "CMeasureRates",
    "EnergyDecay",
    "EscapeRates",
    "SurvivalCurves",
    "TransitionTimes",
    "basin_measures",
    "cmeasure_distances",
    "cmeasure_points",
    "energy_decay",
    "escape_rates",
    "kappa_cmeasure",
    "kappa_cmeasure_tables",
    "plot_escape_rates",
    "plot_survival",
    "run_scene",
    "split_points",
    "stream_survival",
    "survival",
    "transition_times",
]
