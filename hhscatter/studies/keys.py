"""Names of a study's raw runs: exact and unique by construction.

A study names each raw run by a key made from its parameters (``nodrag_E0.30_s0.01``). A key formatted from a
float with a fixed precision can name two runs alike (``f"{0.304:.2f}"`` is ``"0.30"``, as is 0.30's): one
run would be made and read for both. :func:`number_key` writes a number in the study's format when that text
reads back as the same number, and exactly (its shortest round-trip text) when it does not, so different numbers
always give different keys and the keys of the values a format writes exactly do not change. :class:`RunKeys` is
the dict of a study's runs that refuses a key given twice for different scenes.

Examples
--------
>>> from hhscatter.studies.keys import RunKeys, number_key
>>> number_key(0.30, ".2f"), number_key(0.304, ".2f"), number_key(3.0, "g"), number_key(0.1234567, "g")
('0.30', '0.304', '3', '0.1234567')
>>> runs = RunKeys()
>>> runs[f"E{number_key(0.30, '.2f')}"] = {"energy": 0.30}
>>> runs[f"E{number_key(0.30, '.2f')}"] = {"energy": 0.30}  # the same run again: fine
>>> try:
...     runs["E0.30"] = {"energy": 0.304}
... except ValueError as e:
...     print(type(e).__name__)
StudyError
"""

from __future__ import annotations

import math

from hhscatter.errors import StudyError

__all__ = ["RunKeys", "number_key"]


def number_key(value: float, fmt: str = "g") -> str:
    """number_key(value, fmt='g') -> the text of a number in a run key: ``format(value, fmt)`` when it reads back
    as ``value`` exactly, else the shortest text that does (``repr``). Different numbers give different texts.

    Parameters
    ----------
    value : float
        A finite number (a grid value of the study: an energy, a drag, a noise strength).
    fmt : str
        The study's format spec for it (``".2f"``, ``"g"``): kept wherever it is exact.

    Raises
    ------
    StudyError
        ``value`` is not a finite number.

    Examples
    --------
    >>> number_key(0.25, ".2f"), number_key(0.3, ".2f"), number_key(0.304, ".2f"), number_key(1e-7, "g")
    ('0.25', '0.30', '0.304', '1e-07')
    """
    try:
        v = float(value)
    except (TypeError, ValueError):
        v = math.nan
    if isinstance(value, (bool, str)) or not math.isfinite(v):
        raise StudyError(f"a run key is made from a finite number, got {value!r}")
    text = format(v, fmt)
    try:
        exact = float(text) == v
    except ValueError:  # a format that does not write a plain number
        exact = False
    return text if exact else repr(v)


class RunKeys(dict):
    """RunKeys() -> {key: what the run is}: a dict of a study's runs in which a key set again must name the same
    run (an equal value); a key given to two different runs is a :class:`~hhscatter.errors.StudyError` naming both.

    Examples
    --------
    >>> runs = RunKeys(a=1)
    >>> runs["a"] = 1
    >>> try:
    ...     runs["a"] = 2
    ... except Exception as e:
    ...     print(e)
    run key 'a' names two different runs (1 and 2): make the key from every parameter that tells them apart
    """

    def __init__(self, *args, **kwargs):
        super().__init__()
        for k, v in dict(*args, **kwargs).items():
            self[k] = v

    def __setitem__(self, key, value) -> None:
        if key in self and self[key] != value:
            raise StudyError(
                f"run key {key!r} names two different runs ({self[key]!r} and {value!r}): make the key from "
                "every parameter that tells them apart"
            )
        super().__setitem__(key, value)

    def update(self, *args, **kwargs) -> None:
        for k, v in dict(*args, **kwargs).items():
            self[k] = v

    def setdefault(self, key, default=None):
        if key not in self:
            self[key] = default
        return self[key]
