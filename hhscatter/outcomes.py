"""The vocabulary of an orbit's fate, declared once: outcome codes and names, and which outcomes censor.

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

__all__ = ["CENSORED", "CENSORING_OUTCOMES", "ESCAPED", "LEAVING_OUTCOMES", "OUTCOMES", "SETTLED", "STOPPED"]

#: outcome codes (int8 in the engine's arrays), indices into :data:`OUTCOMES`
ESCAPED, SETTLED, CENSORED, STOPPED = 0, 1, 2, 3
#: outcome names, by code (the dictionary of the tables' ``outcome`` column)
OUTCOMES = ("escaped", "settled", "censored", "stopped")
#: outcomes that end a lifetime (the orbit left Ω): observed events of P(t)
LEAVING_OUTCOMES = ("escaped", "settled")
#: outcomes that right-censor a lifetime
CENSORING_OUTCOMES = ("censored", "stopped")
