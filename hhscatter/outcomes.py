"""The vocabulary of an orbit's fate, declared once: outcome codes and names, which outcomes censor, and the
columns of the tables that record it (:data:`TABLE_COLUMNS`: the engine's rows and the Parquet schemas alike).

The engine decides an orbit's outcome at an exact event root (:mod:`hhscatter.integrate.events`), the tables store
it as a dictionary-encoded ``outcome`` column (:mod:`hhscatter.data.schema`), and the survival analysis reads it
(:func:`hhscatter.analysis.survival.fits.observed_from_outcome`): all three use these names.

* ``escaped``: left Ω through an exit (r > r_esc);
* ``settled``: captured in the well (E ≤ E_c − margin, dissipative scenes);
* ``censored``: still inside at ``t_max`` (right-censored lifetime);
* ``stopped``: stopped early because nothing more was needed (e.g. the first section crossing was recorded);
  right-censored too.

Examples
--------
>>> from hhscatter.outcomes import OUTCOMES, ESCAPED, CENSORING_OUTCOMES
>>> OUTCOMES[ESCAPED], CENSORING_OUTCOMES
('escaped', ('censored', 'stopped'))
"""

from __future__ import annotations

__all__ = [
    "CENSORED",
    "CENSORING_OUTCOMES",
    "ESCAPED",
    "LEAVING_OUTCOMES",
    "OUTCOMES",
    "SETTLED",
    "STOPPED",
    "TABLE_COLUMNS",
]

#: outcome codes (int8 in the engine's arrays), indices into :data:`OUTCOMES`
ESCAPED, SETTLED, CENSORED, STOPPED = 0, 1, 2, 3
#: outcome names, by code (the dictionary of the tables' ``outcome`` column)
OUTCOMES = ("escaped", "settled", "censored", "stopped")
#: outcomes that end a lifetime (the orbit left Ω): observed events of P(t)
LEAVING_OUTCOMES = ("escaped", "settled")
#: outcomes that right-censor a lifetime
CENSORING_OUTCOMES = ("censored", "stopped")

#: the columns of each table, in order: what the engine's ChunkResult holds (hhscatter.integrate.results) and
#: what the Parquet schemas declare (hhscatter.data.schema, which gives each its type)
TABLE_COLUMNS = {
    "lifetimes": ("traj_id", "x0", "y0", "px0", "py0", "e0", "gamma", "outcome", "t_end", "exit_channel", "e_end"),
    "sections": ("traj_id", "t", "x", "y", "px", "py", "energy"),
    "snapshots": ("traj_id", "t", "energy"),
    "crossings": ("traj_id", "t", "radius", "direction"),
}
