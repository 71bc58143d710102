"""Argument checks of the notebook API: every public function checks what it is given here, before any work.

One place for the checks every function of :mod:`hhscatter.api` shares: the type and columns of a table, a run
directory, a number in its range, a time grid, a window, a result object of the right kind, and whether two runs
may be compared. A failed check raises :class:`~hhscatter.errors.ConfigError` (a ValueError; exit status 2 in
the CLI) with a message that names the argument, what was expected and what was given — never a table's repr.

Examples
--------
>>> import hhscatter
>>> try:
...     hhscatter.escape_rates(42)
... except hhscatter.ConfigError as e:
...     print(e)
lifetimes must be a pandas DataFrame (a lifetimes table: hhscatter.read_lifetimes(run)), got int 42
>>> number(0.5, "alpha", lo=1.0)
Traceback (most recent call last):
...
hhscatter.errors.ConfigError: alpha must be a number ≥ 1, got float 0.5
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterable

import numpy as np

from hhscatter.errors import ConfigError

__all__ = [
    "describe",
    "frame",
    "number",
    "numeric_columns",
    "result",
    "run_dir",
    "scene_differences",
    "time_grid",
    "window",
]


def describe(obj) -> str:
    """A short description of ``obj`` for a message: its type and, for a scalar or a short text, its value;
    a table by its columns, never its repr."""
    kind = type(obj).__name__
    article = "an" if kind[:1].lower() in "aeiou" else "a"
    if hasattr(obj, "columns") and hasattr(obj, "shape"):
        cols = [str(c) for c in list(obj.columns)[:8]]
        more = ", …" if len(obj.columns) > 8 else ""
        return f"{article} {kind} of {len(obj)} rows with columns [{', '.join(cols)}{more}]"
    if isinstance(obj, (str, os.PathLike)):
        text = str(obj)
        return f"{kind} {text[:60]!r}" + ("…" if len(text) > 60 else "")
    if obj is None or isinstance(obj, (bool, numbers.Number)):
        return f"{kind} {obj!r}"
    return f"{article} {kind}"


def frame(obj, name: str, *, needs: Iterable[str] = (), what: str = "a lifetimes table", reader: str = ""):
    """The DataFrame ``obj`` (argument ``name``), refused unless it is a non-empty pandas DataFrame with the
    columns ``needs``.

    ``what`` says what the table should be and ``reader`` the call that makes one (default
    ``hhscatter.read_lifetimes(run)``); a path given where a table is expected is told to read it first.

    Examples
    --------
    >>> import pandas as pd
    >>> frame(pd.DataFrame({"t_end": [1.0]}), "lifetimes", needs=["t_end", "outcome"])
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: lifetimes lacks the column(s) ['outcome'] of a lifetimes table (hhscatter.read_lifetimes(run)); it has [t_end]
    """
    import pandas as pd  # deferred: pandas loads on first use

    reader = reader or "hhscatter.read_lifetimes(run)"
    if not isinstance(obj, pd.DataFrame):
        raise ConfigError(f"{name} must be a pandas DataFrame ({what}: {reader}), got {describe(obj)}")
    missing = [c for c in needs if c not in obj.columns]
    if missing:
        have = ", ".join(str(c) for c in list(obj.columns)[:12]) + (", …" if len(obj.columns) > 12 else "")
        raise ConfigError(f"{name} lacks the column(s) {missing} of {what} ({reader}); it has [{have}]")
    if len(obj) == 0:
        raise ConfigError(f"{name} is empty: no rows to analyse ({what}: {reader})")
    return obj


def numeric_columns(df, name: str, *, nonneg=(), finite=(), nan_ok=()) -> None:
    """Refuse a table whose columns (those present of the lists) hold what is not a number: ``nonneg`` finite and
    ≥ 0, ``finite`` finite, ``nan_ok`` finite or missing (NaN). The message names the column, a bad row and
    how many there are.

    Examples
    --------
    >>> import pandas as pd
    >>> numeric_columns(pd.DataFrame({"t_end": [1.0, -2.0]}), "lifetimes", nonneg=["t_end"])
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: lifetimes column t_end must hold finite numbers ≥ 0; row 1 has -2.0 (1 such row(s))
    """
    import pandas as pd  # deferred: pandas loads on first use

    for cols, positive, allow_nan in ((nonneg, True, False), (finite, False, False), (nan_ok, False, True)):
        for col in cols:
            if col not in df.columns:
                continue
            raw = df[col]
            try:
                v = pd.to_numeric(raw, errors="coerce").to_numpy(dtype=float, na_value=np.nan)
            except (TypeError, ValueError):
                v = np.full(len(raw), np.nan)
            bad = ~np.isfinite(v)
            if allow_nan:
                bad &= ~(np.isnan(v) & raw.isna().to_numpy())
            if positive:
                bad |= v < 0
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                val = raw.iloc[i]
                raise ConfigError(
                    f"{name} column {col} must hold finite numbers{' ≥ 0' if positive else ''}; row {i} has "
                    f"{repr(val) if isinstance(val, str) else val} ({int(bad.sum())} such row(s))"
                )


def number(
    x,
    name: str,
    *,
    lo: float | None = None,
    hi: float | None = None,
    lo_open: bool = False,
    integer: bool = False,
    finite: bool = True,
) -> float:
    """``x`` as a float (an int with ``integer=True``), refused unless it is a real number (not a bool), finite
    (unless ``finite=False``) and within [lo, hi] (``lo_open``: > lo).

    Examples
    --------
    >>> number(3, "n_boot", lo=1, integer=True)
    3
    """
    kind = "an integer" if integer else "a number"
    ok = isinstance(x, numbers.Integral if integer else numbers.Real) and not isinstance(x, bool)
    v = float(x) if ok else math.nan
    bounds = []
    if lo is not None:
        bounds.append(f"{'>' if lo_open else '≥'} {lo:g}")
    if hi is not None:
        bounds.append(f"≤ {hi:g}")
    if (
        not ok
        or math.isnan(v)
        or (finite and not math.isfinite(v))
        or (lo is not None and (v <= lo if lo_open else v < lo))
        or (hi is not None and v > hi)
    ):
        raise ConfigError(f"{name} must be {kind}{' ' + ' and '.join(bounds) if bounds else ''}, got {describe(x)}")
    return int(x) if integer else v


def time_grid(t, name: str = "t_grid") -> np.ndarray | None:
    """The times ``t`` (time units) as a 1-D float array (None passes), refused unless non-empty, finite, ≥ 0 and
    non-decreasing.

    Examples
    --------
    >>> time_grid([0.0, 1.0, 2.5]).tolist()
    [0.0, 1.0, 2.5]
    """
    if t is None:
        return None
    if isinstance(t, (str, bytes)) or not hasattr(t, "__len__") and not hasattr(t, "__array__"):
        raise ConfigError(f"{name} must be an array of times (time units), got {describe(t)}")
    try:
        a = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be an array of times (time units), got {describe(t)}") from None
    if a.ndim != 1 or a.size == 0:
        raise ConfigError(f"{name} must be a non-empty 1-D array of times, got shape {a.shape}")
    if not np.isfinite(a).all() or (a < 0).any() or (np.diff(a) < 0).any():
        raise ConfigError(f"{name} must hold finite times ≥ 0 in increasing order, got [{a.min():g} … {a.max():g}]")
    return a


def window(w, name: str = "window") -> tuple[float, float]:
    """A time window (lo, hi) as two floats, refused unless two finite numbers with lo < hi.

    Examples
    --------
    >>> window((0, 200))
    (0.0, 200.0)
    """
    if isinstance(w, (str, bytes)) or not isinstance(w, Iterable):
        raise ConfigError(f"{name} must be a pair (t_lo, t_hi) of times, got {describe(w)}")
    w = tuple(w)
    if len(w) != 2:
        raise ConfigError(f"{name} must be a pair (t_lo, t_hi) of times, got {len(w)} values")
    lo, hi = (number(v, f"{name}[{i}]") for i, v in enumerate(w))
    if not lo < hi:
        raise ConfigError(f"{name} must have t_lo < t_hi, got ({lo:g}, {hi:g})")
    return lo, hi


def result(obj, name: str, types: tuple, made_by: str):
    """``obj``, refused unless an instance of one of ``types`` (what ``made_by`` returns).

    Examples
    --------
    >>> result(1.0, "curves", (list,), "hhscatter.survival")
    Traceback (most recent call last):
    ...
    hhscatter.errors.ConfigError: curves must be a list (what hhscatter.survival returns), got float 1.0
    """
    if not isinstance(obj, types):
        names = " or ".join(t.__name__ for t in types)
        raise ConfigError(f"{name} must be a {names} (what {made_by} returns), got {describe(obj)}")
    return obj


def run_dir(run, name: str = "run"):
    """``run``, refused unless a path or URL (str or PathLike) of a run directory: one that holds the
    ``scene.json`` of :func:`hhscatter.simulate`.

    Examples
    --------
    >>> import tempfile
    >>> try:
    ...     run_dir(tempfile.mkdtemp())
    ... except ConfigError as e:
    ...     print(str(e).split(": ", 1)[1])
    not a run directory (no scene.json): give a directory written by hhscatter.simulate
    """
    from hhscatter.data.store import Store  # deferred: fsspec loads on first use

    if not isinstance(run, (str, os.PathLike)):
        raise ConfigError(f"{name} must be the path of a run directory (str or Path), got {describe(run)}")
    try:
        is_run = Store(run).exists("scene.json")
    except (OSError, ValueError):  # a path the file system cannot even look at (a null byte, an unknown protocol)
        is_run = False
    if not is_run:
        raise ConfigError(
            f"{name} = {str(run)!r}: not a run directory (no scene.json): give a directory written by hhscatter.simulate"
        )
    return run


#: scene keys that decide which orbits a run follows and when they end (system, initial conditions, escape rule,
#: noise); two runs compared orbit set against orbit set must agree on them
PAIRING_KEYS = (
    "system",
    "omega",
    "lam",
    "region",
    "radius",
    "ics",
    "momentum",
    "seed",
    "r_esc",
    "r_far",
    "noise",
)


def scene_differences(a: dict | None, b: dict | None, keys: Iterable[str] = PAIRING_KEYS) -> list[str]:
    """The keys of ``keys`` on which two scenes (dicts of a run's scene.json) differ, each as ``key (a vs b)``;
    empty when they agree or when either scene is unknown (None: a table without a record of its run).

    Examples
    --------
    >>> scene_differences({"r_esc": 1.5, "seed": 0}, {"r_esc": 3.0, "seed": 0})
    ['r_esc (1.5 vs 3.0)']
    """
    if a is None or b is None:
        return []
    return [f"{k} ({a.get(k)!r} vs {b.get(k)!r})" for k in keys if a.get(k) != b.get(k)]
